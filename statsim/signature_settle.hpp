#pragma once
/// @file
/// The settling data of a signature (table format 2.3, optional): how long a body takes to come
/// to rest in each rest pose once it is slow, as quantiles per pose. The view the runtime reads
/// (`SettleView`) and the storage generated tables hold (`SettleData`). Included by signature.hpp.
///
/// Why. A body does not stop when it reaches its pose: a box falls flat at once, a bunny rocks
/// on its curved back for seconds. The resting conditions alone (paper 3.4) turn every shape into
/// its pose in the same few tenths of a second, whatever the pose's shape; the reference's
/// settling is a property of the pose (tools/fidelity/README.md, "Where the time to rest goes").
///
/// What is stored (`statsim gather --settle`). The rest drops each record, besides the pose they end in, the
/// time from the last moment the body moved at statsim's default settle speed (0.5 m/s, centre or
/// farthest point by spin, `WorldDef::settle_speed`) or faster to the moment it stayed slower
/// than the quiet speed (0.01 m/s) for good: a drop still moving at the gathering's time limit
/// counts with the time it had. Per pose, `quantiles` values of those times, at the
/// probabilities (k + 1/2) / quantiles, k = 0 .. quantiles - 1, non-decreasing.
///
/// How the runtime uses it (statsim/detail/sleep.hpp): a body that chooses its pose on the
/// ground draws a settling time from the pose's quantiles (one `uniform()`, linear between
/// them, the ends held), turns into the pose and rocks about it, a little, until the time has
/// passed (`settle_rock`); then it stops there and may sleep.

#include "statsim/signature_contact.hpp"

#include <array>
#include <cstdint>

namespace statsim {

/// Quantiles per pose a table may hold.
constexpr std::uint32_t max_settle_quantiles = 64;
/// The longest settling time a table may hold, s (an hour: longer is no settling).
constexpr Scalar max_settle_time = Scalar(3600);

/// The settling data a world reads (see the file comment); absent (`present()` false) in tables
/// without it, which then settle exactly as before.
struct SettleView {
  /// s, `quantiles` values per rest pose, poses in the order of the rest poses.
  Span<const Scalar> time;
  /// Values per pose, at the probabilities (k + 1/2) / quantiles: the values over the poses, or 0
  /// when they do not divide evenly (which `add_shape` refuses).
  std::uint32_t quantiles = 0;
  bool present() const { return time.size > 0; }
  /// The settling time of pose `pose` at probability `u` in [0, 1): linear between the
  /// quantiles, the first below the first probability and the last above the last.
  Scalar at(std::uint32_t pose, Scalar u) const
  {
    const Scalar* q = time.values + std::size_t(pose) * quantiles;
    const Scalar x = u * Scalar(quantiles) - Scalar(0.5);
    if (!(x > 0)) return q[0];
    const std::uint32_t k = std::uint32_t(x);
    if (k + 1 >= quantiles) return q[quantiles - 1];
    const Scalar f = x - Scalar(k);
    return q[k] + (q[k + 1] - q[k]) * f;
  }
};

/// Settling data of a generated signature; sizes are template arguments.
///   NR: rest poses (the signature's), NQ: quantiles per pose.
template <std::uint32_t NR, std::uint32_t NQ>
struct SettleData {
  static_assert(NR >= 1 && NQ >= 1, "a pose and a quantile at least");
  std::array<Scalar, NR * NQ> time;
};

/// The `settle` of a table without settling data (formats 2.0 to 2.2).
struct NoSettleData {};

}  // namespace statsim
