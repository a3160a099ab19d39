// `statsim fidelity`: how close each method's outcomes are to the reference's, as distributions.
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
// which the methods statistical, statistical-norest and statistical-independent then use).
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
//    whatever its step (FlightTop in fidelity.hpp): the first contact is the first step whose
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

namespace statsim::tools::fidelity {

namespace {

constexpr double kGravity = 9.81;
constexpr double kQuietSpeed = 0.01;   // m/s
constexpr double kQuietTime = 0.5;     // s
constexpr double kOtherDegrees = 15.0;
constexpr double kStillWindow = 0.25;  // s, --reference gather's stillness windows (as the gathering's)
constexpr std::uint64_t kSampleB = 1000000;  // run-index offset of the second reference sample

// Goals of summary_error.
constexpr double kGoalTvd = 0.10, kGoalHeight = 0.02, kGoalTravel = 0.20, kGoalBounce = 0.20, kGoalKs = 0.20;

std::uint64_t mix(std::uint64_t seed, std::uint64_t r)
{
  std::uint64_t z = seed * 0x9e3779b97f4a7c15ull + r + 0x632be59bd9b4e019ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace

std::vector<SceneMetric> scene_metrics(const std::string& kind)
{
  if (kind == "heap") return {{"angle_deg", "deg", false}, {"height", "m", true}};
  if (kind == "bin") return {{"fill_height", "m", true}, {"packing", "", true}};
  return {{"held", "", false}, {"overlap", "mm", false}};
}

std::vector<std::string> default_methods()
{
  return {"full", "low", "spheres7", "sphere", "statistical", "statistical-norest", "statistical-independent"};
}

double summary_error(double rest_tvd, double rest_height_err, double travel_w1, double bounce_w1,
                     double first_impact_ks)
{
  return (rest_tvd / kGoalTvd + rest_height_err / kGoalHeight + travel_w1 / kGoalTravel + bounce_w1 / kGoalBounce +
          first_impact_ks / kGoalKs) /
         5.0;
}

const char* summary_error_definition()
{
  return "summary_error is the mean of the five single-drop distances each divided by its goal (rest_tvd/0.10, "
         "rest_height_err/0.02, travel_w1/0.20, bounce_w1/0.20, first_impact_ks/0.20): 1 = at the goals on average.";
}

const char* fidelity_definitions()
{
  return "Reference: Bullet full (btGImpactMeshShape of the full mesh; boxes for box and lshape) at --reference-dt "
         "(single drops) and --pile-reference-dt (piles); methods at --dt. Single drops: --reference gather (default) "
         "uses the Bullet world and settings the tables were gathered with (tools/ref3d: 30 iterations, no warm "
         "starting, split impulse, margin 0.5 mm, restitution threshold 0.02 m/s; no deactivation: asleep once the average speeds of the centre and "
         "the farthest point stay below 0.01 m/s over two consecutive 0.25 s windows), --reference bench those of "
         "statsim bench; piles always use statsim bench's. "
         "Noise floor: a second independent reference sample (run seeds offset by 1,000,000; pile seeds N+1..2N) "
         "against the first.\n"
         "Single drops: run r has its own stream; orientation uniform on SO(3), angular velocity components uniform "
         "in +-5 rad/s, horizontal velocity components uniform in +-0.5 m/s, centre at x=y=0 and height uniform in "
         "[R+0.2, R+1.0] m (R: bounding radius). A run ends when the body is asleep or max(|v|,|w|R) < 0.01 m/s for "
         "0.5 s, or at --time-limit (counted as not rested); time_to_rest = start of the last uninterrupted stretch "
         "asleep or below 0.01 m/s.\n"
         "rest_tvd: body-frame up R^T e_z, nearest rest-pose normal of the signature (the shape's compiled table, or "
         "the first --table), 'other' beyond 15 degrees; "
         "0.5 sum |p - p_ref|. rest_height_err: mean |z - zref(c)| / R, zref(c) the reference's mean rest height in "
         "configuration c (overall mean if none). travel_w1: W1 of horizontal drop-to-rest distance / reference "
         "mean. bounce_w1: bounces = rises of the centre of at least h = max(0.01 m, 0.05 R) above the preceding "
         "minimum after the first contact (hysteresis), W1 / reference mean (1 if 0). rest_time_w1: W1 of "
         "time_to_rest over the drops that rested in each sample / the reference's mean over its rested drops "
         "(1 if only one sample has rested drops); 'not rested' gives each sample's share at the time limit.\n"
         "first_impact_ks: the state the tables describe, the velocity and spin the body leaves the ground with "
         "once its first collision (every contact episode from the first contact until it has left for good) is "
         "over, at any step: first contact = first step whose vertical velocity rises by more than 2|g|dt; free "
         "step = velocity changed by gravity alone (within 1% of |g|dt); the collision ends at the first flight that "
         "leaves with v_z^2/(2|g|) >= h and stays free up to its top; the state compared is the one after the last "
         "step with a contact before it. Max of the KS statistics of |v+| and |w+|; drops that never fly again after "
         "the first contact count as an atom below every value (their share: 'no flight').\n"
         "clamp rate (statsim): sampled responses scaled down by the energy guard / sampled responses applied, "
         "summed over the single drops. Method full-gather: Bullet full with the reference's settings at --dt "
         "(piles and step time: statsim bench's settings).\n"
         "Piles: drop_scene3(--pile-count bodies, seeds 1..N) until all rest or the time limit: W1 of distances from the "
         "pile centroid / reference mean, W1 of centre heights / reference mean, rest_tvd pooled over bodies.\n"
         "Intervals: percentile bootstrap, 200 resamples of both samples (piles: seeds), 90%. step_ms: thread CPU "
         "time per step on the benchmark scene (drop_scene3, --bench-n bodies, --bench-steps steps at 1/60 s).";
}

const char* scenes_definitions()
{
  return "Scenes (--scenes; tools/scenes/piles.hpp), seeds 1..N per sample (reference B: N+1..2N), statsim worlds "
         "seeded per scene seed. heap: --heap-count bodies poured one every 0.1 s, in turn from the 4 corners of a "
         "square of side 2.1 R at (1.5 + 0.75 N^(1/3)) 2.1 R above the origin, 1 m/s downwards, random orientations "
         "(waiting asleep far above until released); bin: --bin-count bodies in a "
         "lattice of --bin-cells x --bin-cells cells of 2.1 R between four wall planes, layer by layer; both run "
         "until every body rests (asleep, or slower than 0.01 m/s for 0.5 s) or --time-limit (the heap: after its last "
         "release). column, wall: "
         "--column-height bodies, or --wall-columns columns of --wall-height, in a rest pose (the first box's "
         "faces along the world axes), touching, no velocity; measured after --stack-time s. --mix SHAPE: heap and "
         "bin of two shapes, body i of --shape when i is even and of SHAPE when odd, R the larger bounding radius, "
         "each statsim body with its own shape's table and Bullet body with its own mesh.\n"
         "angle_deg: 8 angular sectors and radial bins of width R about the centres' mean (x, y); each cell's top is "
         "its highest centre; least squares z = a + b r over the tops of every sector from its highest cell outward, "
         "up to its first empty cell or first top less than R/2 above the lowest centre; atan(-b) in degrees (0 with "
         "fewer than 2 tops). height: "
         "the highest centre, m. fill_height: twice the mean centre height, m. packing: N V / (A fill_height), V the "
         "mesh's volume (mixed: the bodies' mean), A the bin's floor area. held: the highest centre's height over the highest placed centre's "
         "(1: the true height). overlap: deepest penetration between boxes of different bodies (separating axis "
         "test on the shape's boxes) or of a box corner below the ground, mm. all asleep: share of runs with every body asleep at the end (the engine's "
         "sleep state; Bullet: deactivated).\n"
         "Distances: the mean over seeds of the method minus reference A's (relative distances divided by A's "
         "mean); 90% percentile bootstrap intervals over resampled seeds; noise floor: reference B against A.";
}

// ---- the end of the first collision -------------------------------------------------------------

FlightTop::FlightTop(double dt, double min_rise, double gravity) : dt_(dt), min_rise_(min_rise), gravity_(gravity) {}

void FlightTop::add(const Eigen::Vector3d& velocity, const Eigen::Vector3d& spin)
{
  ++steps_;
  const Eigen::Vector3d prev = prev_v_;
  prev_v_ = velocity;
  if (steps_ == 0 || found_) return;
  const double g_dt = gravity_ * dt_;
  // Over a free step v_k = v_(k-1) - g dt e_z; what is left is the impulse of the contacts over
  // the step, per unit mass.
  const Eigen::Vector3d kick = velocity - prev + Eigen::Vector3d(0, 0, g_dt);
  if (contact_step_ < 0) {
    if (velocity.z() - prev.z() <= 2 * g_dt) return;
    contact_step_ = steps_;
  }
  if (kick.norm() > kFreeTolerance * g_dt) {
    // Whatever the step, the velocity after the last step with a contact is the one the body
    // leaves with: engines apply gravity before they solve the contacts.
    leave_v_ = velocity;
    leave_w_ = spin;
    return;
  }
  // The top of a free flight: from there the body left with leave_v_, and its centre rose
  // v_z^2 / (2 g) since, whatever the step.
  const double rise = leave_v_.z() > 0 ? leave_v_.z() * leave_v_.z() / (2 * gravity_) : 0.0;
  if (prev.z() > 0 && velocity.z() <= 0 && rise >= min_rise_) {
    found_ = true;
    speed_ = leave_v_.norm();
    spin_ = leave_w_.norm();
    rise_ = rise;
  }
}

// ---- distances -----------------------------------------------------------------------------------

namespace {

std::vector<double> config_histogram(const std::vector<int>& configs, int k)
{
  std::vector<double> h(static_cast<std::size_t>(k), 0.0);
  for (int c : configs)
    if (c >= 0 && c < k) h[static_cast<std::size_t>(c)] += 1;
  return h;
}

template <class F>
std::vector<double> column(const std::vector<DropRun>& runs, F f)
{
  std::vector<double> v;
  v.reserve(runs.size());
  for (const DropRun& r : runs) v.push_back(f(r));
  return v;
}

double guard(double m)
{
  return m > 0 ? m : 1.0;
}

// Stands for "no flight" in the samples of leaving speeds and spins (both are >= 0).
constexpr double kNoFlight = -1.0;

// W1 of the times to rest of the drops that rest in each sample, over the reference's mean: a
// body that is still rocking at the time limit has no time to rest to compare (a rigid bunny on
// its curved back loses energy only at impacts and can rock on far past any limit), so those
// are left out on both sides, and their shares are reported beside. When only one sample has
// drops that rest, as far apart as can be said: 1.
double rest_time_distance(const std::vector<DropRun>& m, const std::vector<DropRun>& ref)
{
  std::vector<double> a, b;
  for (const DropRun& r : m)
    if (!r.time_limited) a.push_back(r.rest_time);
  for (const DropRun& r : ref)
    if (!r.time_limited) b.push_back(r.rest_time);
  if (a.empty() || b.empty()) return a.empty() && b.empty() ? 0.0 : 1.0;
  return w1(a, b) / guard(mean(b));
}

struct DropStats {
  double tvd, height, travel, bounce, rest_time, ks_v, ks_w;
  double ks() const { return std::max(ks_v, ks_w); }
  double summary() const { return summary_error(tvd, height, travel, bounce, ks()); }
};

DropStats drop_stats(const std::vector<DropRun>& m, const std::vector<DropRun>& ref, int configs)
{
  DropStats s{};
  std::vector<int> cm, cr;
  for (const DropRun& r : m) cm.push_back(r.config);
  for (const DropRun& r : ref) cr.push_back(r.config);
  s.tvd = tvd(config_histogram(cm, configs), config_histogram(cr, configs));

  // zref(c): the reference's mean rest height per configuration.
  std::vector<double> zsum(static_cast<std::size_t>(configs), 0.0), zn(static_cast<std::size_t>(configs), 0.0);
  double all = 0;
  for (const DropRun& r : ref) {
    zsum[static_cast<std::size_t>(r.config)] += r.rest_height;
    zn[static_cast<std::size_t>(r.config)] += 1;
    all += r.rest_height;
  }
  const double overall = ref.empty() ? 0.0 : all / static_cast<double>(ref.size());
  double err = 0;
  for (const DropRun& r : m) {
    const std::size_t c = static_cast<std::size_t>(r.config);
    const double zref = zn[c] > 0 ? zsum[c] / zn[c] : overall;
    err += std::fabs(r.rest_height - zref);
  }
  // Rest heights are stored in units of R (run_single), so this is the error as a fraction of R.
  s.height = m.empty() ? 0.0 : err / static_cast<double>(m.size());

  auto travel = [](const DropRun& r) { return r.travel; };
  auto bounces = [](const DropRun& r) { return r.bounces; };
  s.travel = w1(column(m, travel), column(ref, travel)) / guard(mean(column(ref, travel)));
  s.bounce = w1(column(m, bounces), column(ref, bounces)) / guard(mean(column(ref, bounces)));
  s.rest_time = rest_time_distance(m, ref);
  // A drop without a flight after its first contact is an atom below every speed: the KS
  // statistic then also sees a difference in how often the body flies again, which leaving
  // those drops out would hide.
  auto speed = [](const DropRun& r) { return r.flight ? r.flight_speed : kNoFlight; };
  auto spin = [](const DropRun& r) { return r.flight ? r.flight_spin : kNoFlight; };
  s.ks_v = ks(column(m, speed), column(ref, speed));
  s.ks_w = ks(column(m, spin), column(ref, spin));
  return s;
}

struct PileStats {
  double radial, height, tvd;
};

PileStats pile_stats(const std::vector<PileRun>& m, const std::vector<PileRun>& ref, int configs)
{
  std::vector<double> mr, rr, mh, rh;
  std::vector<int> mc, rc;
  for (const PileRun& p : m) {
    mr.insert(mr.end(), p.radius.begin(), p.radius.end());
    mh.insert(mh.end(), p.height.begin(), p.height.end());
    mc.insert(mc.end(), p.config.begin(), p.config.end());
  }
  for (const PileRun& p : ref) {
    rr.insert(rr.end(), p.radius.begin(), p.radius.end());
    rh.insert(rh.end(), p.height.begin(), p.height.end());
    rc.insert(rc.end(), p.config.begin(), p.config.end());
  }
  return {w1(mr, rr) / guard(mean(rr)), w1(mh, rh) / guard(mean(rh)),
          tvd(config_histogram(mc, configs), config_histogram(rc, configs))};
}

}  // namespace

/// The bootstrap interval of get(stats(method, reference)) over resamples of both samples.
template <class Run, class Stats, class Get>
Interval resampled(const std::vector<Run>& method, const std::vector<Run>& reference, const Stats& stats,
                   const Get& get, int resamples)
{
  return bootstrap(
      method.size(), reference.size(),
      [&](const std::vector<std::size_t>& ia, const std::vector<std::size_t>& ib) {
        return get(stats(pick(method, ia), pick(reference, ib)));
      },
      resamples);
}

Distances compare(const std::vector<DropRun>& method, const std::vector<DropRun>& reference,
                  const std::vector<PileRun>& method_piles, const std::vector<PileRun>& reference_piles, int configs,
                  int resamples)
{
  Distances d;
  const DropStats full = drop_stats(method, reference, configs);
  // One resampling per statistic with the same seed: every statistic sees the same resamples.
  const auto drops = [&](const std::vector<DropRun>& a, const std::vector<DropRun>& b) {
    return drop_stats(a, b, configs);
  };
  auto ci = [&](auto get) { return resampled(method, reference, drops, get, resamples); };
  d.rest_tvd = {full.tvd, ci([](const DropStats& s) { return s.tvd; })};
  d.rest_height_err = {full.height, ci([](const DropStats& s) { return s.height; })};
  d.travel_w1 = {full.travel, ci([](const DropStats& s) { return s.travel; })};
  d.bounce_w1 = {full.bounce, ci([](const DropStats& s) { return s.bounce; })};
  d.rest_time_w1 = {full.rest_time, ci([](const DropStats& s) { return s.rest_time; })};
  d.first_impact_ks_v = {full.ks_v, ci([](const DropStats& s) { return s.ks_v; })};
  d.first_impact_ks_w = {full.ks_w, ci([](const DropStats& s) { return s.ks_w; })};
  d.first_impact_ks = {full.ks(), ci([](const DropStats& s) { return s.ks(); })};
  d.summary_error = {full.summary(), ci([](const DropStats& s) { return s.summary(); })};
  if (!method_piles.empty() && !reference_piles.empty()) {
    d.piles = true;
    const PileStats p = pile_stats(method_piles, reference_piles, configs);
    const auto piles = [&](const std::vector<PileRun>& a, const std::vector<PileRun>& b) {
      return pile_stats(a, b, configs);
    };
    auto pci = [&](auto get) { return resampled(method_piles, reference_piles, piles, get, resamples); };
    d.pile_radial_w1 = {p.radial, pci([](const PileStats& s) { return s.radial; })};
    d.pile_height_w1 = {p.height, pci([](const PileStats& s) { return s.height; })};
    d.pile_rest_tvd = {p.tvd, pci([](const PileStats& s) { return s.tvd; })};
  }
  return d;
}

void validate(const FidelityOptions& o)
{
  auto bad = [](const std::string& m) { throw std::invalid_argument(m); };
  if (o.runs < 1) bad("--runs must be at least 1");
  if (!(o.dt > 0) || o.dt > 0.1) bad("--dt must be in (0, 0.1] s");
  if (!(o.reference_dt > 0) || o.reference_dt > 0.1) bad("--reference-dt must be in (0, 0.1] s");
  if (!(o.pile_reference_dt > 0) || o.pile_reference_dt > 0.1) bad("--pile-reference-dt must be in (0, 0.1] s");
  if (!(o.time_limit > 0) || o.time_limit > 600) bad("--time-limit must be in (0, 600] s");
  if (o.pile_seeds < 1) bad("--pile-seeds must be at least 1");
  if (o.pile_count < 1 || o.pile_count > 16384) bad("--pile-count must be in [1, 16384]");
  if (o.bench_n < 1 || o.bench_n > 16384) bad("--bench-n must be in [1, 16384]");
  if (o.bench_steps < 1) bad("--bench-steps must be at least 1");
  if (o.bootstrap < 0) bad("--bootstrap must be >= 0");
  if (o.reference != "gather" && o.reference != "bench") bad("--reference must be gather or bench");
  for (const std::string& k : o.scenes)
    if (k != "heap" && k != "bin" && k != "stack" && k != "column" && k != "wall")
      bad("--scenes takes heap, bin, stack, column, wall (got '" + k + "')");
  if (!o.drops && o.scenes.empty()) bad("--scenes-only needs --scenes");
  if (o.scene_seeds < 1) bad("--scene-seeds must be at least 1");
  if (o.heap_count < 1 || o.heap_count > 16384) bad("--heap-count must be in [1, 16384]");
  if (o.bin_count < 1 || o.bin_count > 16384) bad("--bin-count must be in [1, 16384]");
  if (o.bin_cells < 1 || o.bin_cells > 64) bad("--bin-cells must be in [1, 64]");
  if (o.column_height < 1 || o.column_height > 1000) bad("--column-height must be in [1, 1000]");
  if (o.wall_columns < 1 || o.wall_columns > 100) bad("--wall-columns must be in [1, 100]");
  if (o.wall_height < 1 || o.wall_height > 1000) bad("--wall-height must be in [1, 1000]");
  if (!(o.stack_time > 0) || o.stack_time > 600) bad("--stack-time must be in (0, 600] s");
  if (!o.mesh.empty() && o.tables.empty()) bad("--mesh needs --table NAME=FILE.json (the shape has no compiled table)");
  for (const auto& t : o.tables)
    if (t.first.empty() || t.second.empty()) bad("--table takes NAME=FILE.json");
  if (!o.mix.empty()) {
    if (o.mix != "bunny" && o.mix != "box" && o.mix != "lshape") bad("--mix takes bunny, box or lshape");
    if (!o.mesh.empty() || !o.tables.empty()) bad("--mix needs a compiled shape (no --mesh, no --table)");
    if (o.drops) bad("--mix needs --scenes-only (it mixes the heap and the bin)");
    for (const std::string& k : o.scenes)
      if (k != "heap" && k != "bin") bad("--mix takes the heap and bin scenes only (got '" + k + "')");
  }
}

// ---- running -------------------------------------------------------------------------------------

namespace {

/// What a method is and how to build its world.
struct MethodSpec {
  std::string name;
  std::string description;
  bool bullet = false;
  bool gather_reference = false;  // tools/ref3d's Bullet world (single drops only)
  std::string bullet_method;  // full, low, hull, spheres7, sphere
  SignatureView<3> table{};
  bench::StatsimVariant variant;
  long long table_bytes = -1;
};

struct Setup {
  bench::Body3 body;
  // --mix: the second shape of the mixed scenes and its compiled table (every statistical method
  // takes it for that shape's bodies).
  bench::Body3 mix_body;
  SignatureView<3> mix_table{};
  bool mixed = false;
  SignatureView<3> poses;  // the signature whose rest poses classify every run
  std::vector<LoadedSignature3> loaded;
  std::vector<MethodSpec> methods;
  double radius = 0;
  // --reference gather: the shape as the gathering builds it (same body frame as `body`: both
  // are the mesh's principal frame about its centre of mass) and the gathering's settings.
  std::unique_ptr<ref3d::ShapeModel> model;
  ref3d::ReferenceSettings reference_settings;
};

// The gathering's reference as a bench::Sim of one body (single drops): a Reference of its own,
// so that nothing (GImpact's lock state included) is shared between threads.
class GatherReferenceSim final : public bench::Sim {
public:
  GatherReferenceSim(const ref3d::ShapeModel& model, const ref3d::ReferenceSettings& settings,
                     const scenes::BodyState3& start)
      : reference_(std::make_unique<ref3d::Reference>(model, settings)),
        radius_(model.bounding_radius),
        window_(std::max(1L, static_cast<long>(std::ceil(kStillWindow / settings.dt - 1e-9)))),
        limit_(kQuietSpeed * static_cast<double>(window_) * settings.dt)
  {
    ref3d::RigidState s;
    s.position = start.position;
    s.orientation = start.orientation;
    s.velocity = start.linear_velocity;
    s.spin = start.angular_velocity;
    run_ = reference_->run(s);
    anchor_ = s;
  }
  // Asleep as the gathering's drop() decides rest: a resting GImpact body jitters by several
  // mm/s from step to step while going nowhere, so instantaneous speeds stay above 0.01 m/s
  // now and then; the average speeds of the centre and of the farthest point over each of two
  // consecutive windows of 0.25 s below kQuietSpeed count instead (like Bullet's deactivation in
  // the other methods, after 0.5 s of stillness).
  void step() override
  {
    run_->step();
    if (++steps_ % window_ != 0) return;
    const ref3d::RigidState s = run_->state();
    const double moved = (s.position - anchor_.position).norm();
    const double turned = s.orientation.angularDistance(anchor_.orientation) * radius_;
    quiet_windows_ = moved < limit_ && turned < limit_ ? quiet_windows_ + 1 : 0;
    anchor_ = s;
  }
  std::size_t asleep() const override { return 0; }
  bench::EndState end_state() const override
  {
    bench::EndState e;
    e.mean_height = run_->state().position.z();
    return e;
  }
  std::size_t body_count() const override { return 1; }
  scenes::BodyState3 body_state(std::size_t) const override
  {
    const ref3d::RigidState r = run_->state();
    scenes::BodyState3 s;
    s.position = r.position;
    s.orientation = r.orientation;
    s.linear_velocity = r.velocity;
    s.angular_velocity = r.spin;
    return s;
  }
  bool body_asleep(std::size_t) const override { return quiet_windows_ >= 2; }

private:
  std::unique_ptr<ref3d::Reference> reference_;
  std::unique_ptr<ref3d::Reference::Run> run_;
  double radius_;
  long window_;   // steps per stillness window
  double limit_;  // m of motion per window
  long steps_ = 0;
  int quiet_windows_ = 0;
  ref3d::RigidState anchor_;
};

// The gathering's reference settings, one per line (as tables/NAME.hpp's header lists them).
std::vector<std::string> gather_settings_lines(const ref3d::ShapeModel& m, const ref3d::ReferenceSettings& r)
{
  char b[600];
  std::vector<std::string> out;
  out.push_back("Bullet " + ref3d::bullet_version() +
                " (double precision) with the settings of statsim gather (tools/ref3d/reference.hpp), one world "
                "per drop");
  std::snprintf(b, sizeof b,
                "dt %.6g s, %d solver iterations, warm starting %s, split impulse %s, erp %.3g, speculative contacts "
                "%s, multipoint convex-plane manifold %s",
                r.dt, r.solver_iterations, r.warm_starting ? "on" : "off", r.split_impulse ? "always" : "Bullet's",
                r.erp, r.speculative_contacts ? "on" : "off", r.multipoint_plane ? "on" : "off");
  out.push_back(b);
  std::snprintf(b, sizeof b,
                "restitution %.3g, friction %.3g (ground 1 and 1: Bullet multiplies), restitution threshold %.3g m/s, "
                "gravity %.3g m/s^2, rolling friction %.3g m, no deactivation (rest: average speeds of the centre and the farthest point below 0.01 m/s over two consecutive 0.25 s windows)",
                r.restitution, r.friction, r.restitution_threshold, r.gravity, r.rest_rolling_friction);
  out.push_back(b);
  const bool plane = r.ground_auto ? m.kind == ref3d::ShapeKind::mesh : r.ground == ref3d::Ground::plane;
  const char* body = m.kind == ref3d::ShapeKind::box        ? "btBoxShape"
                     : m.kind == ref3d::ShapeKind::compound ? "btCompoundShape of btBoxShapes"
                     : r.mesh_hull                          ? "btConvexHullShape of the mesh's hull"
                                                            : "btGImpactMeshShape of the full mesh";
  std::snprintf(b, sizeof b, "body: %s, margin %.3g m, mass %.6g kg; ground: %s", body, r.margin, m.mass.mass,
                plane ? "btStaticPlaneShape z = 0" : "static btBoxShape, top face z = 0");
  out.push_back(b);
  return out;
}

std::unique_ptr<bench::Sim> build(const Setup& setup, const MethodSpec& m, const scenes::DropScene3& scene,
                                  std::uint64_t seed, double dt)
{
  if (m.gather_reference) {
    // make_setup() builds the model whenever a method uses it; single drops only (one body).
    ref3d::ReferenceSettings settings = setup.reference_settings;
    settings.dt = dt;
    return std::make_unique<GatherReferenceSim>(*setup.model, settings, scene.bodies[0]);
  }
  if (m.bullet) {
    // Shapes per world: GImpact shapes keep mutable lock state, so worlds on different threads
    // must not share them.
    return bench::make_bullet(bench::make_bullet_shapes(setup.body), m.bullet_method, "sap", scene, dt);
  }
  return bench::make_statsim3_table(m.table, setup.body.mass, scene, seed, dt, "", m.variant);
}

int classify(const Eigen::Quaterniond& q, const SignatureView<3>& sig)
{
  const Eigen::Vector3d up = q.normalized().toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ();
  const double cos_other = std::cos(kOtherDegrees * M_PI / 180.0);
  int best = -1;
  double best_dot = -2;
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    const Eigen::Vector3d n(double(sig.rest.normals[3 * i]), double(sig.rest.normals[3 * i + 1]),
                            double(sig.rest.normals[3 * i + 2]));
    const double d = up.dot(n.normalized());
    if (d > best_dot) best_dot = d, best = static_cast<int>(i);
  }
  return best >= 0 && best_dot >= cos_other ? best : static_cast<int>(sig.rest.count);
}

scenes::BodyState3 drop_state(std::uint64_t stream, double radius)
{
  scenes::SceneRng rng(stream);
  double w, x, y, z, n2;
  do {
    w = rng.uniform(-1, 1), x = rng.uniform(-1, 1), y = rng.uniform(-1, 1), z = rng.uniform(-1, 1);
    n2 = w * w + x * x + y * y + z * z;
  } while (n2 > 1 || n2 < 1e-6);
  const double inv = 1.0 / std::sqrt(n2);
  scenes::BodyState3 s;
  s.orientation = Eigen::Quaterniond(w * inv, x * inv, y * inv, z * inv);
  s.angular_velocity = Eigen::Vector3d(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
  s.linear_velocity = Eigen::Vector3d(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), 0.0);
  s.position = Eigen::Vector3d(0, 0, rng.uniform(radius + 0.2, radius + 1.0));
  return s;
}

double speed(const scenes::BodyState3& s, double radius)
{
  return std::max(s.linear_velocity.norm(), s.angular_velocity.norm() * radius);
}

DropRun run_single(const Setup& setup, const MethodSpec& m, std::uint64_t stream, double dt, double limit)
{
  const double R = setup.radius;
  scenes::DropScene3 scene;
  scene.options.count = 1;
  scene.options.bounding_radius = R;
  scene.bodies.push_back(drop_state(stream, R));
  scene.bounds_lo = Eigen::Vector3d(-50, -50, -1);
  scene.bounds_hi = Eigen::Vector3d(50, 50, 10);
  std::unique_ptr<bench::Sim> sim = build(setup, m, scene, stream, dt);

  DropRun out;
  const scenes::BodyState3 start = scene.bodies[0];
  scenes::BodyState3 s = sim->body_state(0);
  const double hysteresis = std::max(0.01, 0.05 * R);
  FlightTop top(dt, hysteresis, kGravity);
  top.add(s.linear_velocity, s.angular_velocity);
  bool rising = false;
  double low = 0, high = 0;
  double still_since = -1, quiet_since = -1;
  const long steps = static_cast<long>(std::ceil(limit / dt - 1e-9));
  double t = 0;
  bool rested = false;
  for (long k = 1; k <= steps; ++k) {
    sim->step();
    t = static_cast<double>(k) * dt;
    s = sim->body_state(0);
    const bool contact = top.contact();
    top.add(s.linear_velocity, s.angular_velocity);
    if (!contact && top.contact()) low = s.position.z();
    if (top.contact()) {
      const double z = s.position.z();
      if (!rising) {
        low = std::min(low, z);
        if (z >= low + hysteresis) rising = true, high = z, out.bounces += 1;
      } else {
        high = std::max(high, z);
        if (z <= high - hysteresis) rising = false, low = z;
      }
    }
    const bool asleep = sim->body_asleep(0);
    const bool quiet = speed(s, R) < kQuietSpeed;
    if (asleep || quiet) {
      if (still_since < 0) still_since = t;
    } else {
      still_since = -1;
    }
    if (quiet) {
      if (quiet_since < 0) quiet_since = t;
    } else {
      quiet_since = -1;
    }
    if (asleep || (quiet_since >= 0 && t - quiet_since >= kQuietTime - 1e-9)) {
      rested = true;
      break;
    }
  }
  out.impact = top.contact();
  out.flight = top.found();
  out.flight_speed = top.speed();
  out.flight_spin = top.spin();
  out.responses = sim->statistical_responses();
  out.clamps = sim->energy_clamps();
  out.time_limited = !rested;
  out.rest_time = rested ? still_since : t;
  out.config = classify(s.orientation, setup.poses);
  out.rest_height = s.position.z() / R;
  out.travel = std::hypot(s.position.x() - start.position.x(), s.position.y() - start.position.y());
  return out;
}

PileRun run_pile(const Setup& setup, const MethodSpec& m, std::uint64_t seed, int count, double dt, double limit,
                 std::uint64_t world_seed)
{
  scenes::DropOptions o;
  o.count = count;
  o.bounding_radius = setup.radius;
  o.seed = seed;
  const scenes::DropScene3 scene = scenes::drop_scene3(o);
  MethodSpec many = m;
  many.gather_reference = false;  // GatherReferenceSim holds one body
  std::unique_ptr<bench::Sim> sim = build(setup, many, scene, world_seed, dt);
  const std::size_t n = scene.bodies.size();
  std::vector<double> quiet_since(n, -1);
  const long steps = static_cast<long>(std::ceil(limit / dt - 1e-9));
  PileRun out;
  out.time_limited = true;
  std::vector<scenes::BodyState3> s(n);
  double t = 0;
  for (long k = 1; k <= steps; ++k) {
    sim->step();
    t = static_cast<double>(k) * dt;
    bool all = true;
    for (std::size_t i = 0; i < n; ++i) {
      s[i] = sim->body_state(i);
      if (speed(s[i], setup.radius) < kQuietSpeed) {
        if (quiet_since[i] < 0) quiet_since[i] = t;
      } else {
        quiet_since[i] = -1;
      }
      const bool rest = sim->body_asleep(i) || (quiet_since[i] >= 0 && t - quiet_since[i] >= kQuietTime - 1e-9);
      all = all && rest;
    }
    if (all) {
      out.time_limited = false;
      break;
    }
  }
  out.seconds = t;
  out.responses = sim->statistical_responses();
  out.clamps = sim->energy_clamps();
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& b : s) c += b.position.head<2>();
  c /= static_cast<double>(n);
  for (const auto& b : s) {
    out.radius.push_back((b.position.head<2>() - c).norm());
    out.height.push_back(b.position.z());
    out.config.push_back(classify(b.orientation, setup.poses));
  }
  return out;
}

double measure_step_ms(const Setup& setup, const MethodSpec& m, int n, int steps)
{
  scenes::DropOptions o;
  o.count = n;
  o.bounding_radius = setup.radius;
  o.seed = 1;
  const scenes::DropScene3 scene = scenes::drop_scene3(o);
  MethodSpec many = m;
  many.gather_reference = false;  // GatherReferenceSim holds one body
  std::unique_ptr<bench::Sim> sim = build(setup, many, scene, 1, 1.0 / 60.0);
  const double t0 = bench::thread_cpu_ms();
  for (int k = 0; k < steps; ++k) sim->step();
  return (bench::thread_cpu_ms() - t0) / steps;
}

bench::Body3 body_from_mesh(const std::string& path, const SignatureView<3>& table)
{
  TriMesh mesh;
  MeshError error;
  if (!load_obj(path, mesh, error)) throw std::runtime_error(error.message);
  const MassProperties mp = compute_mass_properties(mesh, 1.0);
  bench::Body3 body;
  body.shape = std::filesystem::path(path).stem().string();
  for (const auto& p : mesh.vertices) {
    body.full_vertices.push_back(mp.principal_axes.transpose() * (p - mp.com));
    body.bounding_radius = std::max(body.bounding_radius, body.full_vertices.back().norm());
  }
  for (const auto& t : mesh.triangles) body.full_indices.insert(body.full_indices.end(), t.begin(), t.end());
  body.mass = double(table.mass);
  body.inertia = mp.principal_moments * (body.mass / mp.volume);
  body.sphere_radius = double(table.height.mean[0]);
  body.sphere_radius_note = "the loaded table's mean collision radius h_coll at spin ratio 0";
  const WorldDef<3> def{};
  body.surface.restitution = double(table.material.restitution);
  body.surface.friction = double(table.material.friction);
  body.surface.rolling_resistance = double(table.material.rolling_resistance);
  body.surface.restitution_threshold = double(def.restitution_threshold);
  body.surface.sleep_speed = double(def.sleep_speed);
  body.surface.sleep_time = double(def.sleep_time);
  body.has_table = true;
  body.table_name = "loaded";
  return body;
}

Setup make_setup(const FidelityOptions& o)
{
  Setup s;
  // No reallocation after a view is taken: views point into the tables' strings and vectors.
  s.loaded.reserve(o.tables.size());
  for (const auto& t : o.tables) {
    s.loaded.push_back(load_signature_json(t.second));
    s.loaded.back().name() = t.first;
  }
  SignatureView<3> compiled{};
  bool have_compiled = false;
  if (o.mesh.empty()) {
    s.body = bench::load_body3(o.shape, o.meshes_dir);
    have_compiled = bench::statsim_table3(o.shape, compiled);
    if (!have_compiled && s.loaded.empty())
      throw std::runtime_error("no statistical table for " + o.shape + " (generate tables/" + o.shape +
                               ".hpp or pass --table NAME=FILE.json)");
  } else {
    s.body = body_from_mesh(o.mesh, s.loaded.front().view());
  }
  s.radius = s.body.bounding_radius;
  if (!o.mix.empty()) {
    s.mixed = true;
    s.mix_body = bench::load_body3(o.mix, o.meshes_dir);
    if (!bench::statsim_table3(o.mix, s.mix_table)) throw std::runtime_error("no statistical table for " + o.mix);
  }
  const std::vector<std::string> names = o.methods.empty() ? default_methods() : o.methods;
  if (o.reference == "gather" || std::find(names.begin(), names.end(), "full-gather") != names.end()) {
    // The gathering's defaults (tables/NAME.hpp's header lists them) at the body's density.
    const std::string shape = o.mesh.empty() ? o.shape : std::string();
    s.model = std::make_unique<ref3d::ShapeModel>(ref3d::load_shape_model(shape, o.mesh, 1000.0));
    if (std::abs(s.model->mass.mass - s.body.mass) > 1e-9 * s.body.mass)
      *s.model = ref3d::load_shape_model(shape, o.mesh, 1000.0 * s.body.mass / s.model->mass.mass);
  }
  s.poses = have_compiled ? compiled : s.loaded.front().view();
  const SignatureView<3> base = have_compiled ? compiled : s.loaded.front().view();
  const long long base_bytes =
      have_compiled ? static_cast<long long>(signature_bytes(compiled)) : static_cast<long long>(s.loaded.front().bytes());
  const std::string base_name = have_compiled ? s.body.table_name : s.loaded.front().path;

  auto shapes = bench::make_bullet_shapes(s.body);
  auto mix_shapes = s.mixed ? bench::make_bullet_shapes(s.mix_body) : nullptr;
  for (const std::string& name : names) {
    MethodSpec m;
    m.name = name;
    if (s.mixed && name.rfind("statistical:", 0) == 0) {
      if (o.methods.empty()) continue;
      throw std::invalid_argument("method " + name + ": --mix takes the compiled tables only");
    }
    if (name == "full" || name == "low" || name == "hull" || name == "spheres7" || name == "sphere") {
      std::string why;
      if (!bench::bullet_supports(*shapes, name, why) || (mix_shapes && !bench::bullet_supports(*mix_shapes, name, why))) {
        if (o.methods.empty()) continue;  // the default list keeps what the shape supports
        throw std::invalid_argument("method " + name + ": " + why);
      }
      m.bullet = true;
      m.bullet_method = name;
      m.description = "Bullet " + name;
    } else if (name == "full-gather") {
      m.bullet = true;
      m.gather_reference = true;
      m.bullet_method = "full";
      m.description = "Bullet full, statsim gather's settings (piles and step time: statsim bench's)";
    } else if (name == "statistical" || name == "statistical-norest" || name == "statistical-independent") {
      m.table = base;
      m.table_bytes = base_bytes;
      m.variant.rest_conditions = name != "statistical-norest";
      m.variant.independent_pairs = name == "statistical-independent";
      m.description = "statsim, " + base_name +
                      (name == "statistical-norest" ? ", resting conditions off"
                       : name == "statistical-independent" ? ", independent pair response"
                                                           : ", momentum pair response, resting conditions on");
    } else if (name.rfind("statistical:", 0) == 0) {
      const std::string t = name.substr(12);
      auto it = std::find_if(s.loaded.begin(), s.loaded.end(), [&](const LoadedSignature3& l) { return l.name() == t; });
      if (it == s.loaded.end()) throw std::invalid_argument("method " + name + ": no --table " + t + "=FILE.json");
      m.table = it->view();
      m.table_bytes = static_cast<long long>(it->bytes());
      m.description = "statsim, " + it->path + (it->i16() ? " (i16)" : " (f32)");
    } else {
      throw std::invalid_argument("unknown method '" + name +
                                  "' (full, full-gather, low, hull, spheres7, sphere, statistical, statistical-norest, "
                                  "statistical-independent, statistical:NAME)");
    }
    s.methods.push_back(m);
  }
  // Every loaded table is compared even when not named in --methods.
  for (const LoadedSignature3& l : s.loaded) {
    const std::string name = "statistical:" + l.name();
    if (std::none_of(s.methods.begin(), s.methods.end(), [&](const MethodSpec& m) { return m.name == name; })) {
      MethodSpec m;
      m.name = name;
      m.table = l.view();
      m.table_bytes = static_cast<long long>(l.bytes());
      m.description = "statsim, " + l.path + (l.i16() ? " (i16)" : " (f32)");
      s.methods.push_back(m);
    }
  }
  return s;
}

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


// ---- pile scenes (--scenes) ------------------------------------------------------------------------

std::vector<std::string> expand_scenes(const std::vector<std::string>& names)
{
  std::vector<std::string> out;
  auto add = [&](const std::string& k) {
    if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  };
  for (const std::string& n : names) {
    if (n == "stack") add("column"), add("wall");
    else add(n);
  }
  return out;
}

// A stack's pose for a shape built of boxes: the first box's axes along the world's (a box face
// down, the L-shape flat on its large face). The L-shape's body frame is its principal frame;
// a box is symmetric about its own axes, so turning the frame into a proper rotation by flipping
// one axis keeps every face axis-aligned.
Eigen::Quaterniond stack_orientation(const bench::Body3& body)
{
  if (body.boxes.empty())
    throw std::invalid_argument("the column and the wall need a shape built of boxes (box, lshape), not " + body.shape);
  Eigen::Matrix3d q = body.boxes.front().rotation.transpose();
  if (q.determinant() < 0) q.row(0) *= -1;
  return Eigen::Quaterniond(q).normalized();
}

// Volume of the closed triangle mesh (divergence theorem: the sum of the signed volumes of the
// tetrahedra from the origin to each triangle, a . (b x c) / 6).
double mesh_volume(const bench::Body3& body)
{
  double v = 0;
  for (std::size_t t = 0; t + 2 < body.full_indices.size(); t += 3) {
    const Eigen::Vector3d& a = body.full_vertices[static_cast<std::size_t>(body.full_indices[t])];
    const Eigen::Vector3d& b = body.full_vertices[static_cast<std::size_t>(body.full_indices[t + 1])];
    const Eigen::Vector3d& c = body.full_vertices[static_cast<std::size_t>(body.full_indices[t + 2])];
    v += a.dot(b.cross(c));
  }
  return std::fabs(v) / 6.0;
}

// The bounding radius R of the heap and bin: of the shape, or the larger of a mixed scene's two.
double scene_radius(const Setup& setup)
{
  return setup.mixed ? std::max(setup.radius, setup.mix_body.bounding_radius) : setup.radius;
}

scenes::PileScene3 make_scene(const Setup& setup, const FidelityOptions& o, const std::string& kind,
                              std::uint64_t seed)
{
  if (kind == "heap") {
    scenes::HeapOptions h;
    h.count = o.heap_count;
    h.bounding_radius = scene_radius(setup);
    h.seed = seed;
    h.shapes = setup.mixed ? 2 : 1;
    return scenes::heap_scene(h);
  }
  if (kind == "bin") {
    scenes::BinOptions b;
    b.count = o.bin_count;
    b.bounding_radius = scene_radius(setup);
    b.seed = seed;
    b.shapes = setup.mixed ? 2 : 1;
    b.cells = o.bin_cells;
    return scenes::bin_scene(b);
  }
  scenes::StackOptions s;
  s.orientation = stack_orientation(setup.body);
  s.height = kind == "column" ? o.column_height : o.wall_height;
  s.columns = kind == "column" ? 1 : o.wall_columns;
  scenes::rotated_extent(setup.body.full_vertices, s.orientation, s.lo, s.hi);
  return scenes::stack_scene(s);
}

std::string describe_scene(const scenes::PileScene3& sc, const FidelityOptions& o)
{
  char b[400];
  if (sc.kind == "heap")
    std::snprintf(b, sizeof b,
                  "heap: %zu bodies poured one every %.3g s from 4 points %.3g m apart at %.3g m above the origin, "
                  "%.3g m/s downwards, onto the ground; runs end when all rest after the last release or %.3g s after it",
                  sc.bodies.size(), sc.release_time.size() > 1 ? sc.release_time[1] : 0.0, sc.cell, sc.nozzle_height,
                  sc.pour_speed, o.time_limit);
  else if (sc.kind == "bin")
    std::snprintf(b, sizeof b,
                  "bin: %zu bodies in a square bin of inner side %.3g m (%d x %d cells of %.3g m, layers from %.3g m), "
                  "walls and ground planes; runs end when all rest or at %.3g s",
                  sc.bodies.size(), 2 * sc.bin_half_width, o.bin_cells, o.bin_cells, sc.cell, 1.5 * sc.cell,
                  o.time_limit);
  else
    std::snprintf(b, sizeof b,
                  "%s: %d column(s) of %d bodies in a rest pose, touching (pitch %.4g m, column width %.4g m, top "
                  "centre placed at %.4g m), no velocity; measured after %.3g s",
                  sc.kind.c_str(), sc.columns, sc.height, sc.pitch, sc.width, sc.bodies.back().position.z(),
                  o.stack_time);
  return b;
}

struct SceneOutcome {
  SceneRun run;
  std::vector<scenes::BodyState3> states;  // final
  std::vector<bool> asleep;
  std::vector<int> shapes;  // a mixed scene's shape of each body (PileScene3::shapes)
};

SceneOutcome run_scene(const Setup& setup, const MethodSpec& m, const scenes::PileScene3& sc,
                       const FidelityOptions& o, double dt, std::uint64_t world_seed,
                       const std::vector<double>& volumes)
{
  const double radius = scene_radius(setup);
  const scenes::DropScene3 drop = sc.as_drop_scene();
  std::vector<bullet::Plane> planes;
  for (const scenes::ScenePlane& p : sc.planes) planes.push_back({p.normal, p.offset});
  std::unique_ptr<bench::Sim> sim;
  if (m.bullet) {
    // dbvt: the sweep-and-prune broad phase holds N + 2 handles, too few with the bin's walls.
    bullet::DropSettings s = bench::bullet_drop_settings(setup.body, m.bullet_method, "dbvt", drop);
    s.planes = planes;
    if (sc.shapes.empty())
      sim = bench::make_bullet(bench::make_bullet_shapes(setup.body), m.bullet_method, s, sc.bodies, dt);
    else
      sim = bench::make_bullet_mixed({bench::make_bullet_shapes(setup.body), bench::make_bullet_shapes(setup.mix_body)},
                                     sc.shapes, m.bullet_method, s, sc.bodies, dt);
  } else {
    // The statsim world adds the ground itself; the rest are walls.
    const std::vector<bullet::Plane> walls(planes.begin() + 1, planes.end());
    if (sc.shapes.empty())
      sim = bench::make_statsim3_table(m.table, setup.body.mass, drop, world_seed, dt, "", m.variant, walls);
    else
      sim = bench::make_statsim3_mixed({m.table, setup.mix_table}, {setup.body.mass, setup.mix_body.mass}, sc.shapes,
                                       drop, world_seed, dt, m.variant, walls);
  }
  const bool stack = sc.kind == "column" || sc.kind == "wall";
  // The heap's time limit counts from its last release.
  const double limit = stack ? o.stack_time : o.time_limit + (sc.release_time.empty() ? 0.0 : sc.release_time.back());
  const std::size_t n = sc.bodies.size();
  std::vector<double> quiet_since(n, -1);
  const long steps = static_cast<long>(std::ceil(limit / dt - 1e-9));
  SceneOutcome out;
  out.shapes = sc.shapes;
  out.run.time_limited = !stack;
  out.states.resize(n);
  double t = 0;
  std::size_t released = 0;  // heap: bodies are released in order
  for (long k = 1; k <= steps; ++k) {
    for (; released < sc.release.size() && sc.release_time[released] <= t + 1e-9; ++released)
      sim->place_body(released, sc.release[released]);
    sim->step();
    t = static_cast<double>(k) * dt;
    if (stack || released < sc.release.size()) continue;
    bool all = true;
    for (std::size_t i = 0; i < n; ++i) {
      const scenes::BodyState3 s = sim->body_state(i);
      if (speed(s, radius) < kQuietSpeed) {
        if (quiet_since[i] < 0) quiet_since[i] = t;
      } else {
        quiet_since[i] = -1;
      }
      all = all && (sim->body_asleep(i) || (quiet_since[i] >= 0 && t - quiet_since[i] >= kQuietTime - 1e-9));
    }
    if (all) {
      out.run.time_limited = false;
      break;
    }
  }
  out.run.seconds = t;
  out.run.all_asleep = true;
  std::vector<Eigen::Vector3d> centres(n);
  out.asleep.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.states[i] = sim->body_state(i);
    centres[i] = out.states[i].position;
    out.asleep[i] = sim->body_asleep(i);
    out.run.all_asleep = out.run.all_asleep && out.asleep[i];
  }
  if (sc.kind == "heap") {
    const scenes::HeapProfile h = scenes::heap_profile(centres, radius, 0.5 * radius);
    out.run.values = {h.angle_deg, h.height};
  } else if (sc.kind == "bin") {
    std::vector<double> z;
    for (const Eigen::Vector3d& c : centres) z.push_back(c.z());
    const double side = 2 * sc.bin_half_width;
    // A mixed bin: the mean volume of its bodies.
    double volume = 0;
    for (std::size_t i = 0; i < n; ++i) volume += volumes[sc.shapes.empty() ? 0 : static_cast<std::size_t>(sc.shapes[i])];
    volume /= static_cast<double>(n);
    const scenes::BinFill f = scenes::bin_fill(z, volume, side * side);
    out.run.values = {f.fill_height, f.packing};
  } else {
    std::vector<Eigen::Quaterniond> orientations(n);
    for (std::size_t i = 0; i < n; ++i) orientations[i] = out.states[i].orientation;
    std::vector<scenes::SceneBox> boxes;
    for (const bench::Body3::Box& b : setup.body.boxes) boxes.push_back({b.centre, b.rotation, b.half_extents});
    const scenes::StackHold h = scenes::stack_hold(sc, boxes, centres, orientations);
    out.run.values = {h.held, 1e3 * h.overlap};
  }
  return out;
}

void write_scene_frames(const std::string& path, const Setup& setup, const SceneOutcome& r)
{
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + path);
  scenes::write_frames_header(f);
  for (std::size_t i = 0; i < r.states.size(); ++i)
    scenes::write_frame_row(f, 0, r.run.seconds, static_cast<std::uint32_t>(i),
                            (!r.shapes.empty() && r.shapes[i] == 1 ? setup.mix_body : setup.body).shape.c_str(),
                            r.states[i].position,
                            r.states[i].orientation, r.asleep[i] ? 2 : 0, 0.0);
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
}

