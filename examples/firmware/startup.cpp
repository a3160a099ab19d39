// Start-up code and platform services of the firmware example on a bare Cortex-M4F (QEMU's
// mps2-an386): the vector table, the reset handler, semihosting output and exit, a SysTick
// clock and the stack's high-water mark. See mps2-an386.ld for the memory map.

#include <cstdint>
#include <cstdlib>
#include <new>

extern "C" {
// From the linker script.
extern std::uint32_t __data_load[], __data_start[], __data_end[], __bss_start[], __bss_end[];
extern std::uint32_t __stack_limit[], __stack_top[];
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();

void statsim_init();
[[noreturn]] void statsim_exit(int status);
void statsim_reset();
void statsim_fault();
void statsim_systick();
}

namespace {

// ARM semihosting: `bkpt 0xAB` with the operation in r0 and its argument in r1 (QEMU with
// -semihosting-config enable=on). SYS_WRITE0 writes a NUL-terminated string (QEMU prints it on
// its stderr); SYS_EXIT ends the emulator, with status 0 for ADP_Stopped_ApplicationExit and 1
// for any other reason.
constexpr int sys_write0 = 0x04;
constexpr int sys_exit = 0x18;
constexpr std::uintptr_t adp_application_exit = 0x20026;
constexpr std::uintptr_t adp_runtime_error = 0x20023;

int semihost(int op, const void* arg)
{
  register int r0 asm("r0") = op;
  register const void* r1 asm("r1") = arg;
  asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

[[noreturn]] void exit_with(int status)
{
  semihost(sys_exit, reinterpret_cast<const void*>(status == 0 ? adp_application_exit : adp_runtime_error));
  for (;;) {
  }
}

// SysTick counts the processor clock (25 MHz on the MPS2) down from 2^24 - 1; the interrupt
// counts wraps. Under `qemu -icount shift=0` the virtual clock advances 1 ns per instruction, so
// a tick is 40 instructions.
volatile std::uint32_t systick_wraps = 0;
constexpr std::uintptr_t syst_csr = 0xE000E010, syst_rvr = 0xE000E014, syst_cvr = 0xE000E018;
inline volatile std::uint32_t& reg(std::uintptr_t address) { return *reinterpret_cast<volatile std::uint32_t*>(address); }

constexpr std::uint32_t stack_paint = 0x5717c0deu;

}  // namespace

extern "C" {

// Runs once the FPU is on (see statsim_reset): RAM set-up, the SysTick clock, static constructors.
void statsim_init()
{
  for (std::uint32_t *src = __data_load, *dst = __data_start; dst < __data_end;) *dst++ = *src++;
  for (std::uint32_t* p = __bss_start; p < __bss_end; ++p) *p = 0;
  // Paint the stack below this frame so that its high-water mark can be read at the end.
  const std::uintptr_t frame = reinterpret_cast<std::uintptr_t>(__builtin_frame_address(0)) - 128;
  for (std::uint32_t* p = __stack_limit; reinterpret_cast<std::uintptr_t>(p) < frame; ++p) *p = stack_paint;
  reg(syst_rvr) = 0x00ffffffu;
  reg(syst_cvr) = 0;
  reg(syst_csr) = 0x7u;  // processor clock, interrupt on wrap, enabled
  for (void (**f)() = __init_array_start; f < __init_array_end; ++f) (*f)();
}

[[noreturn]] void statsim_exit(int status) { exit_with(status); }

// The reset handler may not touch the FPU before CPACR grants access to CP10 and CP11, and
// compiled code might (saving registers, copying memory), so it is written in assembly.
__attribute__((naked, noreturn)) void statsim_reset()
{
  asm volatile(
      "ldr r0, =0xE000ED88\n"  // CPACR
      "ldr r1, [r0]\n"
      "orr r1, r1, #0x00F00000\n"  // CP10, CP11: full access
      "str r1, [r0]\n"
      "dsb\n"
      "isb\n"
      "bl statsim_init\n"
      "bl main\n"
      "b statsim_exit\n");
}

void statsim_fault()
{
  semihost(sys_write0, "firmware: fault\n");
  exit_with(1);
}

void statsim_systick() { systick_wraps = systick_wraps + 1; }

using Handler = void (*)();
__attribute__((section(".vectors"), used)) const Handler statsim_vectors[16] = {
    reinterpret_cast<Handler>(__stack_top),  // initial stack pointer
    statsim_reset,
    statsim_fault,  // NMI
    statsim_fault,  // HardFault
    statsim_fault,  // MemManage
    statsim_fault,  // BusFault
    statsim_fault,  // UsageFault
    nullptr, nullptr, nullptr, nullptr,
    statsim_fault,  // SVCall
    statsim_fault,  // DebugMonitor
    nullptr,
    statsim_fault,  // PendSV
    statsim_systick,
};

}  // extern "C"

// Platform services main.cpp uses.
namespace platform {

void write(const char* text) { semihost(sys_write0, text); }

[[noreturn]] void fail() { exit_with(1); }

std::uint64_t clock_ticks()
{
  std::uint32_t wraps, count;
  do {
    wraps = systick_wraps;
    count = reg(syst_cvr);
  } while (wraps != systick_wraps);
  return (std::uint64_t(wraps) << 24) + (0x00ffffffu - count);
}

std::uint32_t stack_used()
{
  const std::uint32_t* p = __stack_limit;
  while (p < __stack_top && *p == stack_paint) ++p;
  return std::uint32_t(reinterpret_cast<std::uintptr_t>(__stack_top) - reinterpret_cast<std::uintptr_t>(p));
}

std::uint32_t stack_size()
{
  return std::uint32_t(reinterpret_cast<std::uintptr_t>(__stack_top) - reinterpret_cast<std::uintptr_t>(__stack_limit));
}

}  // namespace platform

#ifdef FIRMWARE_HEAP_PROBE
// A program that allocates, built from this file alone: its link must fail, since the toolchain
// file leaves malloc and operator new undefined (test firmware_no_heap).
int main()
{
  int* volatile p = new int(1);
  delete p;
  void* volatile m = std::malloc(8);
  std::free(m);
  return 0;
}
#endif
