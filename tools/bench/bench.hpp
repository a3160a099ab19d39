// `statsim bench`: the paper's Table 1 against real engines, in one run.
//
// The scene is the shared "bunny drop" (tools/scenes): N bodies dropped from random states in a
// cylinder above the ground plane, identical initial states for every method. Methods (3D):
//   full        Bullet, btGImpactMeshShape of the full mesh (bunny.obj)
//   low         Bullet, btGImpactMeshShape of the ~100-vertex mesh (bunny_low.obj)
//   hull        Bullet, btConvexHullShape of bunny_low.obj's vertices (what a game would use)
//   spheres7    Bullet, btCompoundShape of the 7 spheres of bunny_spheres7.txt
//   sphere      Bullet, one btSphereShape (radius: the table's mean collision radius at zero spin)
//   statistical statsim World3 with the shape's table and the runtime's default broad phase
//               (BroadPhase::automatic: sweep-and-prune up to WorldDef::grid_above_bodies bodies,
//               the hashed grid above); statistical-sap and statistical-grid force one of the two
// 2D (--dim 2, squares): polygon (Box2D b2PolygonShape), circle (Box2D b2CircleShape), statistical
// (statsim World2 with the square2d table).
//
// Timing: for each N, every cell (method x broad phase) first runs `warmup` steps in a world that is
// then thrown away, then `repeats` timed runs of `steps` steps, each in a fresh world built from the
// initial states (construction is not timed). Repeats are interleaved across methods (repeat 1 of
// every method, then repeat 2, ...) so that load drifting on a shared machine hits all methods
// alike. Per repeat: mean time per step over the whole run, over the falling phase (the steps
// before the first body of any method at that N falls asleep: the same window for all) and over
// the rest; reported: the median over repeats, the min and
// max of the whole-run means, and the envelope: the mean over steps of the fastest repeat at each
// step (the engines are deterministic, so every repeat does the same work step by step, and the
// envelope filters out preemption on a loaded machine).
// A cell stops early and is skipped when its steps exceed `limit_ms` (running mean over the last
// 10 steps, or the warm-up's mean); later N of that cell are skipped too, as are cells whose time
// at the previous N, scaled linearly, is over the limit. A cell stops repeating (keeping what it
// has, at least one repeat) once its timed runs took more than `budget_s`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace statsim::tools {

struct BenchOptions {
  int dim = 3;                       ///< 3 (Bullet vs statsim) or 2 (Box2D vs statsim)
  std::string shape = "bunny";       ///< 3D: bunny, box or lshape; 2D: square
  std::vector<int> counts{10, 100, 1000, 10000};
  std::vector<std::string> methods;  ///< empty: every method of `dim`
  std::vector<std::string> broadphases{"sap", "dbvt"};  ///< Bullet's; 2D and statsim have one
  double dt = 1.0 / 60.0;            ///< s
  int steps = 300;                   ///< K, timed steps per repeat
  int warmup = 10;                   ///< W, untimed steps before the first repeat
  int repeats = 3;                   ///< R
  double limit_ms = 2000.0;          ///< skip cells whose step takes longer
  double budget_s = 300.0;           ///< stop repeating a cell after this much timed time
  std::uint64_t seed = 1;            ///< of the scene (and of statsim's random streams)
  std::string meshes_dir;            ///< empty: the source tree's tools/meshes
  bool progress = true;              ///< progress lines on stderr
  bool chart_cpu = false;            ///< chart the thread CPU time instead of the wall-clock median
  bool hull_contacts = true;         ///< statsim: BodyContacts::hulls (false: the default, collision spheres)
  unsigned workers = 1;              ///< statsim: threads stepping each world (WorldDef::workers)
  bool all_features = false;         ///< statsim 3D: `Features::all`, not the scene's smallest set
};

/// One cell of the benchmark: a method at one N with one broad phase.
struct BenchCell {
  std::string method;
  std::string engine;      ///< "bullet", "box2d", "statsim"
  std::string broadphase;  ///< "sap", "dbvt", "tree" (Box2D)
  int n = 0;
  bool skipped = false;
  std::string note;        ///< why skipped, or warnings
  int repeats = 0;         ///< timed repeats done
  int steps = 0;           ///< steps per repeat
  double step_ms_median = 0, step_ms_min = 0, step_ms_max = 0;  ///< whole run, per step
  /// Whole run, per step: the mean over steps of the fastest repeat at each step (the repeats
  /// are identical simulations, so this filters out preemption by other processes).
  double step_ms_envelope = 0;
  /// Whole run, per step: this thread's CPU time (not time waiting for a core on a shared
  /// machine; it includes the bench loop's own bookkeeping, a few microseconds per step at most),
  /// median over repeats.
  double cpu_ms = -1;
  double collision_ms = -1, response_ms = -1;  ///< per step, median over repeats; -1: n/a
  double broad_ms = -1, narrow_ms = -1;        ///< per step; -1: n/a
  /// Falling phase: steps 1..fall_steps, before the first body of any method at this N fell
  /// asleep (the same window for every method). Per step, median over repeats; -1: empty window.
  double fall_ms = -1;
  double settle_ms = -1;   ///< per step after the falling window; -1: the window is the whole run
  int fall_steps = 0;      ///< length of the falling window, steps
  int first_sleep_step = -1;  ///< this method's first step ending with a body asleep (median); -1: none
  double asleep_end = 0;      ///< fraction of bodies asleep at the end of the last repeat
  double mean_height_end = 0; ///< m
  double contacts_end = 0;    ///< touching pairs at the end, per body
};

struct BenchResult {
  BenchOptions options;
  std::vector<BenchCell> cells;
  std::vector<std::string> settings;  ///< engine settings and scene descriptions, one per line
  std::string machine;                ///< CPU, cores, load, compiler
  std::string command;                ///< the command line, for the report
};

/// Checks the options; throws std::invalid_argument naming the problem.
void validate_bench_options(const BenchOptions& options);
/// Runs the benchmark. Throws std::runtime_error (missing mesh, ...) or std::invalid_argument.
BenchResult run_bench(const BenchOptions& options);

/// The report: Markdown tables like the paper's Table 1 (per broad phase), the falling/settling
/// split, ratios of statistical to the others, and the settings.
std::string bench_markdown(const BenchResult& result);
/// CSV, one row per cell: method,n,broadphase,step_ms_median,step_ms_min,step_ms_max,collision_ms,
/// response_ms,broad_ms,narrow_ms,fall_ms,settle_ms,fall_steps,first_sleep_step,step_ms_envelope,cpu_ms,repeats,steps,
/// engine,skipped,asleep_end,mean_height_end,contacts_per_body_end,note. n/a values are empty.
std::string bench_csv(const BenchResult& result);
/// Log-log chart of time per step against N, one line per method and broad phase: PATH (PNG)
/// and PATH with .svg, drawn by tools/plot/bench.py from bench_csv(). Throws std::runtime_error
/// when the chart cannot be drawn (see plot::run_script).
void write_bench_chart(const BenchResult& result, const std::filesystem::path& path);

}  // namespace statsim::tools
