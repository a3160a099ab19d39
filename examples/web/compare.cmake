# Runs the host build of the firmware example's scenes (f32 and i16 tables) and the web build of
# the same scenes, in Node (run-node.mjs) or in headless Chromium (chromium.mjs), and fails
# unless both succeed and print the same world lines.
#   cmake -DHOST=firmware_host -DHOST_I16=firmware_host_i16 -DNODE=node -DSCRIPT=run-node.mjs
#         -DSITE=build/web/site [-DMODULES=build/web-node/node_modules] -P compare.cmake
foreach(v HOST HOST_I16 NODE SCRIPT SITE)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "compare.cmake: -D${v}=... is required")
  endif()
endforeach()

set(host_out "")
foreach(host ${HOST} ${HOST_I16})
  execute_process(COMMAND ${host} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
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
execute_process(COMMAND ${NODE} ${web_args} RESULT_VARIABLE web_rc OUTPUT_VARIABLE web_out ERROR_VARIABLE web_err
                TIMEOUT 300)
message("web build, ${SCRIPT} (exit ${web_rc}):\n${web_out}${web_err}")
if(NOT web_rc EQUAL 0)
  message(FATAL_ERROR "the web build failed (${web_rc})")
endif()

string(REGEX MATCHALL "(world[23]|models) [^\n]*hash 0x[0-9a-f]+" host_lines "${host_out}")
string(REGEX MATCHALL "(world[23]|models) [^\n]*hash 0x[0-9a-f]+" web_lines "${web_out}")
list(LENGTH host_lines n)
if(NOT n EQUAL 6)
  message(FATAL_ERROR "expected six world lines from the host builds (three per precision), got ${n}")
endif()
if(NOT host_lines STREQUAL web_lines)
  message(FATAL_ERROR "the web build's state differs from the host's:\n  host: ${host_lines}\n  web:  ${web_lines}")
endif()
message("host and web build agree bit for bit")
