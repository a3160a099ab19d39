// `statsim fidelity`: how close each method's outcomes are to the reference's, as distributions.
// This file runs the stages in order (stages.hpp): the set-up of the methods (methods.cpp), the
// single drops (drops.cpp), the drop piles and pile scenes (piles.cpp), the distances
// (distances.cpp); fidelity_report.cpp writes the report. What each measures:
//
//
// Reference: Bullet "full" (btGImpactMeshShape of the full mesh; btBoxShape / compound of boxes
// for box and lshape), at --reference-dt (default 1 ms, the gathering's step) in single drops
// and --pile-reference-dt (default 1/240 s) in piles. Single drops, --reference gather (the
// default): the Bullet world the tables were gathered in (tools/ref3d's Reference and its
// ReferenceSettings: 30 iterations, no warm starting, split impulse, margin 0.5 mm, restitution
// threshold 0.02 m/s; no deactivation: asleep after two 0.25 s windows of average speeds below
// 0.01 m/s, as the gathering decides rest); the statistics
// are then compared with the engine set-up the signature describes. --reference bench, and the
// piles always: the settings of `statsim bench` (tools/bench/bench_bullet.cpp). Both are listed
// in the report. The methods run at --dt (default 1/60 s,
// the benchmark's). Noise floor: a second, independent reference sample, compared with the first
// by the same code.
//
// Rest configurations are those of the shape's compiled table (with --mesh: of the first --table,
// which the methods statistical, statistical-norest, statistical-independent and statistical-spheres
// then use).
// Single drops (--runs N per sample). Run r draws its initial state from its own splitmix64
// stream seeded with mix(seed, r) (reference sample B: r + 1,000,000): orientation uniform on
// SO(3) (a uniform point of the unit 4-ball by rejection, normalised); angular velocity
// components uniform in +-5 rad/s; horizontal velocity components uniform in +-0.5 m/s,
// vertical 0; centre of mass at x = y = 0 and height uniform in [R + 0.2, R + 1.0] m above the
// plane z = 0, R the bounding radius. statsim worlds of run r are seeded with the same stream
// seed. A run ends at rest: the body asleep (Bullet deactivation, statsim MotionState::asleep),
// or max(|v|, |w| R) < 0.01 m/s for 0.5 s; or at --time-limit (10 s; counted: the drop did not
// rest). time_to_rest is the start of the last uninterrupted stretch of steps, ending at rest, in
// which the body was asleep or slower than 0.01 m/s.
//  - rest configuration: body-frame up R^T e_z, the nearest rest-pose normal of the signature
//    by angle, "other" when more than 15 degrees from all. rest_tvd = 0.5 sum |p - p_ref| over
//    the poses and "other".
//  - rest_height_err = mean over the method's runs of |z_run - zref(c_run)| / R, zref(c) the
//    reference's mean rest height in configuration c (its overall mean where it has no run in c).
//  - travel: horizontal distance from drop point to rest point; travel_w1 = W1 / mean_ref(travel).
//  - bounces: after the first contact (below), rises of the centre's height of at least
//    h = max(0.01 m, 0.05 R) above the lowest height since the last counted rise; after a rise
//    the centre must fall h below its highest point before the next can count.
//    bounce_w1 = W1 / mean_ref(bounces) (mean 0: divided by 1).
//  - rest_time_w1 = W1 of time_to_rest over the drops that rested, in each sample, divided by the
//    reference's mean over its drops that rested; the share that did not rest is reported for
//    each sample beside it. A rigid body rocking on a curved side loses energy only at impacts
//    and can rock past any time limit; its time to rest is unknown, and the time limit in its
//    place would measure the limit. When only one sample has drops that rested: 1.
//  - first_impact_ks: the tables describe a collision as everything from the first contact until
//    the body has left the ground for good (a box landing on a corner strikes with a second and a
//    third), and give the velocity and spin it leaves with. Each drop is measured at that event,
//    whatever its step (FlightTop in common/flight_top.hpp): the first contact is the first step whose
//    vertical velocity rises by more than 2 g dt; a step is free when the velocity changed by
//    gravity alone (within 1% of g dt); the collision ends at the first flight, after the first
//    contact, that leaves fast enough to rise h (v_z^2 / (2 g) >= h, the bounces' h) and stays
//    free up to its top (v_z from > 0 to <= 0). Lower hops are part of the collision. The state
//    compared is the one after the last step with a contact before that flight: engines apply
//    gravity before they solve contacts, so that is the velocity and spin the body left with, at
//    any step. (The state after the first step with a contact would be the first of several
//    contact episodes at 1 ms but all of them at 1/60 s: it would measure the step as much as
//    the response.) KS statistics of |v+| and of |w+|; first_impact_ks is the larger. A drop
//    that never flies again after its first contact (it slides, rolls or rocks to rest) has no
//    such state: it counts in both KS statistics as an atom below every speed and spin, so
//    the difference between the shares of such drops (reported as "no flight") is part of the
//    distance rather than left out.
//  - clamp rate (statsim methods): the energy guard's clamped sampled responses over all sampled
//    responses applied (World::energy_clamp_count / statistical_response_count), summed over the
//    single drops (and, in the JSON, over the piles).
// Method full-gather: Bullet full with the reference's settings at --dt, to tell the step's
// effect from the settings' (its piles and step time use statsim bench's settings, as full).
// Piles: drop_scene3(count = --pile-count, seed s) for s = 1..--pile-seeds (reference floor:
// seeds pile-seeds+1..2 pile-seeds), run until every body rests (asleep, or slower than
// 0.01 m/s for 0.5 s) or the time limit. pile_radial_w1: W1 of the bodies' horizontal
// distances from their pile's centroid, pooled over seeds, / mean_ref; pile_height_w1: W1 of the
// final centre heights / mean_ref; pile_rest_tvd: rest configurations pooled over bodies.
// Intervals: percentile bootstrap, --bootstrap (200) resamples of both samples (piles: of the
// seeds), 90 %, a fixed seed. step_ms: thread CPU time per step on the benchmark scene
// (drop_scene3, --bench-n bodies, --bench-steps steps at 1/60 s; Bullet with btAxisSweep3), in
// the same run. summary_error: see summary_error_definition().
#include "fidelity/fidelity.hpp"

