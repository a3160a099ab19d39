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
/// Bad input from callers is never an assertion: it is a Status, in every build.
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

/// Version of the layout of generated signature tables. A table generated for another version
/// fails to compile against this runtime (the tables static_assert on it).
#define STATSIM_TABLE_FORMAT_VERSION 2
/// Additions to format 2 that older tables can do without: 1 adds the mesh frame and the
/// body-body data (`ContactView`). A table of format 2.0 still loads; one that needs 2.1 checks
/// this with `#if` and stops with a message on a runtime that lacks it.
#define STATSIM_TABLE_FORMAT_MINOR 1

namespace statsim {

/// The floating-point type of every quantity in the runtime. Tables are generated for it.
using Scalar = float;

/// Called when an internal invariant fails (a bug in statsim, not bad input).
/// `expression`, `file` and `line` name the failed check. The default handler traps; firmware
/// can log and reset, a host test can record. A handler may return, in which case the runtime
/// carries on (the result is then unspecified, but memory-safe).
using AssertHandler = void (*)(const char* expression, const char* file, int line);

namespace detail {
[[noreturn]] inline void default_assert_handler(const char*, const char*, int) { __builtin_trap(); }
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