double metric_mean(const std::vector<SceneRun>& runs, std::size_t k)
{
  double s = 0;
  for (const SceneRun& r : runs) s += r.values[k];
  return runs.empty() ? 0.0 : s / static_cast<double>(runs.size());
}

double metric_distance(const SceneMetric& m, const std::vector<SceneRun>& a, const std::vector<SceneRun>& ref,
                       std::size_t k)
{
  const double d = metric_mean(a, k) - metric_mean(ref, k);
  if (!m.relative) return d;
  const double r = metric_mean(ref, k);
  return r != 0 ? d / r : 0.0;
}

double asleep_share(const std::vector<SceneRun>& runs)
{
  double n = 0;
  for (const SceneRun& r : runs) n += r.all_asleep;
  return runs.empty() ? 0.0 : n / static_cast<double>(runs.size());
}

// Means (with intervals over resampled seeds) and, against `ref`, the distances.
void summarise(SceneSample& s, const std::vector<SceneMetric>& metrics, const std::vector<SceneRun>* ref,
               int resamples)
{
  const std::size_t n = s.runs.size();
  auto own = [&](auto stat) {
    return bootstrap(
        n, n, [&](const std::vector<std::size_t>& ia, const std::vector<std::size_t>&) { return stat(pick(s.runs, ia)); },
        resamples);
  };
  s.means.clear();
  s.distances.clear();
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    s.means.push_back({metric_mean(s.runs, k), own([k](const std::vector<SceneRun>& r) { return metric_mean(r, k); })});
    if (!ref) continue;
    const SceneMetric& m = metrics[k];
    s.distances.push_back({metric_distance(m, s.runs, *ref, k),
                           resampled(s.runs, *ref,
                                     [&](const std::vector<SceneRun>& a, const std::vector<SceneRun>& b) {
                                       return metric_distance(m, a, b, k);
                                     },
                                     [](double x) { return x; }, resamples)});
  }
  s.asleep = {asleep_share(s.runs), own([](const std::vector<SceneRun>& r) { return asleep_share(r); })};
}

