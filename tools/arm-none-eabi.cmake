# CMake toolchain file for bare-metal Cortex-M4F (Debian's gcc-arm-none-eabi, newlib, libstdc++):
#   cmake -S examples/firmware -B build-fw -DCMAKE_TOOLCHAIN_FILE=tools/arm-none-eabi.cmake
# Thumb-2, single-precision FPU, hard-float ABI, -Os, no exceptions, no RTTI, no heap:
#  - -ffp-contract=off as on the host, so no multiply-add is fused (the FPv4 has vfma);
#  - -fno-math-errno: sqrt is the vsqrt instruction (exactly rounded, as on the host), not newlib's
#    sqrtf, whose errno pulls in 1 KB of reentrancy data;
#  - malloc, calloc, realloc (and newlib's reentrant forms) and every operator new are wrapped to
#    symbols nobody defines, so any code that could allocate fails the link ("undefined reference
#    to `__wrap_malloc'");
#  - no C++ run-time support for static objects beyond .init_array (the startup code runs it):
#    -fno-threadsafe-statics (no guard functions), -fno-use-cxa-atexit (nothing registered at
#    exit, and bare metal never exits).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_SIZE arm-none-eabi-size CACHE FILEPATH "arm-none-eabi-size")
set(CMAKE_NM arm-none-eabi-nm CACHE FILEPATH "arm-none-eabi-nm")
# No startup code or linker script is known to CMake's compiler checks: test by compiling only.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(_statsim_cpu "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard")
set(_statsim_common "${_statsim_cpu} -ffp-contract=off -fno-math-errno -ffunction-sections -fdata-sections")
set(CMAKE_C_FLAGS_INIT "${_statsim_common}")
set(CMAKE_ASM_FLAGS_INIT "${_statsim_cpu}")
set(CMAKE_CXX_FLAGS_INIT
    "${_statsim_common} -fno-exceptions -fno-rtti -fno-threadsafe-statics -fno-use-cxa-atexit")
# Build type MinSizeRel (-Os -DNDEBUG): examples/firmware makes it the default.

set(_statsim_no_heap "")
foreach(_sym malloc calloc realloc _malloc_r _calloc_r _realloc_r _Znwj _Znaj _ZnwjRKSt9nothrow_t
             _ZnajRKSt9nothrow_t _ZnwjSt11align_val_t _ZnajSt11align_val_t)
  string(APPEND _statsim_no_heap " -Wl,--wrap=${_sym}")
endforeach()
set(CMAKE_EXE_LINKER_FLAGS_INIT "${_statsim_cpu} -nostartfiles -Wl,--gc-sections${_statsim_no_heap}")

# Programs from the host. Packages too: the only one is Eigen, header-only and the same for
# every target (its config file lives in the host's /usr/share/eigen3).
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
