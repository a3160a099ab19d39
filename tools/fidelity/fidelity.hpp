// `statsim fidelity`: accuracy against speed. Every method (Bullet representations and statsim
// variants and tables) is run from many independent initial states drawn from one
// distribution, and its outcomes are compared with the reference (Bullet with the full mesh at a
// small step) as distributions, each distance with a bootstrap interval, beside the distance
// between two independent reference samples (the noise floor). The definitions are in
// fidelity.cpp's file comment and in `statsim fidelity --help`.
#pragma once

#include "common/flight_top.hpp"
#include "fidelity/metrics.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace statsim::tools::fidelity {

struct FidelityOptions {
  std::string shape = "bunny";  ///< bunny, box or lshape (compiled tables); ignored with `mesh`
  std::string mesh;             ///< OBJ of a shape without a compiled table (needs a table)
  /// Loaded tables: NAME, FILE.json (method "statistical:NAME").
  std::vector<std::pair<std::string, std::string>> tables;
  std::vector<std::string> methods;  ///< empty: the default list (see default_methods())
  int runs = 500;                    ///< single drops per sample
  double dt = 1.0 / 60.0;            ///< s, step of the methods
  double reference_dt = 1e-3;        ///< s, step of the reference (Bullet full) in single drops
  /// Settings of the single drops' reference: "gather" (tools/ref3d's, those the tables were
  /// gathered with) or "bench" (statsim bench's Bullet settings). Piles always use "bench".
  std::string reference = "gather";
  double time_limit = 10.0;          ///< s, a run ends at rest or here
  bool piles = true;
  int pile_seeds = 20;               ///< piles: scene seeds 1..N (reference floor: N+1..2N)
  int pile_count = 50;               ///< bodies per pile
  /// s, step of the piles' and scenes' reference; 0: each scene's own converged step
  /// (pile_reference_step()).
  double pile_reference_dt = 0.0;
  /// Iterations of the piles' and scenes' reference solver per step (statsim bench's Bullet
  /// settings otherwise; Bullet's default is 10).
  int pile_reference_iterations = 10;
  /// "step" or "iterations": instead of comparing methods, run only the piles' and scenes'
  /// reference at `refinements` + 1 levels, the step halved (or the iterations doubled) from one
  /// level to the next, and report how far each figure moves (tools/fidelity/convergence.hpp).
  /// Empty: the normal run.
  std::string convergence;
  int refinements = 2;               ///< levels after the first of a convergence run
  int bench_n = 100;                 ///< bodies of the step-time scene
  int bench_steps = 300;             ///< steps of the step-time scene
  bool timing = true;                ///< measure step_ms
  std::uint64_t seed = 1;            ///< of the single-drop streams and the statsim worlds
  /// 0: a single drop's statsim world is seeded by the drop's stream. Otherwise by a mix of this
  /// and the stream: the same drops with other draws of the tables, so a rerun shows how far
  /// statsim's own sampling moves a figure (the references' drops are unchanged).
  std::uint64_t draw_seed = 0;
  unsigned threads = 0;              ///< 0: every core
  int bootstrap = 200;               ///< resamples per interval
  std::string meshes_dir;            ///< empty: the source tree's tools/meshes
  bool progress = true;
  /// Pile scenes (tools/scenes/piles.hpp) to run: heap, bin, column, wall ("stack": column and
  /// wall). Each against Bullet full at pile_reference_step() with statsim bench's settings.
  std::vector<std::string> scenes;
  bool drops = true;                 ///< false: no single drops, piles or step time (scenes only)
  int scene_seeds = 10;              ///< scene seeds 1..N per sample (reference floor: N+1..2N)
  int heap_count = 60;               ///< bodies of the heap
  int bin_count = 60;                ///< bodies of the bin
  int bin_cells = 4;                 ///< lattice cells along the bin's side
  int column_height = 10;            ///< bodies of the column
  int wall_columns = 4;              ///< columns of the wall
  int wall_height = 5;               ///< bodies per column of the wall
  double stack_time = 3.0;           ///< s, simulated time of the column and the wall
  std::string scene_frames;          ///< directory: final states of seed 1 as frame files; empty: none
  /// JSON of an earlier run with the same scenes (`--json`): its reference samples A and B stand
  /// in for running the reference again (tools/fidelity/scene_reference.hpp); empty: run it.
  std::string scene_reference;
  /// Mixed heap and bin: half their bodies of this second shape (bunny, box or lshape, with its
  /// compiled table), taken in turn with `shape`'s; empty: one shape. Methods: statistical and
  /// Bullet full only.
  std::string mix;
};

/// The step of the reference (Bullet full, statsim bench's settings) in the pile scene `kind`
/// (heap, bin, column, wall, or "piles": the 50-body drop piles): `o.pile_reference_dt` when set,
/// else the scene's converged step, the coarsest that `statsim fidelity --convergence step` found
/// no refinement to move (tools/fidelity/README.md, "Is the reference converged?").
double pile_reference_step(const FidelityOptions& o, const std::string& kind);

