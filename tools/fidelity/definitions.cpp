// What `statsim fidelity` measures, in words and numbers: the pile scenes' metrics, the summary
// error and its goals, the definitions written into --help and the JSON.
#include "fidelity/fidelity.hpp"

#include <cmath>

namespace statsim::tools::fidelity {

namespace {

// Goals of summary_error.
constexpr double kGoalTvd = 0.10, kGoalHeight = 0.02, kGoalTravel = 0.20, kGoalBounce = 0.20, kGoalKs = 0.20;

}  // namespace

std::vector<SceneMetric> scene_metrics(const std::string& kind)
{
  if (kind == "heap") return {{"angle_deg", "deg", false}, {"height", "m", true}};
  if (kind == "bin") return {{"fill_height", "m", true}, {"packing", "", true}};
  return {{"held", "", false}, {"overlap", "mm", false}};
}

double goal_tolerance(const SceneMetric& metric)
{
  const std::string& n = metric.name;
  if (n == "angle_deg") return 3.0;
  if (n == "height") return 0.10;
  if (n == "fill_height" || n == "packing") return 0.05;
  if (n == "held") return 0.02;
  return 0.0;
}

PileSummary pile_summary(const std::vector<SceneResult>& scenes, std::size_t m)
{
  PileSummary s;
  double terms = 0, runs = 0;
  for (const SceneResult& sc : scenes) {
    if (m >= sc.methods.size() || (sc.kind != "heap" && sc.kind != "bin")) continue;
    const SceneSample& x = sc.methods[m];
    for (std::size_t k = 0; k < sc.metrics.size() && k < x.distances.size(); ++k) {
      const double tol = goal_tolerance(sc.metrics[k]);
      if (tol <= 0) continue;
      s.pile_error += std::fabs(x.distances[k].value) / tol;
      terms += 1;
    }
    for (const SceneRun& r : x.runs) s.step_ms += r.step_ms, runs += 1;
  }
  if (terms > 0) s.pile_error /= terms;
  if (runs > 0) s.step_ms /= runs;
  return s;
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

}  // namespace statsim::tools::fidelity