#include "bench/bench_internal.hpp"
#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "ref3d/reference.hpp"
#include "ref3d/signature_json.hpp"
#include "scenes/frames.hpp"
#include "scenes/piles.hpp"
#include "scenes/scenes.hpp"
#include "statsim/signature.hpp"
#include "statsim/world3.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "fidelity/fidelity.hpp"

#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "fidelity/stages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace statsim::tools::fidelity {

namespace {

constexpr std::uint64_t kSampleB = 1000000;  // run-index offset of the second reference sample

/// Runs `per_sample` jobs of each of `samples` samples (0 and 1: the reference's samples A and
/// B, then the methods) on `threads` threads and hands each result to its sample's MethodResult,
/// in job order. Job j is run j / samples of sample j % samples: interleaved, so that the
/// expensive reference runs spread over the whole job list.
template <class Run, class Keep>
void run_samples(const char* label, std::size_t samples, std::size_t per_sample, unsigned threads, bool progress_on,
                 FidelityResult& res, Run run, Keep keep)
{
  Progress progress(label, samples * per_sample, progress_on);
  const auto all = parallel_map(
      samples * per_sample,
      [&](std::size_t job) {
        auto result = run(job % samples, job / samples);
        progress.add();
        return result;
      },
      threads);
  for (std::size_t job = 0; job < all.size(); ++job) {
    const std::size_t sample = job % samples;
    keep(sample == 0 ? res.reference : sample == 1 ? res.reference_b : res.methods[sample - 2], all[job]);
  }
}

}  // namespace

