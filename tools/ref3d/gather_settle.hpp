// The settling stage of `statsim gather` (statsim/signature_settle.hpp has the model): from the
// rest drops, already run for the rest poses, the quantiles of each kept pose's settling time.
// No reference engine runs here: each drop measured its own settling time (DropResult::
// settle_time, reference.hpp), from the last step at the settle speed or faster to the step after
// which it stayed slower than the quiet speed; a drop that did not settle within its time limit
// counts with the time it had, a lower bound.
//
// Every drop, settled or not, belongs to the kept pose nearest its final body-frame up vector
// (the largest dot product with the pose's normal, as the runtime's nearest_rest_pose picks), so
// drops that ended in a pose the table leaves out still count for the pose a body would take.
#pragma once

#include "ref3d/gather_options.hpp"
#include "ref3d/gather_trials.hpp"
#include "ref3d/rest_poses.hpp"

#include <vector>

namespace statsim::tools::ref3d {

/// What the settling stage measured (a part of GatherResult).
struct SettleFit {
  int quantiles = 0;               ///< per pose
  double settle_speed = 0.0;       ///< m/s, as measured with
  double quiet_speed = 0.0;        ///< m/s
  std::vector<double> time;        ///< s, `quantiles` per kept pose in the poses' order, non-decreasing in each
  std::vector<int> drops;          ///< drops assigned to each kept pose
  std::vector<double> mean;        ///< s, each pose's mean settling time over its drops (or all)
  int time_limited = 0;            ///< drops that counted with their time limit (not settled)
  double seconds = 0.0;
  bool present() const { return !time.empty(); }
};

/// The quantiles of `times` at the probabilities p = (k + 1/2) / `quantiles`, k = 0 .. quantiles
/// - 1: with the times sorted, x_0 <= .. <= x_(n-1), the value at p is the linear interpolation of
/// the order statistics at h = p n - 1/2, h clamped to [0, n - 1] (x_h exactly where h is whole).
/// Each order statistic thus stands at the middle of its 1/n of probability, the rule the
/// runtime's SettleView::at reads the quantiles back by. Non-decreasing; empty when `times` is.
std::vector<double> settle_quantiles(std::vector<double> times, int quantiles);

/// The stage for the kept poses `rest` (fit_rest_poses on the same `drops`) with the options `o`:
/// quantiles per pose clamped to [0, statsim::max_settle_time]; a pose no drop is nearest to
/// (which fit_rest_poses does not make) takes the quantiles of all drops. Empty without poses.
SettleFit fit_settle(const std::vector<DropTrial>& drops, const std::vector<RestPose>& rest, const GatherOptions& o);

}  // namespace statsim::tools::ref3d
