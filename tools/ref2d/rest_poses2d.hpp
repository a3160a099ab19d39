// The rest-pose stage of `statsim gather2d`: from the drops' final up vectors to the table's rest
// poses (greedy clustering, snapping to hull edges, families under the shape's symmetry and which
// poses are kept, by common/rest_families.hpp). Needs no Box2D: the drops are given.
#pragma once

#include "ref2d/gather2d_options.hpp"
#include "ref2d/polygon2d.hpp"

#include <vector>

namespace statsim::tools {

struct RestCluster {
  Point2 normal;           ///< body-frame up vector (unit)
  double height = 0.0;     ///< core-shape support height under `normal`, m
  double frequency = 0.0;  ///< fraction of all drops
  int count = 0;
  double spread_degrees = 0.0;  ///< largest angle of a member to the (unsnapped) mean
  double snap_degrees = -1.0;   ///< angle moved when snapped to a hull face normal; < 0: not snapped
  bool kept = false;
  int family = 0;  ///< equivalence family under the shape's symmetry, 0 = most frequent
  double family_frequency = 0.0;  ///< the family's summed frequency
};

struct RestPoses2d {
  std::vector<RestCluster> clusters;  ///< all clusters, kept ones first (by frequency)
  double dropped = 0.0;               ///< fraction of the settled drops in poses not kept
};

/// The poses of the drops whose up vectors are `ups` (body frame; `settled[i]` 0: drop i did not
/// settle and counts only in the frequencies' denominator), by the options' cluster_degrees,
/// min_frequency and max_dropped.
RestPoses2d cluster_rest_poses(const Shape2& shape, const std::vector<Point2>& ups, const std::vector<char>& settled,
                               const Gather2dOptions& o);

}  // namespace statsim::tools
