#pragma once
/// @file
/// Build-wide options of the statsim runtime, in one place.
///
/// Units are SI throughout: metres, seconds, kilograms, radians. World up is +z in 3D and +y in
/// 2D; frames are right-handed. The runtime never allocates and never throws: every fallible call
/// returns a `statsim::Status`.
///
/// Options are macros with a value. Put overrides in a header of your own and name it with
/// `-DSTATSIM_USER_CONFIG="my_config.hpp"`, or define them on the command line. Every option is
/// checked below, so a wrong value fails the build instead of being ignored.

#ifdef STATSIM_USER_CONFIG
#include STATSIM_USER_CONFIG
#endif

#include <cstdint>

/// 1: STATSIM_ASSERT checks internal invariants and calls the assert handler on failure.
/// 0: the checks compile to nothing. Default: 1 unless NDEBUG is defined.
/// Bad input from callers is never an assertion: it is a Status, in every build. The one
/// exception is an id past the end handed to an accessor that returns a reference
/// (`WorldCore::body()`, `plane()`, `shape()`): a bug in the caller, asserted, and memory-safe
/// where assertions are off; `WorldCore::find_body()` is the checked lookup.
#ifndef STATSIM_ENABLE_ASSERT
#ifdef NDEBUG
#define STATSIM_ENABLE_ASSERT 0
#else
#define STATSIM_ENABLE_ASSERT 1
#endif
#endif
#if STATSIM_ENABLE_ASSERT != 0 && STATSIM_ENABLE_ASSERT != 1
#error "STATSIM_ENABLE_ASSERT must be 0 or 1"
#endif

/// 1: the default assert handler prints "FILE:LINE: statsim assertion failed: EXPRESSION" to
/// stderr, then aborts. 0: it only traps, needing no stdio (whose buffers allocate on bare-metal
/// C libraries, and imports system calls into WebAssembly). Default: 1 on an operating system
/// (Unix, macOS, Windows), 0 elsewhere (bare metal, WebAssembly).
#ifndef STATSIM_ASSERT_MESSAGE
#if (defined(__unix__) || defined(__APPLE__) || defined(_WIN32)) && !defined(__EMSCRIPTEN__)
#define STATSIM_ASSERT_MESSAGE 1
#else
#define STATSIM_ASSERT_MESSAGE 0
#endif
#endif
#if STATSIM_ASSERT_MESSAGE != 0 && STATSIM_ASSERT_MESSAGE != 1
#error "STATSIM_ASSERT_MESSAGE must be 0 or 1"
#endif
#if STATSIM_ASSERT_MESSAGE
#include <cstdio>
#include <cstdlib>
#endif

/// 1: a world can run parts of its step on worker threads that the program lends it
/// (`WorldDef::workers`, statsim/README.md "Workers"). 0: that code is left out, and a world
/// refuses `Workers::count` above 1 with `Status::invalid_parameter`. Default: 1 on an operating
/// system (Unix, macOS, Windows), 0 elsewhere (bare metal, WebAssembly), where it would be code
/// that nothing calls.
#ifndef STATSIM_WORKERS
#if (defined(__unix__) || defined(__APPLE__) || defined(_WIN32)) && !defined(__EMSCRIPTEN__)
#define STATSIM_WORKERS 1
#else
#define STATSIM_WORKERS 0
#endif
#endif
#if STATSIM_WORKERS != 0 && STATSIM_WORKERS != 1
#error "STATSIM_WORKERS must be 0 or 1"
#endif

/// 1: a world with hull contacts (`BodyContacts::hulls`) keeps, for each pair the impact pass
/// found touching at a face, the contact's normal and reach (`detail::PairHull`, 16 bytes in 3D
/// and 12 in 2D, room for 2 per body, at most `MaxPairs`), so that the later passes of the step
/// read them instead of rotating the face and reading the support map again; touching pairs
/// beyond the room are found afresh. The results are the same bit for bit either way. 0: no such
/// storage; every pass finds the contacts afresh. Default: 1 on an operating system (Unix, macOS,
/// Windows), 0 elsewhere (bare metal, WebAssembly), where the bytes count for more than the time.
#ifndef STATSIM_HULL_CACHE
#if (defined(__unix__) || defined(__APPLE__) || defined(_WIN32)) && !defined(__EMSCRIPTEN__)
#define STATSIM_HULL_CACHE 1
#else
#define STATSIM_HULL_CACHE 0
#endif
#endif
#if STATSIM_HULL_CACHE != 0 && STATSIM_HULL_CACHE != 1
#error "STATSIM_HULL_CACHE must be 0 or 1"
#endif

