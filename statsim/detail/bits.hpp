#pragma once
/// @file
/// Bit sets over body slots (`WorldData::awake`, `flagged`, `rolled`): the phases of a step walk
/// the set bits instead of every body.

#include <cstdint>

namespace statsim {
namespace detail {

/// Words of a bit set of `n` bodies.
constexpr std::uint32_t bit_words(std::uint32_t n)
{
  return (n + 31) / 32;
}

/// Index of the lowest set bit of `x` (not 0).
inline std::uint32_t lowest_bit(std::uint32_t x)
{
#if defined(__GNUC__) || defined(__clang__)
  return std::uint32_t(__builtin_ctz(x));
#else
  std::uint32_t i = 0;
  while (!(x & 1u)) {
    x >>= 1;
    ++i;
  }
  return i;
#endif
}

/// Calls `f(i)` for every body i whose bit is set in the first `bit_words(count)` words, in
/// increasing order, at a cost of one word per 32 bodies plus the bodies set. Each word is read
/// once, before its bodies are visited: `f` may clear the bit of the body it is given.
template <class F>
void for_each_set(const std::uint32_t* words, std::uint32_t count, F&& f)
{
  const std::uint32_t n = bit_words(count);
  for (std::uint32_t k = 0; k < n; ++k)
    for (std::uint32_t bits = words[k]; bits != 0; bits &= bits - 1) f(k * 32 + lowest_bit(bits));
}

inline void set_bit(std::uint32_t* words, std::uint32_t i)
{
  words[i / 32] |= std::uint32_t(1) << (i % 32);
}
inline bool bit_set(const std::uint32_t* words, std::uint32_t i) { return (words[i / 32] >> (i % 32)) & 1u; }
inline void clear_bit(std::uint32_t* words, std::uint32_t i)
{
  words[i / 32] &= ~(std::uint32_t(1) << (i % 32));
}

}  // namespace detail
}  // namespace statsim
