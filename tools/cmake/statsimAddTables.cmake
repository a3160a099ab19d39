# statsim_add_tables(TARGET name SHAPES mesh... [OPTIONS option...] [NAMESPACE ns]
#                    [OUTPUT_DIRECTORY dir])
#
# Generates a signature table for each mesh at build time with the statsim host tool
# (`statsim gather --mesh MESH --out .../statsim/tables/STEM.hpp OPTIONS...`) and makes an
# INTERFACE target `name` that carries them: link it and `#include <statsim/tables/STEM.hpp>`,
# then `world.add_shape(statsim::tables::STEM.view())` (NAMESPACE: the tables are `ns::STEM`
# instead). The header records its command with file names only, so its bytes do not depend on
# where the mesh or the build directory are. A table is generated again only when
# its mesh, the options or the tool change. Meshes are in metres (or say so in OPTIONS with
# `--units` or `--scale`); relative paths are relative to the calling CMakeLists.txt. OPTIONS are
# gather's (`statsim gather --help`): `--density`, `--precision i16`, smaller tables for tests
# (`--trials 3 ...`).
#
# STATSIM_GATHER_OPTIONS (a CMake variable, or else the environment variable of that name), a
# space-separated string: options added to every table's gathering, after OPTIONS; for quick test
# builds that must not edit the project (`--trials 3 ...`).
#
# The tool is `statsim::tool`: from `find_package(statsim COMPONENTS tools)`, or the statsim
# project itself (add_subdirectory with STATSIM_BUILD_TOOLS=ON).
function(statsim_add_tables)
  cmake_parse_arguments(ARG "" "TARGET;OUTPUT_DIRECTORY;NAMESPACE" "SHAPES;OPTIONS" ${ARGN})
  if(NOT ARG_TARGET OR NOT ARG_SHAPES)
    message(FATAL_ERROR "statsim_add_tables: give TARGET name and SHAPES mesh...")
  endif()
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "statsim_add_tables: unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT TARGET statsim::tool)
    message(FATAL_ERROR "statsim_add_tables needs the statsim host tool: find_package(statsim COMPONENTS tools), "
                        "or add the statsim project with STATSIM_BUILD_TOOLS=ON")
  endif()
  set(dir "${ARG_OUTPUT_DIRECTORY}")
  if(NOT dir)
    set(dir "${CMAKE_CURRENT_BINARY_DIR}/${ARG_TARGET}_tables")
  endif()
  set(extra "${STATSIM_GATHER_OPTIONS}")
  if(NOT extra AND DEFINED ENV{STATSIM_GATHER_OPTIONS})
    set(extra "$ENV{STATSIM_GATHER_OPTIONS}")
  endif()
  separate_arguments(extra UNIX_COMMAND "${extra}")
  list(APPEND ARG_OPTIONS ${extra})
  if(ARG_NAMESPACE)
    list(APPEND ARG_OPTIONS --namespace "${ARG_NAMESPACE}")
  endif()
  # The options as a file that changes only when they do: a dependency of every table, so that
  # new options regenerate them with any generator.
  string(REPLACE ";" "\n" options_text "${ARG_OPTIONS}")
  file(CONFIGURE OUTPUT "${dir}/options.txt" CONTENT "${options_text}\n")
  set(outputs "")
  set(stems "")
  foreach(mesh IN LISTS ARG_SHAPES)
    get_filename_component(path "${mesh}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    get_filename_component(stem "${mesh}" NAME_WE)
    if(stem IN_LIST stems)
      message(FATAL_ERROR "statsim_add_tables: two meshes named ${stem}: a table takes its name from the file")
    endif()
    list(APPEND stems "${stem}")
    set(out "${dir}/statsim/tables/${stem}.hpp")
    add_custom_command(OUTPUT "${out}"
                       COMMAND "$<TARGET_FILE:statsim::tool>" gather --mesh "${path}" --out "${out}" --quiet
                               ${ARG_OPTIONS}
                       DEPENDS "${path}" "${dir}/options.txt" "$<TARGET_FILE:statsim::tool>"
                       COMMENT "statsim gather: ${stem} (${mesh})"
                       VERBATIM)
    list(APPEND outputs "${out}")
  endforeach()
  add_custom_target(${ARG_TARGET}_generate DEPENDS ${outputs})
  get_target_property(tool statsim::tool ALIASED_TARGET)
  if(tool)
    add_dependencies(${ARG_TARGET}_generate ${tool})  # built in this project: build it first
  endif()
  add_library(${ARG_TARGET} INTERFACE)
  target_include_directories(${ARG_TARGET} INTERFACE "${dir}")
  target_link_libraries(${ARG_TARGET} INTERFACE statsim::statsim)
  # Dependencies of an INTERFACE library are followed by every target that links it.
  add_dependencies(${ARG_TARGET} ${ARG_TARGET}_generate)
endfunction()