/// The shape a run measures as its report and JSON name it: the compiled shape or the mesh, and
/// a mixed scene's second shape.
std::string shape_label(const FidelityOptions& o);

/// Method names used when none are given: full, low, spheres7, sphere, statistical,
/// statistical-norest, statistical-independent (those the shape supports).
std::vector<std::string> default_methods();

/// The end of a drop's first collision (`FlightTop`, common/flight_top.hpp).
using statsim::tools::FlightTop;

/// Interval of a single drop's motion profile (`DropRun::profile_speed`, `--profile-csv`), s.
constexpr double kProfileStep = 0.05;

/// Outcome of one single drop.
struct DropRun {
  int config = -1;             ///< rest configuration: pose index, or the pose count for "other"
  double rest_height = 0;      ///< centre of mass height at rest, m
  double travel = 0;           ///< horizontal distance drop point to rest point, m
  double bounces = 0;          ///< rises of the centre after the first contact (see the definitions)
  double rest_time = 0;        ///< s, when the rest condition began
  /// s, the last time the drop moved at statsim's default `WorldDef::settle_speed` or faster
  /// (centre, or farthest point by spin): where a statsim body would begin to settle; 0 if never
  double settle_onset = 0;
  bool time_limited = false;   ///< reached the time limit before rest (did not rest)
  bool impact = false;         ///< a first contact was seen
  bool flight = false;         ///< a flight after the first contact was found (FlightTop::found)
  double flight_speed = 0;     ///< m/s, |v| as the body left for that flight (FlightTop)
  double flight_spin = 0;      ///< rad/s, |w| as the body left for that flight
  double impact_speed = 0;     ///< m/s, |v| before the first contact's step (|V-|; FlightTop)
  double impact_spin = 0;      ///< rad/s, |w| before the first contact's step
  std::uint64_t responses = 0; ///< statsim: sampled responses applied (World::statistical_response_count)
  std::uint64_t clamps = 0;    ///< statsim: of those, scaled down by the energy guard
  /// The motion every kProfileStep s, sample k at t = (k + 1) kProfileStep, until the drop rested
  /// or the time limit: |v| (m/s), |w| R (m/s, the farthest point's speed by spin), centre height (m).
  std::vector<float> profile_speed, profile_spin, profile_height;
};

/// Final state of one pile.
struct PileRun {
  std::vector<double> radius;  ///< horizontal distance of each body from the pile's centroid, m
  std::vector<double> height;  ///< centre heights, m
  std::vector<int> config;     ///< rest configurations (pose index, or the count for "other")
  bool time_limited = false;
  double seconds = 0;          ///< simulated time until all rested (or the limit)
  std::uint64_t responses = 0; ///< statsim: sampled responses applied
  std::uint64_t clamps = 0;    ///< statsim: of those, scaled down by the energy guard
};

/// A distance and its bootstrap interval.
struct Distance {
  double value = 0;
  Interval ci;
};

/// Every distance of one sample against the reference.
struct Distances {
  Distance rest_tvd, rest_height_err, travel_w1, bounce_w1, rest_time_w1;
  Distance first_impact_ks, first_impact_ks_v, first_impact_ks_w;
  Distance summary_error;
  bool piles = false;
  Distance pile_radial_w1, pile_height_w1, pile_rest_tvd;
};

struct MethodResult {
  std::string name;
  std::string description;
  double dt = 0;
  std::vector<DropRun> drops;
  std::vector<PileRun> piles;
  Distances d;
  double step_ms = -1;        ///< thread CPU ms per step on the benchmark scene; -1: not measured
  long long table_bytes = -1; ///< -1: no table
};

/// Outcome of one run of a pile scene.
struct SceneRun {
  std::vector<double> values;  ///< the scene's measurements, in scene_metrics() order
  bool all_asleep = false;     ///< every body asleep at the end (the engine's sleep state)
  bool time_limited = false;   ///< heap, bin: not every body rested by the time limit
  double seconds = 0;          ///< simulated time of the run, s
  /// Thread CPU time of the engine's steps over the run, ms per step (0: not measured, as in a
  /// reference read back by --scene-reference from a file written before it was recorded).
  double step_ms = 0;
};

/// A measurement of a scene and how its distance to the reference is taken.
struct SceneMetric {
  std::string name;    ///< e.g. "angle_deg"
  std::string unit;    ///< of the values
  bool relative;       ///< distance (mean - mean_ref) / mean_ref; else mean - mean_ref in the unit
};
/// The measurements of a scene kind (heap, bin, column, wall).
std::vector<SceneMetric> scene_metrics(const std::string& kind);
/// The distance a figure's goal allows, in its distance's unit (issue goals: angle of repose 3 deg,
/// heap height 10%, bin fill height and packing 5%, a stack's held height 0.02); 0: the figure has
/// no goal (a stack's overlap).
double goal_tolerance(const SceneMetric& metric);


