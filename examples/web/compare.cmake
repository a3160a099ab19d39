# Runs the host build of the firmware example's scenes (f32 and i16 tables) and the web build of
# the same scenes, in Node (run-node.mjs) or in headless Chromium (chromium.mjs), and fails
# unless both succeed and print the same world lines. With DEMO_HOST (web_demo_host), the page's
# own pour too, in three short scenes (bunnies; L-shapes without resting conditions; 2D squares):
# the lines, but for the time per step, must be equal.
#   cmake -DHOST=firmware_host -DHOST_I16=firmware_host_i16 [-DDEMO_HOST=web_demo_host] -DNODE=node
#         -DSCRIPT=run-node.mjs -DSITE=build/web/site [-DMODULES=build/web-node/node_modules] -P compare.cmake
foreach(v HOST HOST_I16 NODE SCRIPT SITE)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "compare.cmake: -D${v}=... is required")
  endif()
endforeach()

set(host_out "")
foreach(host ${HOST} ${HOST_I16})
  execute_process(COMMAND ${host} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  message("host ${host} (exit ${rc}):\n${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the host build failed (${rc})")
  endif()
  string(APPEND host_out "${out}")
endforeach()

set(web_args ${SCRIPT} --site ${SITE} --check)
if(DEFINED MODULES)
  list(APPEND web_args --modules ${MODULES})
endif()
# The page's pours: the query of index.html?bench and the same scene's web_demo_host options.
set(pours "shape=bunny&n=500&steps=200&warmup=0" "shape=lshape&n=500&steps=200&warmup=0&rest=0"
          "shape=square&n=500&steps=200&warmup=0")
set(pour_options_0 --shape bunny --n 500 --steps 200 --warmup 0)
set(pour_options_1 --shape lshape --n 500 --steps 200 --warmup 0 --no-rest)
set(pour_options_2 --shape square --n 500 --steps 200 --warmup 0)
set(demo_host_out "")
if(DEFINED DEMO_HOST)
  foreach(k 0 1 2)
    list(GET pours ${k} query)
    list(APPEND web_args --bench ${query})
    execute_process(COMMAND ${DEMO_HOST} ${pour_options_${k}} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                    ERROR_VARIABLE err TIMEOUT 300)
    string(JOIN " " shown ${pour_options_${k}})
    message("host ${DEMO_HOST} ${shown} (exit ${rc}):\n${out}${err}")
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "web_demo_host failed (${rc})")
    endif()
    string(APPEND demo_host_out "${out}")
  endforeach()
endif()
execute_process(COMMAND ${NODE} ${web_args} RESULT_VARIABLE web_rc OUTPUT_VARIABLE web_out ERROR_VARIABLE web_err
                TIMEOUT 300)
message("web build, ${SCRIPT} (exit ${web_rc}):\n${web_out}${web_err}")
if(NOT web_rc EQUAL 0)
  message(FATAL_ERROR "the web build failed (${web_rc})")
endif()

# Six lines: three per precision.
include(${CMAKE_CURRENT_LIST_DIR}/../firmware/world_lines.cmake)
expect_same_world_lines("${host_out}" "${web_out}" 6 "the web build")

if(DEFINED DEMO_HOST)
  # The time per step differs, the rest must not.
  foreach(v demo_host_out web_out)
    string(REGEX MATCHALL "web_demo [^\n]*hash 0x[0-9a-f]+" lines "${${v}}")
    string(REGEX REPLACE " ms_per_step [0-9.]+" "" ${v}_pours "${lines}")
  endforeach()
  list(LENGTH demo_host_out_pours n)
  if(NOT n EQUAL 3)
    message(FATAL_ERROR "expected three pour lines from web_demo_host, got ${n}")
  endif()
  if(NOT demo_host_out_pours STREQUAL web_out_pours)
    message(FATAL_ERROR "the page's pour differs from the host's:\n  host: ${demo_host_out_pours}\n  web:  ${web_out_pours}")
  endif()
endif()
message("host and web build agree bit for bit")
