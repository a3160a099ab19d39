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
#include "common/table_writer.hpp"
#include "ref2d/fig3.hpp"
#include "ref2d/polygon2d.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace statsim::tools {

/// Default axes (the runtime clamps outside them).
std::vector<double> default_height_ratios();   ///< 16 spin ratios 0..32, denser near 0
std::vector<double> default_cos_thetas();      ///< 7 values 0.15..1
std::vector<double> default_signed_spins();    ///< 9 values -6..6, denser near 0
std::vector<double> default_speeds();          ///< 5 values 0.5..9 m/s

/// Defaults: 16 x 1000 height drops, 315 cells x 200 response trials, 2000 rest drops. Box2D steps
/// one small body so fast that generous statistics cost seconds per shape (gathering times and the
/// standard errors they give: tools/ref2d/README.md).
struct Gather2dOptions {
  std::string shape = "square";  ///< "square", "lshape" or "polygon"
  std::string polygon;           ///< vertices "x1,y1 x2,y2 ..." when shape == "polygon"
  std::string name = "square2d"; ///< C++ name of the table (an identifier)
  TableTarget target;            ///< where the header goes: how it names its paths, its namespace
  std::uint64_t seed = 1;
  double restitution = 0.3;  ///< of the body and of the ground (Box2D mixes with max: e)
  double friction = 0.5;     ///< of the body and of the ground (Box2D mixes sqrt(mu mu) = mu)

  std::vector<double> height_ratios = default_height_ratios();
  int height_trials = 1000;    ///< drops per spin ratio
  double height_speed = 2.0;   ///< m/s, straight down

  std::vector<double> cos_thetas = default_cos_thetas();
  std::vector<double> signed_spins = default_signed_spins();
  std::vector<double> speeds = default_speeds();
  int trials = 200;                   ///< per response cell
  double response_dt = 1.0 / 480.0;   ///< s (smaller for small fast-spinning shapes, see the header)
  double response_time_limit = 3.0;   ///< s of simulated time per trial

  int rest_drops = 2000;
  double rest_dt = 1.0 / 120.0;
  double rest_time_limit = 30.0;      ///< s of simulated time per drop
  double cluster_degrees = 10.0;      ///< greedy clustering tolerance
  double min_frequency = 0.05;        ///< families kept: summed frequency > this
  double max_dropped = 0.02;          ///< then rarer families kept while the dropped share exceeds this

  // Body-body data (4.); false (--no-body-contacts): a table of format 2.0 without it.
  bool body_contacts = true;
  int support_size = 9;     ///< S of the support map (4 S values)
  int contact_faces = 16;   ///< longest hull edges stored (fewer when the hull has fewer)
  int pair_trials = 2000;   ///< pair flights per height-table spin ratio
  int packing_piles = 10;   ///< Box2D piles of `statsim compare2d` (seeds 1..N)
  int packing_count = 100;  ///< bodies per pile
  int packing_steps = 900;  ///< steps of 1/60 s per pile

  unsigned threads = 0;  ///< 0 = hardware concurrency; does not change the result
  bool progress = false;
};

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

/// The shape an options object names (throws std::invalid_argument for a bad polygon).
Shape2 gather2d_shape(const Gather2dOptions& options);

/// Throws std::invalid_argument with a readable message for unusable options.
void validate_gather2d_options(const Gather2dOptions& options);

/// Runs the three experiments, and the body-body data when options.body_contacts.
Gather2dResult run_gather2d(const Gather2dOptions& options);

/// Only the rest-pose experiment (for tests): fills rest_* and clusters.
Gather2dResult run_rest_poses(const Gather2dOptions& options);

/// The generated header. `command` is the command line recorded in it.
std::string gather2d_header(const Gather2dResult& result, const std::string& command);

/// A JSON summary (statistics, counts and timings).
std::string gather2d_json(const Gather2dResult& result, const std::string& command);

/// A human-readable summary.
std::string gather2d_summary(const Gather2dResult& result);

/// Quotes `s` for a POSIX shell when needed.
std::string shell_quote(const std::string& s);

}  // namespace statsim::tools
