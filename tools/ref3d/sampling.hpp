// Deterministic random numbers for the 3D gathering: every trial draws from its own generator,
// seeded from (seed, stream, index) only, so results do not depend on threads or order.
#pragma once

#include "statsim/random.hpp"  // mix64, the runtime's SplitMix64 finaliser

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace statsim::tools::ref3d {

// TrialRng's `stream`, one per kind of trial, all here so that no two kinds share one (the
// committed tables depend on each value). gather: heights, responses, rest drops, and the checks
// (kCheckStream and kCheckStream + 1); gather-pairs: pair flights (kPairStream to
// kPairStream + 3), their heights and the bins; the landing stage's impacts with gravity and
// the runtime's draws at their contacts; the spin measure's draws at the response trials'.
constexpr std::uint64_t kHeightStream = 1;
constexpr std::uint64_t kResponseStream = 2;
constexpr std::uint64_t kRestStream = 3;
constexpr std::uint64_t kCheckStream = 5;
constexpr std::uint64_t kPairStream = 11;
constexpr std::uint64_t kPairHeightStream = 12;
constexpr std::uint64_t kBinStream = 16;
constexpr std::uint64_t kLandingStream = 20;
constexpr std::uint64_t kLandingDrawStream = 21;
constexpr std::uint64_t kSpinDrawStream = 22;

/// xoshiro256** seeded through SplitMix64 from (seed, stream, index).
class TrialRng {
public:
  TrialRng(std::uint64_t seed, std::uint64_t stream, std::uint64_t index)
  {
    std::uint64_t x = mix64(mix64(seed) ^ mix64(stream * 0x632be59bd9b4e019ull + 1) ^ (index * 0xd1342543de82ef95ull));
    for (auto& w : s_) {
      x = mix64(x);
      w = x;
    }
  }
  std::uint64_t next()
  {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  /// Uniform in [0, 1), 53 bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Uniform rotation (Shoemake's method), as a unit quaternion.
  Eigen::Quaterniond rotation()
  {
    const double u1 = uniform(), u2 = uniform(), u3 = uniform();
    constexpr double two_pi = 6.283185307179586476925286766559;
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
    return Eigen::Quaterniond(b * std::cos(two_pi * u3), a * std::sin(two_pi * u2), a * std::cos(two_pi * u2),
                              b * std::sin(two_pi * u3));
  }
  /// Uniform direction on the unit sphere.
  Eigen::Vector3d direction()
  {
    constexpr double two_pi = 6.283185307179586476925286766559;
    const double z = uniform(-1.0, 1.0), a = two_pi * uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z);
  }

private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4];
};

}  // namespace statsim::tools::ref3d
