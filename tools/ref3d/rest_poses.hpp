// The rest-pose stage of `statsim gather`: from the settled drops' up vectors to the table's
// rest poses (clustering, snapping to hull faces, families under the shape's symmetry and which
// poses are kept, by common/rest_families.hpp). Needs no reference engine: the drops are given.
#pragma once

#include "ref3d/gather_options.hpp"
#include "ref3d/gather_trials.hpp"
#include "ref3d/model.hpp"

#include <Eigen/Core>

#include <vector>

namespace statsim::tools::ref3d {

struct RestPose {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, body frame
  double height = 0.0;      ///< m: the snapped face's offset, else the measured mean
  double measured_height = 0.0;  ///< mean over the drops, m
  double height_std = 0.0;  ///< m
  double frequency = 0.0;   ///< fraction of the settled drops
  int count = 0;
  bool snapped = false;     ///< the normal is a hull face's (the mean was within 3 degrees of it)
  int family = 0;           ///< equivalence family under the shape's symmetry, 0 = most frequent
  double family_frequency = 0.0;  ///< the family's summed frequency
};

/// The rest poses of a set of drops (a part of GatherResult).
struct RestPoseFit {
  std::vector<RestPose> rest;       ///< kept poses, most frequent first
  std::vector<RestPose> rest_rare;  ///< poses not kept
  double rest_dropped = 0.0;        ///< fraction of the settled drops in poses not kept
  int rest_families = 0;            ///< families of all poses, kept or not
  int settled = 0, unsettled = 0;
  double mean_settle_time = 0.0;    ///< s of simulation, over the settled drops
};

/// The poses of `drops` on shape `m` by the options' rest_tolerance_deg, rest_min_frequency and
/// rest_max_dropped (gather.hpp's item 3 says how).
RestPoseFit fit_rest_poses(const ShapeModel& m, const std::vector<DropTrial>& drops, const GatherOptions& o);

/// Clusters unit vectors: leader clustering in input order within `tol` (radians), then up to 20
/// rounds of assigning each vector to the nearest cluster mean (a new cluster when none is within
/// `tol`) until nothing moves. Returns the cluster of each vector; deterministic.
std::vector<int> cluster_directions(const std::vector<Eigen::Vector3d>& dirs, double tol);

}  // namespace statsim::tools::ref3d
