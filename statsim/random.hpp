#pragma once
/// @file
/// Deterministic random numbers: PCG32 (O'Neill's XSH-RR 64/32), one stream per body, and a
/// Gaussian sampler. No global state: every draw goes through a generator the caller owns.

#include "statsim/math.hpp"

#include <cstdint>

namespace statsim {

/// SplitMix64 finaliser: a bijective 64-bit mix, used to turn (seed, index) into stream ids.
constexpr std::uint64_t mix64(std::uint64_t z)
{
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/// PCG32: 64-bit state, 32-bit output, period 2^64 per stream, 2^63 streams.
class Pcg32 {
 public:
  static constexpr std::uint64_t multiplier = 6364136223846793005ull;

  /// The generator for stream `stream` of `seed`; distinct streams are independent sequences.
  constexpr Pcg32(std::uint64_t seed, std::uint64_t stream) : state_(0), increment_((stream << 1u) | 1u)
  {
    next_u32();
    state_ += seed;
    next_u32();
  }

  /// Resumes a generator from a saved state (see `state()`).
  static constexpr Pcg32 resume(std::uint64_t state, std::uint64_t stream)
  {
    Pcg32 g;
    g.state_ = state;
    g.increment_ = (stream << 1u) | 1u;
    return g;
  }

  constexpr std::uint32_t next_u32()
  {
    const std::uint64_t old = state_;
    state_ = old * multiplier + increment_;
    const std::uint32_t xorshifted = std::uint32_t(((old >> 18u) ^ old) >> 27u);
    const std::uint32_t rot = std::uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  /// Uniform in [0, 1), a multiple of 2^-24.
  constexpr float uniform() { return float(next_u32() >> 8) * (1.0f / 16777216.0f); }

  /// Uniform in [lo, hi).
  constexpr float uniform(float lo, float hi)
  {
    const float u = uniform();
    return lo + (hi - lo) * u;
  }

  /// Two independent standard normal samples (Marsaglia's polar method).
  /// Consumes a variable number of draws (on average 2.55), always the same for the same state.
  void gaussian_pair(float& a, float& b)
  {
    float u, v, s;
    do {
      // Each draw is taken into its own variable: the order of two draws inside one
      // expression is unspecified in C++ and differs between compilers.
      const float du = uniform();
      const float dv = uniform();
      u = 2.0f * du - 1.0f;
      v = 2.0f * dv - 1.0f;
      s = u * u + v * v;
    } while (s >= 1.0f || s == 0.0f);
    const float f = std::sqrt(-2.0f * detail::portable_log(s) / s);
    a = u * f;
    b = v * f;
  }

  /// One standard normal sample (the partner sample of the pair is discarded).
  float gaussian()
  {
    float a, b;
    gaussian_pair(a, b);
    return a;
  }

  /// A normal sample with the given mean and standard deviation.
  float gaussian(float mean, float stddev)
  {
    const float g = gaussian();
    return mean + stddev * g;
  }

  constexpr std::uint64_t state() const { return state_; }

 private:
  constexpr Pcg32() : state_(0), increment_(1) {}
  std::uint64_t state_;
  std::uint64_t increment_;
};

/// Stream id of body `index` in a world seeded with `seed`: each body draws from its own stream,
/// so adding a body or reordering contacts never shifts another body's random sequence.
constexpr std::uint64_t body_stream(std::uint64_t seed, std::uint32_t index)
{
  return mix64(seed ^ mix64(0x5747a7u + std::uint64_t(index)));
}

namespace detail {
/// A point drawn uniformly from the unit disc without its centre, by rejection; `s` = x^2 + y^2.
inline void disc_point(Pcg32& rng, float& x, float& y, float& s)
{
  do {
    const float du = rng.uniform();  // one draw per statement: see gaussian_pair
    const float dv = rng.uniform();
    x = 2.0f * du - 1.0f;
    y = 2.0f * dv - 1.0f;
    s = x * x + y * y;
  } while (s >= 1.0f || s == 0.0f);
}
}  // namespace detail

/// An orientation drawn uniformly over all rotations (body to world, unit length; the Haar
/// measure), from `rng`: for bodies dropped in random poses. Uses only square roots, which IEEE
/// arithmetic rounds exactly, so every platform draws the same bits. Consumes a variable number
/// of draws, always the same for the same state.
template <int D>
typename Space<D>::Rot random_orientation(Pcg32& rng);

/// 3D: Marsaglia's uniform point on the 3-sphere (1972), which is a uniform unit quaternion. With
/// (x1, y1) and (x2, y2) uniform in the unit disc, s1 and s2 their squared lengths, the point
/// (x1, y1, x2 f, y2 f) with f = sqrt((1 - s1) / s2) has length^2 s1 + s2 (1 - s1) / s2 = 1.
template <>
inline Quaternion random_orientation<3>(Pcg32& rng)
{
  float x1, y1, s1, x2, y2, s2;
  detail::disc_point(rng, x1, y1, s1);
  detail::disc_point(rng, x2, y2, s2);
  const float f = std::sqrt((1.0f - s1) / s2);
  return Quaternion(x1, y1, x2 * f, y2 * f);  // (w, x, y, z)
}

/// 2D: a uniform point of the unit disc, scaled to the unit circle: a uniform angle.
template <>
inline Rot2 random_orientation<2>(Pcg32& rng)
{
  float x, y, s;
  detail::disc_point(rng, x, y, s);
  const float r = std::sqrt(s);
  return {x / r, y / r};
}

}  // namespace statsim
