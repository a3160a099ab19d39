# Installs statsim into a temporary prefix, then configures, builds and runs a small project that
# finds it with find_package(statsim), generating a table from a mesh at build time when the
# tools were built; then the same project through add_subdirectory. Run by CTest (test
# install_and_consume).
foreach(var SOURCE_DIR WORK_DIR GENERATOR CXX)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run.cmake needs -D${var}=...")
  endif()
endforeach()
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

# Runs a built program that must print "NAME: ok"; LABEL names it in the log.
function(run_ok program name label)
  run("${program}")
  if(NOT last_output MATCHES "${name}: ok")
    message(FATAL_ERROR "${name} (${label}) printed: ${last_output}")
  endif()
  message(STATUS "${label}: ${last_output}")
endfunction()

# A runtime-only build of statsim (no tools, tests or examples): what a firmware user does.
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}" -B "${WORK_DIR}/statsim" -G "${GENERATOR}" -DCMAKE_CXX_COMPILER=${CXX}
    -DSTATSIM_BUILD_TOOLS=OFF -DSTATSIM_BUILD_TESTS=OFF -DSTATSIM_BUILD_EXAMPLES=OFF
    -DCMAKE_INSTALL_PREFIX=${prefix})
run(${CMAKE_COMMAND} --install "${WORK_DIR}/statsim")
if(NOT EXISTS "${prefix}/include/statsim/world3.hpp")
  message(FATAL_ERROR "headers were not installed")
endif()

# The host tool, installed as the component `tools` from the main build (TOOLS_BUILD_DIR, when
# it has the tools): the consumer then generates a table at build time with statsim_add_tables.
set(with_tools OFF)
if(TOOLS_BUILD_DIR AND EXISTS "${TOOLS_BUILD_DIR}/bin/statsim")
  run(${CMAKE_COMMAND} --install "${TOOLS_BUILD_DIR}" --component tools --prefix "${prefix}")
  if(NOT EXISTS "${prefix}/lib/cmake/statsim/statsimToolsTargets.cmake" OR NOT EXISTS "${prefix}/bin/statsim")
    message(FATAL_ERROR "the tools component did not install bin/statsim and statsimToolsTargets.cmake")
  endif()
  set(with_tools ON)
endif()

run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${WORK_DIR}/consumer" -G "${GENERATOR}"
    -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build "${WORK_DIR}/consumer")
run_ok("${WORK_DIR}/consumer/consumer" consumer "find_package")
if(with_tools)
  if(NOT EXISTS "${WORK_DIR}/consumer/consumer_tables_tables/statsim/tables/block.hpp")
    message(FATAL_ERROR "statsim_add_tables generated no table")
  endif()
  file(READ "${WORK_DIR}/consumer/consumer_tables_tables/statsim/tables/block.hpp" table)
  string(FIND "${table}" "${WORK_DIR}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "the generated table names the build directory ${WORK_DIR}")
  endif()
  run_ok("${WORK_DIR}/consumer/consumer_own" consumer_own "statsim_add_tables")
  # Built again with nothing changed, the table is not generated again.
  run(${CMAKE_COMMAND} --build "${WORK_DIR}/consumer")
  if(last_output MATCHES "statsim gather")
    message(FATAL_ERROR "the table was generated again with nothing changed:\n${last_output}")
  endif()
endif()

# The same project through add_subdirectory: the same includes (<statsim/...>, <statsim/tables/...>).
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${WORK_DIR}/subdirectory" -G "${GENERATOR}"
    -DCMAKE_CXX_COMPILER=${CXX} -DSTATSIM_SOURCE_DIR=${SOURCE_DIR} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build "${WORK_DIR}/subdirectory")
run_ok("${WORK_DIR}/subdirectory/consumer" consumer "add_subdirectory")