FidelityResult run_fidelity(const FidelityOptions& options)
{
  validate(options);
  const auto t_start = std::chrono::steady_clock::now();
  // The methods' views point into the loaded tables, which a move of the Setup (its vector
  // moved whole) leaves in place.
  const std::unique_ptr<Setup> setup = std::make_unique<Setup>(make_setup(options));

  FidelityResult res;
  res.options = options;
  res.shape = shape_label(options);
  res.bounding_radius = setup->radius;
  for (std::uint32_t i = 0; i < setup->poses.rest.count; ++i) {
    char b[160];
    std::snprintf(b, sizeof b, "(%.3f, %.3f, %.3f) %.4f m", double(setup->poses.rest.normals[3 * i]),
                  double(setup->poses.rest.normals[3 * i + 1]), double(setup->poses.rest.normals[3 * i + 2]),
                  double(setup->poses.rest.heights[i]));
    res.pose_labels.push_back(b);
  }
  res.pose_labels.push_back("other");
  const int configs = static_cast<int>(res.pose_labels.size());
  const bool gather_ref = options.reference == "gather";
  if (!options.drops) {
    for (const std::string& line : bench::bullet_settings(setup->body))
      res.settings.push_back("scenes (statsim bench's settings): " + line);
  } else if (gather_ref) {
    res.settings = gather_settings_lines(*setup->model, setup->reference_settings);
    if (options.piles || !options.scenes.empty())
      for (const std::string& line : bench::bullet_settings(setup->body))
        res.settings.push_back("piles and scenes (statsim bench's settings): " + line);
  } else {
    res.settings = bench::bullet_settings(setup->body);
  }

  // Single drops' reference; the piles' is always Bullet full with statsim bench's settings.
  MethodSpec ref;
  ref.name = "reference";
  ref.bullet = true;
  ref.gather_reference = gather_ref;
  ref.bullet_method = "full";
  ref.description = "Bullet full";
  const MethodSpec pile_ref = pile_reference_method(options.pile_reference_iterations);
  const std::string which = gather_ref ? "Bullet full, statsim gather's settings" : "Bullet full, statsim bench's settings";
  res.reference.name = "reference";
  res.reference.description = which + ", sample A";
  res.reference.dt = options.reference_dt;
  res.reference_b = res.reference;
  res.reference_b.description = which + ", sample B (noise floor)";

  // Every single drop is one job: (sample, run). Sample 0 and 1: the references; then the methods.
  const std::size_t runs = static_cast<std::size_t>(options.runs);
  const std::size_t samples = 2 + setup->methods.size();
  const unsigned threads = resolve_thread_count(options.threads);
  res.methods.resize(setup->methods.size());
  if (options.drops) {
    run_samples(
        "fidelity: single drops", samples, runs, threads, options.progress, res,
        [&](std::size_t sample, std::size_t r) {
          const MethodSpec& m = sample < 2 ? ref : setup->methods[sample - 2];
          const double dt = sample < 2 ? options.reference_dt : options.dt;
          const std::uint64_t index = r + (sample == 1 ? kSampleB : 0);
          const std::uint64_t stream = mix(options.seed, index);
          const std::uint64_t world = options.draw_seed == 0 ? stream : mix(options.draw_seed, stream);
          return run_single(*setup, m, stream, dt, options.time_limit, world);
        },
        [](MethodResult& mr, const DropRun& d) { mr.drops.push_back(d); });
  }
  for (std::size_t i = 0; i < setup->methods.size(); ++i) {
    res.methods[i].name = setup->methods[i].name;
    res.methods[i].description = setup->methods[i].description;
    res.methods[i].dt = options.dt;
    res.methods[i].table_bytes = setup->methods[i].table_bytes;
  }

  if (options.drops && options.piles) {
    const std::size_t seeds = static_cast<std::size_t>(options.pile_seeds);
    run_samples(
        "fidelity: piles", samples, seeds, threads, options.progress, res,
        [&](std::size_t sample, std::size_t k) {
          const MethodSpec& m = sample < 2 ? pile_ref : setup->methods[sample - 2];
          const double dt = sample < 2 ? pile_reference_step(options, "piles") : options.dt;
          const std::uint64_t seed = 1 + k + (sample == 1 ? seeds : 0);
          return run_pile(*setup, m, seed, options.pile_count, dt, options.time_limit, mix(options.seed, seed));
        },
        [](MethodResult& mr, const PileRun& p) { mr.piles.push_back(p); });
  }

  if (options.drops) {
    Progress progress("fidelity: bootstrap", samples - 1, options.progress);
    res.noise_floor = compare(res.reference_b.drops, res.reference.drops, res.reference_b.piles, res.reference.piles,
                              configs, options.bootstrap);
    progress.add();
    std::vector<Distances> d = parallel_map(
        res.methods.size(),
        [&](std::size_t i) {
          Distances x = compare(res.methods[i].drops, res.reference.drops, res.methods[i].piles, res.reference.piles,
                                configs, options.bootstrap);
          progress.add();
          return x;
        },
        threads);
    for (std::size_t i = 0; i < d.size(); ++i) res.methods[i].d = d[i];
  }

  if (!options.scenes.empty()) res.scenes = run_scenes(*setup, options, threads);

  if (options.drops && options.timing) {
    // One method at a time on this thread: thread CPU time is what the benchmark reports.
    Progress progress("fidelity: step time", setup->methods.size(), options.progress);
    for (std::size_t i = 0; i < setup->methods.size(); ++i) {
      res.methods[i].step_ms = measure_step_ms(*setup, setup->methods[i], options.bench_n, options.bench_steps);
      progress.add();
    }
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

}  // namespace statsim::tools::fidelity
