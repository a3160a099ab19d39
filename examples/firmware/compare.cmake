# Runs the firmware under QEMU (mps2-an386, semihosting, -icount shift=0) and the host build of
# the same source, and fails unless both succeed and print the same world lines. Then the host
# build loads the snapshots the firmware printed (`firmware_host --snapshots FILE`), steps them
# as the firmware did, and must print the firmware's hashes of their continuations.
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

# Snapshots saved on the Cortex-M, continued on the host.
set(snap_pattern "snap[23] continued [^\n]*hash 0x[0-9a-f]+")
string(REGEX MATCHALL "${snap_pattern}" fw_snaps "${fw_all}")
list(LENGTH fw_snaps n_snaps)
if(NOT n_snaps EQUAL 2)
  message(FATAL_ERROR "expected 2 snapshot lines from the firmware, got ${n_snaps}")
endif()
get_filename_component(fw_name ${ELF} NAME_WE)
set(fw_file ${CMAKE_CURRENT_BINARY_DIR}/${fw_name}_output.txt)
file(WRITE ${fw_file} "${fw_all}")
execute_process(COMMAND ${HOST} --snapshots ${fw_file} RESULT_VARIABLE load_rc OUTPUT_VARIABLE load_out
                ERROR_VARIABLE load_err TIMEOUT 120)
message("host, continuing the firmware's snapshots (exit ${load_rc}):\n${load_out}${load_err}")
string(REGEX MATCHALL "${snap_pattern}" host_snaps "${load_out}")
if(NOT load_rc EQUAL 0 OR NOT host_snaps STREQUAL fw_snaps)
  message(FATAL_ERROR "the host's continuation of the firmware's snapshots differs:\n  host: ${host_snaps}\n  firmware: ${fw_snaps}")
endif()

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
