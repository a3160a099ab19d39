// `statsim gather2d`: the statistical signature of a 2D shape (paper 3.2), gathered with Box2D
// 2.4.1 as the reference, written as a C++ header of `statsim::Signature<2, ...>` data.
//
// Three experiments, each trial seeded from (seed, experiment, cell, trial) only, so the output
// is byte-identical for a given command whatever the number of threads:
//  1. height table (paper 3.2.1): the centre height at the first contact of the core shape with a
//     line, for spin ratios s = |w| L / |v| (L: bounding radius), measured exactly as `statsim
//     fig3` does (Box2D's skin bias removed; see box2d_util.hpp);
//  2. response tables (paper 3.2.2): no gravity; the body arrives at the ground with V- at angle
//     theta to the inverse normal and signed spin; Box2D resolves the collision until the body
//     separates; W+ L / |V-| and (V_rigid+ - V_particle+) / |V-| are averaged per cell;
//  3. rest poses (paper 3.2.3): drops with gravity until Box2D puts the body to sleep; the
//     body-frame up vectors are clustered and snapped to hull edges; poses equivalent under the
//     shape's symmetry form families, and the poses kept are those of the families seen in more
//     than 5% of the drops together, then rarer families while more than 2% of the settled drops
//     would be in poses not kept (common/rest_families.hpp, the rule of statsim gather).
#pragma once

#include "common/body_contacts.hpp"
#include "ref2d/fig3.hpp"
#include "ref2d/gather2d_emit.hpp"
#include "ref2d/gather2d_options.hpp"
#include "ref2d/polygon2d.hpp"
#include "ref2d/rest_poses2d.hpp"

#include <array>
#include <string>
#include <vector>

namespace statsim::tools {

/// The heights of one spin ratio, summarised as `statsim fig3` does.
using HeightRow = Fig3Row;

struct ResponseCell {
  double cos_theta = 0.0;
  double spin = 0.0;   ///< signed spin ratio
  double speed = 0.0;  ///< m/s
  std::array<double, 3> mean{};  ///< w+ L/|V-|, dv_x/|V-|, dv_y/|V-|
  std::array<double, 3> std{};
  int trials = 0;
  int time_limited = 0;  ///< trials that had not separated at the time limit
  double mean_steps = 0.0;
};

struct Gather2dResult {
  Gather2dOptions options;
  Shape2 shape;
  double length = 0.0;  ///< L = bounding radius, m
  double height_dt = 0.0;
  double response_dt = 0.0;
  float restitution_threshold = 0.0f;  ///< Box2D's (b2FixtureDef default), m/s
  std::vector<HeightRow> heights;
  std::vector<ResponseCell> cells;  ///< row-major: cos theta slowest, then spin, then speed
  int response_trials = 0;
  int response_time_limited = 0;
  int rest_drops = 0;
  int rest_time_limited = 0;
  std::vector<RestCluster> clusters;  ///< all clusters, kept ones first (by frequency)
  double rest_dropped = 0.0;          ///< fraction of the settled drops in poses not kept
  std::vector<Point2> rest_ups;       ///< final body-frame up vector of each drop
  std::vector<char> rest_settled;     ///< per drop: 1 = Box2D put it to sleep
  BodyContactData contact;  ///< when options.body_contacts
  double seconds_heights = 0.0;
  double seconds_responses = 0.0;
  double seconds_rest = 0.0;
};

/// Runs the three experiments, and the body-body data when options.body_contacts.
Gather2dResult run_gather2d(const Gather2dOptions& options);

/// Only the rest-pose experiment (for tests): fills rest_* and clusters.
Gather2dResult run_rest_poses(const Gather2dOptions& options);

}  // namespace statsim::tools