std::vector<SceneResult> run_scenes(const Setup& setup, const FidelityOptions& o, unsigned threads)
{
  std::vector<SceneResult> results;
  std::vector<double> volumes{mesh_volume(setup.body)};
  if (setup.mixed) volumes.push_back(mesh_volume(setup.mix_body));
  const std::size_t seeds = static_cast<std::size_t>(o.scene_seeds);
  const std::size_t samples = 2 + setup.methods.size();
  MethodSpec ref;
  ref.name = "reference";
  ref.bullet = true;
  ref.bullet_method = "full";
  for (const std::string& kind : expand_scenes(o.scenes)) {
    SceneResult res;
    res.kind = kind;
    res.metrics = scene_metrics(kind);
    res.description = describe_scene(make_scene(setup, o, kind, 1), o);
    Progress progress(("fidelity: " + kind).c_str(), samples * seeds, o.progress);
    // Job j: sample j % samples, seed index j / samples (the expensive reference runs spread out).
    const std::vector<SceneOutcome> all = parallel_map(
        samples * seeds,
        [&](std::size_t job) {
          const std::size_t sample = job % samples, k = job / samples;
          const std::uint64_t seed = 1 + k + (sample == 1 ? seeds : 0);
          const MethodSpec& m = sample < 2 ? ref : setup.methods[sample - 2];
          const double dt = sample < 2 ? o.pile_reference_dt : o.dt;
          SceneOutcome r = run_scene(setup, m, make_scene(setup, o, kind, seed), o, dt, mix(o.seed, seed), volumes);
          progress.add();
          if (k != 0 || o.scene_frames.empty()) r.states.clear();
          return r;
        },
        threads);
    res.reference.name = "reference";
    res.reference.dt = o.pile_reference_dt;
    res.reference_b.name = "reference_b";
    res.reference_b.dt = o.pile_reference_dt;
    res.methods.resize(setup.methods.size());
    for (std::size_t i = 0; i < setup.methods.size(); ++i) {
      res.methods[i].name = setup.methods[i].name;
      res.methods[i].dt = o.dt;
    }
    for (std::size_t job = 0; job < all.size(); ++job) {
      const std::size_t sample = job % samples;
      SceneSample& s = sample == 0 ? res.reference : sample == 1 ? res.reference_b : res.methods[sample - 2];
      s.runs.push_back(all[job].run);
      if (!all[job].states.empty()) {
        const std::string file = o.scene_frames + "/" + kind + "_" + (sample == 0 ? std::string("reference") : s.name) +
                                 ".csv";
        if (sample != 1) write_scene_frames(file, setup, all[job]);
      }
    }
    summarise(res.reference, res.metrics, nullptr, o.bootstrap);
    summarise(res.reference_b, res.metrics, &res.reference.runs, o.bootstrap);
    for (SceneSample& s : res.methods) summarise(s, res.metrics, &res.reference.runs, o.bootstrap);
    results.push_back(std::move(res));
  }
  return results;
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
  res.shape = options.mesh.empty() ? options.shape : options.mesh;
  if (!options.mix.empty()) res.shape += " and " + options.mix + " (mixed, half and half)";
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
  MethodSpec pile_ref = ref;
  pile_ref.gather_reference = false;
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
          return run_single(*setup, m, mix(options.seed, index), dt, options.time_limit);
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
          const double dt = sample < 2 ? options.pile_reference_dt : options.dt;
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
