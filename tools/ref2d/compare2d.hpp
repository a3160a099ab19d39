// `statsim compare2d`: the same drop of N bodies in Box2D (full polygons) and in statsim's World2
// (statistical bodies from the committed tables/NAME2d.hpp), side by side: time per step and how
// far the statistical result is from Box2D's.
#pragma once

#include "statsim/signature.hpp"

#include <cstdint>
#include <string>
#include <vector>

class b2World;
class b2Body;

namespace CLI {
class App;
}

namespace statsim::tools {

struct Compare2dOptions {
  std::string shape = "square";  ///< "square" or "lshape" (a committed table must exist)
  int n = 100;                   ///< bodies, 1..2048
  int steps = 900;               ///< steps of dt for both simulations
  double dt = 1.0 / 60.0;
  std::uint64_t seed = 1;         ///< drop k (0 <= k < drops) starts from the states of seed + k
  int repeat = 3;                ///< runs per simulation; each step's time is the least of them
  /// Independent drops per method, pooled. One drop of 100 bodies is a noisy sample: Box2D's
  /// own share of tilted bodies varies widely between seeds (tools/ref2d/README.md).
  int drops = 10;
  bool pile_rest = false;        ///< statsim's WorldDef::pile_rest
  bool sleep_islands = true;     ///< statsim's WorldDef::sleep_islands
  bool ground_hulls = false;     ///< statsim's WorldDef::ground_hulls
  /// Box2D takes this many steps of dt / box2d_substeps for each step of dt (its convergence:
  /// tools/ref2d/convergence2d.py); statsim always steps dt.
  int box2d_substeps = 1;
  /// When above 0: every this many seconds of simulated time (rounded to whole steps), record the
  /// highest centre and the bodies awake (`MethodResult::history`).
  double history_every = 0.0;
};

/// One sample of a run's history (`Compare2dOptions::history_every`).
struct HistorySample {
  double time = 0.0;     ///< s after the start
  double highest = 0.0;  ///< highest centre of any body, m; mean over drops
  double awake = 0.0;    ///< bodies awake; mean over drops
};

/// Initial state of one body (both simulations start from these).
struct Body2State {
  double x = 0.0, y = 0.0, angle = 0.0, vx = 0.0, vy = 0.0, w = 0.0;
};

/// One method's outcome over all drops: step times are means over the drops of each drop's
/// figure; distributions pool the bodies of every drop.
struct MethodResult {
  std::string method;                 ///< "box2d", "box2d_b" (the second reference sample) or "statsim"
  std::vector<double> step_ms;        ///< wall-clock time of every step of the first drop, ms
  double median_ms = 0.0;             ///< median over all steps
  double mean_ms = 0.0;
  double falling_median_ms = 0.0;     ///< median over the steps before anything sleeps (in either)
  double active_mean_ms = 0.0;        ///< mean over the steps until both are all asleep (or all steps)
  int first_sleep_step = -1;          ///< first drop: first step after which a body slept (-1: never)
  int all_asleep_step = -1;           ///< first drop: step from which every body stayed asleep (-1: not by the end)
  int asleep = 0;                     ///< bodies asleep at the end, all drops
  std::vector<Body2State> final;      ///< final states, drop after drop
  std::vector<std::uint8_t> final_asleep;  ///< 1 for a body asleep at the end, as `final`
  std::vector<HistorySample> history;  ///< when Compare2dOptions::history_every > 0
  std::vector<double> histogram;      ///< fractions per rest pose of the signature, then "other"
  double pile_height = 0.0;           ///< highest point of any body (its polygon at its pose), m; mean over drops
  double pile_height_sd = 0.0;        ///< standard deviation of pile_height over the drops, m
  double mean_x = 0.0;
  double mad_x = 0.0;                 ///< mean absolute deviation of x within a drop, m; mean over drops
  double rest_tvd = 0.0;              ///< total variation distance of the pooled histograms to Box2D's
  double rest_tvd_single = 0.0;       ///< the same per drop, mean over drops (one drop alone is noisy)
  double spread_w1 = 0.0;             ///< W1 of the pooled x distributions / Box2D's mad_x
  double lowest = 0.0;                ///< lowest point of any body, m (< 0: sunk into the ground)
  /// Median over the bodies of the distance from each centre to the nearest other centre, m;
  /// mean over drops. How closely the bodies pack: unit squares lying face to face are 1 m apart.
  double neighbour_median = 0.0;
  double max_speed = 0.0;             ///< largest final |v|, m/s
  double kinetic_energy = 0.0;        ///< final total kinetic energy, J; mean over drops
};

struct Compare2dResult {
  Compare2dOptions options;
  std::string table;                  ///< name of the signature used
  std::vector<std::string> categories;  ///< rest-pose labels, then "other"
  int falling_steps = 0;              ///< steps before anything slept in either simulation
  int active_steps = 0;               ///< steps until both simulations were all asleep (or all steps)
  MethodResult box2d;
  MethodResult statsim;
  /// Box2D again on the next `drops` seeds: its distances from `box2d` are the noise floor, the
  /// distance two samples of the reference itself show.
  MethodResult box2d_b;
};

/// Writes the final state of the first drop of Box2D and of statsim as frame files
/// (tools/scenes/frames.hpp), `dir`/box2d.csv and `dir`/statsim.csv, one frame each (the last
/// step), for `statsim render`; creates `dir`. Throws std::runtime_error when a file cannot be
/// written.
void write_compare2d_frames(const Compare2dResult& result, const std::string& dir);

/// Initial states: random positions clear of each other in a region above the ground (as wide as
/// a square grid of the bodies, twice as tall), random orientations and small random velocities;
/// deterministic in (seed, n, shape).
std::vector<Body2State> compare2d_initial_states(const Compare2dOptions& options, double bounding_radius);

struct Shape2;

/// A pile's reference as `statsim compare2d` builds it: the ground and one body per initial state
/// (in order) in `world`, with the table's material (Box2D density 1: only mass ratios matter).
/// Returns the bodies.
std::vector<b2Body*> add_box2d_pile(b2World& world, const Shape2& shape, const statsim::SignatureView<2>& sig,
                                    const std::vector<Body2State>& init);

/// True when a committed table for `shape` was compiled into the tools.
bool compare2d_has_table(const std::string& shape);

/// Runs both simulations. Throws std::invalid_argument for bad options or a missing table.
Compare2dResult run_compare2d(const Compare2dOptions& options);

/// The side-by-side table for humans.
std::string compare2d_table(const Compare2dResult& result);

/// CSV: header `method,n,steps,step_ms,step_ms_mean,falling_ms,active_ms,rest_tvd,spread_w1,pile_height,asleep,drops,rest_tvd_single,neighbour_median,pile_height_sd`,
/// one row per method: box2d (distances 0), box2d_b (the noise floor), statsim. step_ms is the
/// median over all steps.
std::string compare2d_csv(const Compare2dResult& result);

/// Adds `compare2d` to `app`.
void register_compare2d_command(CLI::App& app);

}  // namespace statsim::tools
