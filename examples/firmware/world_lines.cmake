# expect_same_world_lines(HOST_OUTPUT OTHER_OUTPUT COUNT WHAT): the world lines of a run of the
# firmware example's scenes ("world3 ... hash 0x...", "world2 ...", "models ..."), COUNT of them in
# the host build's output, must be those of the other build (WHAT names it in the message), in
# order. Shared by compare.cmake (QEMU) and examples/web/compare.cmake (Node, Chromium).
function(expect_same_world_lines host_output other_output count what)
  set(pattern "(world[23]|models) [^\n]*hash 0x[0-9a-f]+")
  string(REGEX MATCHALL "${pattern}" host_lines "${host_output}")
  string(REGEX MATCHALL "${pattern}" other_lines "${other_output}")
  list(LENGTH host_lines n)
  if(NOT n EQUAL count)
    message(FATAL_ERROR "expected ${count} world lines from the host build, got ${n}")
  endif()
  if(NOT host_lines STREQUAL other_lines)
    message(FATAL_ERROR "${what}'s state differs from the host's:\n  host: ${host_lines}\n  ${what}: ${other_lines}")
  endif()
endfunction()