/// One sample's runs of a scene and, for the methods, the distances to the reference sample A.
struct SceneSample {
  std::string name;                 ///< method, "reference" or "reference_b"
  double dt = 0;
  std::vector<SceneRun> runs;       ///< one per seed
  std::vector<Distance> means;      ///< per metric: the mean over seeds and its 90% interval
  std::vector<Distance> distances;  ///< per metric: against reference A (the floor: B against A)
  Distance asleep;                  ///< share of runs with every body asleep at the end
};

struct SceneResult {
  std::string kind;
  std::string description;          ///< the scene's set-up in one line
  std::vector<SceneMetric> metrics;
  SceneSample reference, reference_b;
  std::vector<SceneSample> methods;
};

/// A pile model's summary over the heap and bin scenes run (the stacks have a summary of their
/// own: their held height): the mean of |distance| / goal_tolerance over their figures (1: at the
/// goals on average), and the thread CPU time per step of their runs, mean over the runs (ms).
struct PileSummary {
  double pile_error = 0;
  double step_ms = 0;
};
/// The summary of method `m` (an index into each scene's methods).
PileSummary pile_summary(const std::vector<SceneResult>& scenes, std::size_t m);

struct FidelityResult {
  FidelityOptions options;
  std::string shape;                  ///< name of the body
  double bounding_radius = 0;         ///< R, m
  std::vector<std::string> pose_labels;  ///< rest configurations ("(x, y, z) h"), then "other"
  MethodResult reference;             ///< sample A
  MethodResult reference_b;           ///< sample B (noise floor)
  Distances noise_floor;              ///< B against A
  std::vector<MethodResult> methods;
  std::vector<SceneResult> scenes;    ///< --scenes
  std::vector<std::string> settings;  ///< engine settings, one per line
  std::string command;
  double seconds = 0;                 ///< wall time of the whole run
};

/// summary_error from the five single-drop distances (see summary_error_definition()).
double summary_error(double rest_tvd, double rest_height_err, double travel_w1, double bounce_w1,
                     double first_impact_ks);
/// The sentence that defines summary_error (written into the JSON and the help).
const char* summary_error_definition();
/// The definitions of every measurement, for --help and the JSON.
const char* fidelity_definitions();
/// The definitions of the pile scenes' measurements (--scenes), for --help and the JSON.
const char* scenes_definitions();

/// Distances of `method` against `reference` (both DropRun samples over the same rest
/// configurations, `configs` of them including "other"); piles when both have piles.
Distances compare(const std::vector<DropRun>& method, const std::vector<DropRun>& reference,
                  const std::vector<PileRun>& method_piles, const std::vector<PileRun>& reference_piles, int configs,
                  int resamples);

/// Throws std::invalid_argument naming a bad option.
void validate(const FidelityOptions& options);
/// Runs everything. Throws std::runtime_error / std::invalid_argument.
FidelityResult run_fidelity(const FidelityOptions& options);

std::string fidelity_json(const FidelityResult& result);
/// Every single drop of every sample, one CSV row each (`--drops-csv`): the sample (reference,
/// reference_b, or the method's name), the run's index, and the DropRun's fields, doubles written
/// with 17 significant digits, so the distances can be recomputed from the file exactly.
std::string drops_csv(const FidelityResult& result);
/// The single drops' mean motion against time (`--profile-csv`), one row per sample and
/// kProfileStep: t (s), the share of drops not yet at rest, and over every drop the mean |v|, |w| R
/// (m/s) and centre height above the drop's final height (m), a drop at rest counting with 0, 0
/// and 0. Where a statistical body loses its motion earlier than the reference, and how.
std::string profile_csv(const FidelityResult& result, double time_limit);
std::string fidelity_table(const FidelityResult& result);
/// The scenes' tables (part of fidelity_table()).
std::string scenes_table(const FidelityResult& result);

/// The charts of a run; an empty path draws none. Each is a PNG at the path and an SVG beside it
/// (FILE.svg), with the noise floor marked.
struct Charts {
  std::string chart;        ///< summary error (90% interval) against time per step (log x), the
                            ///< Pareto front and the goal line
  std::string bytes_chart;  ///< summary error (90% interval) against table bytes (log x), one point
                            ///< per method with a table (statistical tables) and the goal line
  std::string metric_dir;   ///< directory: one chart per distance against time per step
  bool any() const { return !chart.empty() || !bytes_chart.empty() || !metric_dir.empty(); }
};
/// Draws `charts` with tools/plot/fidelity.py from the file written with fidelity_json(). Throws
/// std::runtime_error with the script's message (a missing or malformed file, no method with a
/// table for bytes_chart, no python3 with matplotlib: see plot::run_script).
void write_charts(const std::filesystem::path& json_file, const Charts& charts);
/// The same for a result in memory.
void write_charts(const FidelityResult& result, const Charts& charts);

}  // namespace statsim::tools::fidelity
