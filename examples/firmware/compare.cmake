# Runs the firmware under QEMU (mps2-an386, semihosting, -icount shift=0) and the host build of
# the same source, and fails unless both succeed and print the same world lines.
#   cmake -DQEMU=qemu-system-arm -DELF=firmware.elf -DHOST=firmware_host -P compare.cmake
foreach(v QEMU ELF HOST)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "compare.cmake: -D${v}=... is required")
  endif()
endforeach()

execute_process(COMMAND ${HOST} RESULT_VARIABLE host_rc OUTPUT_VARIABLE host_out ERROR_VARIABLE host_err
                TIMEOUT 120)
# Semihosting output arrives on QEMU's stderr; SYS_EXIT gives status 0 only for a clean exit.
execute_process(COMMAND ${QEMU} -M mps2-an386 -nographic -monitor none -serial none -icount shift=0
                        -semihosting-config enable=on,target=native -kernel ${ELF}
                RESULT_VARIABLE fw_rc OUTPUT_VARIABLE fw_out ERROR_VARIABLE fw_err TIMEOUT 240)
set(fw_all "${fw_out}${fw_err}")
message("host (exit ${host_rc}):\n${host_out}${host_err}")
message("firmware under qemu (exit ${fw_rc}):\n${fw_all}")
if(NOT host_rc EQUAL 0)
  message(FATAL_ERROR "the host build failed (${host_rc})")
endif()
if(NOT fw_rc EQUAL 0)
  message(FATAL_ERROR "the firmware failed under qemu (${fw_rc})")
endif()

include(${CMAKE_CURRENT_LIST_DIR}/world_lines.cmake)
expect_same_world_lines("${host_out}" "${fw_all}" 3 "the firmware")

# Under -icount shift=0 a SysTick count (25 MHz) is 40 instructions.
string(REGEX MATCHALL "firmware: (world[23]|models) systick [0-9]+ steps [0-9]+" clocks "${fw_all}")
foreach(c IN LISTS clocks)
  string(REGEX REPLACE "firmware: (world[23]|models) systick ([0-9]+) steps ([0-9]+)" "\\1;\\2;\\3" f "${c}")
  list(GET f 0 world)
  list(GET f 1 ticks)
  list(GET f 2 steps)
  math(EXPR per_step "${ticks} * 40 / ${steps}")
  message("${world}: about ${per_step} instructions per step")
endforeach()
message("host and firmware agree bit for bit")