/// Version of the layout of generated signature tables. A table generated for another version
/// fails to compile against this runtime (the tables static_assert on it).
#define STATSIM_TABLE_FORMAT_VERSION 2
/// Additions to format 2 that older tables can do without: 1 adds the mesh frame and the
/// body-body data (`ContactView`), 2 the landing data (`LandingView`), 3 the settling data
/// (`SettleView`), 4 the spin measure (`ResponseSpin`), 5 its value `ResponseSpin::energy`. A
/// table of an older minor format still loads; one that needs a newer one checks this with `#if`
/// and stops with a message on a runtime that lacks it.
#define STATSIM_TABLE_FORMAT_MINOR 5

namespace statsim {

/// The floating-point type of every quantity in the runtime. Tables are generated for it.
using Scalar = float;

/// Called when an internal invariant fails (a bug in statsim, or an id past the end, see
/// STATSIM_ENABLE_ASSERT). `expression`, `file` and `line` name the failed check. The default
/// handler prints them and aborts (see STATSIM_ASSERT_MESSAGE; without it, it traps);
/// firmware can log and reset, a host test can record. A handler may return, in which case the
/// runtime carries on (the result is then unspecified, but memory-safe).
using AssertHandler = void (*)(const char* expression, const char* file, int line);

namespace detail {
#if STATSIM_ASSERT_MESSAGE
[[noreturn]] inline void default_assert_handler(const char* expression, const char* file, int line)
{
  std::fprintf(stderr, "%s:%d: statsim assertion failed: %s\n", file, line, expression);
  std::fflush(stderr);
  std::abort();
}
#else
[[noreturn]] inline void default_assert_handler(const char*, const char*, int) { __builtin_trap(); }
#endif
inline AssertHandler& assert_handler_slot()
{
  static AssertHandler handler = &default_assert_handler;
  return handler;
}
}  // namespace detail

/// Replaces the assert handler; pass nullptr to restore the default. Returns the previous one.
inline AssertHandler set_assert_handler(AssertHandler handler)
{
  AssertHandler previous = detail::assert_handler_slot();
  detail::assert_handler_slot() = handler ? handler : &detail::default_assert_handler;
  return previous;
}

namespace detail {
/// True when the code that includes this header is compiled to fuse a multiply and an add into
/// one rounding (`-ffp-contract=fast`, gcc's default outside ISO mode, or `on`, clang's, with
/// FMA hardware) or to keep excess precision (x87): either changes results in the last bits, and
/// so the hashes. With x = 1 + 2^-12 and c = 1 + 2^-11, x * x = 1 + 2^-11 + 2^-24 exactly; rounded
/// to float that is a tie, to even, c; so x * x - c is 0 when the product is rounded and 2^-24
/// when it is fused with the subtraction (or held wider). The volatile reads keep the compiler
/// from folding the expression at compile time, where it would round as the language says.
inline bool float_contraction()
{
  volatile Scalar x_in = Scalar(1) + Scalar(1) / Scalar(4096);
  volatile Scalar c_in = Scalar(1) + Scalar(1) / Scalar(2048);
  const Scalar x = x_in;
  const Scalar c = c_in;
  return x * x - c != 0;
}
}  // namespace detail

}  // namespace statsim

#if STATSIM_ENABLE_ASSERT
#define STATSIM_ASSERT(cond)                                                      \
  do {                                                                            \
    if (!(cond)) ::statsim::detail::assert_handler_slot()(#cond, __FILE__, __LINE__); \
  } while (0)
#else
#define STATSIM_ASSERT(cond) \
  do {                       \
  } while (0)
#endif
