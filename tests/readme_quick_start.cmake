# README.md's quick start for a user's own mesh, exactly as written: the two files and the
# commands of "Your own mesh" (after the set-up command, which built the build under test) are
# extracted from the README (each fenced block follows a
# "<!-- quick start: NAME -->" line) and run in a scratch directory, with the test mesh
# tests/meshes/block.stl as my_app/part.stl, HOME set to the scratch directory, and `build` the
# build directory under test. Run by CTest (test readme_quick_start).
#   cmake -DSOURCE_DIR=... -DBUILD_DIR=... -DWORK_DIR=... -P readme_quick_start.cmake
foreach(var SOURCE_DIR BUILD_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "readme_quick_start.cmake needs -D${var}=...")
  endif()
endforeach()
file(READ "${SOURCE_DIR}/README.md" readme)

# The fenced block after the marker line of `name`, without its fences.
function(extract name out_var)
  set(marker "<!-- quick start: ${name} -->\n```")
  string(FIND "${readme}" "${marker}" at)
  if(at LESS 0)
    message(FATAL_ERROR "README.md has no quick-start block '${name}'")
  endif()
  string(SUBSTRING "${readme}" ${at} -1 rest)
  string(FIND "${rest}" "\n" eol)
  math(EXPR eol "${eol} + 1")
  string(SUBSTRING "${rest}" ${eol} -1 rest)   # past the marker line
  string(FIND "${rest}" "\n" eol)
  math(EXPR eol "${eol} + 1")
  string(SUBSTRING "${rest}" ${eol} -1 rest)   # past the opening fence
  string(FIND "${rest}" "```" close)
  string(SUBSTRING "${rest}" 0 ${close} block)
  set(${out_var} "${block}" PARENT_SCOPE)
endfunction()

extract("my_app/CMakeLists.txt" cmake_text)
extract("my_app/main.cpp" cpp_text)
extract("commands" commands_text)

# The goal: at most 30 lines of code and three commands from a fresh clone, the first of them
# README's set-up command.
string(REGEX MATCHALL "\n" cmake_lines "${cmake_text}")
string(REGEX MATCHALL "\n" cpp_lines "${cpp_text}")
list(LENGTH cmake_lines n_cmake)
list(LENGTH cpp_lines n_cpp)
math(EXPR n_code "${n_cmake} + ${n_cpp}")
string(REGEX REPLACE "\n$" "" commands_text "${commands_text}")
string(REPLACE "\n" ";" commands "${commands_text}")
list(LENGTH commands n_commands)
message(STATUS "quick start: ${n_code} lines of code, ${n_commands} commands")
if(n_code GREATER 30 OR n_commands GREATER 2)
  message(FATAL_ERROR "the quick start must stay within 30 lines of code and 3 commands (the set-up command and 2)")
endif()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}/my_app")
file(WRITE "${WORK_DIR}/my_app/CMakeLists.txt" "${cmake_text}")
file(WRITE "${WORK_DIR}/my_app/main.cpp" "${cpp_text}")
configure_file("${SOURCE_DIR}/tests/meshes/block.stl" "${WORK_DIR}/my_app/part.stl" COPYONLY)
file(CREATE_LINK "${BUILD_DIR}" "${WORK_DIR}/build" SYMBOLIC)
set(ENV{HOME} "${WORK_DIR}")
# A small gathering (seconds instead of minutes; the body-body piles with their defaults alone take
# a minute): statsim_add_tables adds these options.
string(CONCAT _gather_options "--cos-theta 0.5,1 --cos-phi -1,1 --spin-ratios 0,1 --height-ratios 0,1,4 --trials 3 "
       "--height-trials 8 --rest-drops 24 --threads 2 --pair-trials 20 --packing-piles 1 --packing-bins 1 --packing-count 8")
set(ENV{STATSIM_GATHER_OPTIONS} "${_gather_options}")

foreach(command IN LISTS commands)
  message(STATUS "+ ${command}")
  execute_process(COMMAND bash -c "${command}" WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc
                  OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${command}\n${out}\n${err}")
  endif()
endforeach()
if(NOT out MATCHES "[0-9]+ of 100 asleep")
  message(FATAL_ERROR "the program printed: ${out}")
endif()
message(STATUS "${out}")
