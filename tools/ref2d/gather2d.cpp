// `statsim gather2d`: see gather2d.hpp.
#include "ref2d/gather2d.hpp"
#include "ref2d/pairs2d.hpp"
#include "common/commands.hpp"

#include "common/atomic_file.hpp"
#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "common/rest_families.hpp"
#include "common/table_writer.hpp"
#include "ref2d/box2d_util.hpp"
#include "ref2d/compare2d.hpp"

#include "common/support_map.hpp"
#include "statsim/detail/hull.hpp"
#include "statsim/detail/shape_setup.hpp"
#include "statsim/detail/response.hpp"
#include "statsim/statistical.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>

namespace statsim::tools {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGravity = 9.81;
// Experiments: the first word of each trial's seed.
constexpr std::uint64_t kHeightTable = 1;
constexpr std::uint64_t kResponseTable = 2;
constexpr std::uint64_t kRestPoses = 3;
// Box2D's skins: contact is reported (and resolved) once the cores are within 2 * 0.01 m.
constexpr double kSkin = 2.0 * static_cast<double>(b2_polygonRadius);

std::string fmt(const char* format, double x)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x == 0.0 ? 0.0 : x);
  return buf;
}

std::string g6(double x)
{
  return fmt("%.6g", x);
}

// A table array: 6 values a line, one level deeper than the entries.
std::string hex_array(const std::vector<double>& values)
{
  return hex_float_array(values, ArrayStyle{6, 8, false});
}

double angle_between(Point2 a, Point2 b)
{
  return std::atan2(std::fabs(a.x * b.y - a.y * b.x), a.x * b.x + a.y * b.y) * 180.0 / kPi;
}

Point2 normalized(Point2 p)
{
  const double n = std::hypot(p.x, p.y);
  return {p.x / n, p.y / n};
}

// Mean and sample standard deviation, two-pass.
void mean_std(const std::vector<double>& xs, double& mean, double& std)
{
  mean = 0.0;
  for (double x : xs) {
    mean += x;
  }
  mean /= static_cast<double>(xs.size());
  double ss = 0.0;
  for (double x : xs) {
    ss += (x - mean) * (x - mean);
  }
  std = xs.size() > 1 ? std::sqrt(ss / static_cast<double>(xs.size() - 1)) : 0.0;
}

// ---- the experiments ---------------------------------------------------------------------------

struct Context {
  Shape2 shape;
  std::vector<b2PolygonShape> pieces;
  std::vector<Point2> verts;  // core vertices as Box2D stores them, about the centre of mass
  double length = 0.0;        // L = bounding radius
  Surface surface;
  statsim::Material material;
  float threshold = 1.0f;
};

Context make_context(const Gather2dOptions& o)
{
  Context c;
  c.shape = gather2d_shape(o);
  c.pieces = box2d_pieces(c.shape);
  c.length = c.shape.bounding_radius;
  c.surface.friction = static_cast<float>(o.friction);
  c.surface.restitution = static_cast<float>(o.restitution);
  c.surface.restitution_threshold = b2FixtureDef().restitutionThreshold;
  c.surface.density = 1.0f;
  c.threshold = c.surface.restitution_threshold;
  c.material.restitution = static_cast<statsim::Scalar>(o.restitution);
  c.material.friction = static_cast<statsim::Scalar>(o.friction);
  // Verts exactly as Box2D stores them, relative to its centre of mass.
  b2World world(b2Vec2(0.0f, 0.0f));
  b2BodyDef def;
  def.type = b2_dynamicBody;
  c.verts = core_vertices(create_body(world, def, c.pieces, c.surface));
  return c;
}

// Box2D limits a body's rotation to b2_maxRotation (pi/2) per step: keep below 0.4 rad.
double step_for_spin(double dt, double max_spin)
{
  return max_spin > 0.0 ? std::min(dt, 0.4 / max_spin) : dt;
}

struct ResponseTrial {
  double out[3] = {0.0, 0.0, 0.0};
  int steps = 0;
  char time_limited = 0;
};

// One response trial (paper 3.2.2) in the canonical frame: ground y = 0 with normal +y, V- =
// |V-| (sin theta, -cos theta) (non-negative x), spin w = s |V-| / L (counter-clockwise positive,
// as in the runtime's 2D frame). No gravity. Box2D steps until the collision is over:
//  - separated: no touching contact, moving up, and the exact free flight (box2d_util's
//    first_contact_time) does not bring the core within the skin of the ground again before the
//    centre is clear of it (looked at up to 1 s ahead); or
//  - sliding: velocities unchanged for 16 steps and not approaching (slow grazing contacts end
//    like this without gravity: no normal force, so no friction);
//  - else the time limit after the first contact (counted; a body rocking on a corner without
//    gravity can take long), whose final velocities are used.
// Output: W+ L / |V-|, (V_rigid+ - V_particle+) / |V-| with V_particle+ from the runtime's
// statsim::point_particle_velocity<2> on Box2D's float V- (same material and threshold).
ResponseTrial simulate_response(const Context& ctx, double cos_theta, double spin_ratio, double speed, double dt,
                                double time_limit, std::mt19937_64& rng)
{
  const Shape2& shape = ctx.shape;
  const double angle = 2.0 * kPi * uniform01(rng);
  const double phase = uniform01(rng);
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  const double vn = speed * cos_theta;
  const double vx = speed * sin_theta;
  const double w = spin_ratio * speed / ctx.length;
  // The paper's protocol: random orientation at a fixed height (clear of Box2D's skin and its
  // fat-AABB margin), plus a random fraction of one step's travel so that contacts fall anywhere
  // within a step. The first contact is whatever the approaching, turning body touches first.
  const double height = shape.bounding_radius + 0.03 + phase * vn * dt;
  const double t_estimate = (height - 0.5 * (shape.bounding_radius + shape.inradius_min)) / vn;

  b2World world(b2Vec2(0.0f, 0.0f));
  world.SetAllowSleeping(false);
  create_ground(world, ctx.surface, 100.0f);
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position.Set(static_cast<float>(-vx * t_estimate), static_cast<float>(height));
  def.angle = static_cast<float>(angle);
  def.linearVelocity.Set(static_cast<float>(vx), static_cast<float>(-vn));
  def.angularVelocity = static_cast<float>(w);
  def.allowSleep = false;
  b2Body* body = create_body(world, def, ctx.pieces, ctx.surface);

  const b2Vec2 v0 = body->GetLinearVelocity();
  const float h = static_cast<float>(dt);
  const int free_steps = static_cast<int>(std::ceil((2.0 * t_estimate + 1.0) / dt));
  const int contact_steps = static_cast<int>(std::ceil(time_limit / dt));
  const double still = 1e-6 * speed;
  ResponseTrial trial;
  int first_contact = -1;
  int quiet = 0;
  for (int step = 0;; ++step) {
    if (first_contact < 0 && step >= free_steps) {
      throw std::runtime_error("gather2d: Box2D never reported the body touching the ground");
    }
    if (first_contact >= 0 && step - first_contact >= contact_steps) {
      trial.time_limited = 1;
      break;
    }
    const b2Vec2 pv = body->GetLinearVelocity();
    const float pw = body->GetAngularVelocity();
    world.Step(h, 8, 3);
    trial.steps = step + 1;
    const bool touching = touching_anything(body);
    if (first_contact < 0) {
      if (!touching) {
        continue;
      }
      first_contact = step;
    }
    const b2Vec2 v = body->GetLinearVelocity();
    const float wv = body->GetAngularVelocity();
    const bool changed = std::hypot(static_cast<double>(v.x) - pv.x, static_cast<double>(v.y) - pv.y) > still ||
                         std::fabs(static_cast<double>(wv) - pw) * ctx.length > still;
    quiet = changed ? 0 : quiet + 1;
    if (!touching && v.y > 0.0f) {
      // Free flight from here: separated for good if the core never comes within the skin of the
      // ground again, checked exactly until the centre is clear of it (at most 1 s ahead).
      const FreeState s = read_state(body);
      const double clear = (shape.bounding_radius + kSkin + 0.01 - s.cy) / s.vy;
      const double horizon = std::min(1.0, std::max(0.0, clear));
      if (!first_contact_time(s, ctx.verts, horizon, kSkin + 0.005)) {
        break;
      }
    }
    // Sliding along the ground with nothing more happening (slow grazing contacts without
    // gravity end this way: no normal force, so no friction).
    if (quiet >= 16 && static_cast<double>(v.y) >= -still) {
      break;
    }
  }

  const b2Vec2 v1 = body->GetLinearVelocity();
  const float w1 = body->GetAngularVelocity();
  const statsim::Vector2 vminus(v0.x, v0.y);
  const statsim::Vector2 vp = statsim::point_particle_velocity<2>(vminus, statsim::Vector2(0.0f, 1.0f), ctx.material,
                                                                 ctx.threshold);
  const double s = static_cast<double>(vminus.norm());
  trial.out[0] = static_cast<double>(w1) * ctx.length / s;
  trial.out[1] = (static_cast<double>(v1.x) - static_cast<double>(vp.x())) / s;
  trial.out[2] = (static_cast<double>(v1.y) - static_cast<double>(vp.y())) / s;
  return trial;
}

struct RestTrial {
  Point2 up;
  char settled = 0;
};

RestTrial simulate_rest(const Context& ctx, const Gather2dOptions& o, std::mt19937_64& rng)
{
  const double angle = 2.0 * kPi * uniform01(rng);
  const double height = ctx.shape.bounding_radius + 0.05 + 1.5 * uniform01(rng);
  const double vx = 2.0 * uniform01(rng) - 1.0;
  const double vy = 2.0 * uniform01(rng) - 1.0;
  const double w = (2.0 * uniform01(rng) - 1.0) * 2.0 * kPi;

  b2World world(b2Vec2(0.0f, static_cast<float>(-kGravity)));
  world.SetAllowSleeping(true);
  create_ground(world, ctx.surface, 1000.0f);
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position.Set(0.0f, static_cast<float>(height));
  def.angle = static_cast<float>(angle);
  def.linearVelocity.Set(static_cast<float>(vx), static_cast<float>(vy));
  def.angularVelocity = static_cast<float>(w);
  b2Body* body = create_body(world, def, ctx.pieces, ctx.surface);
  const int max_steps = static_cast<int>(std::ceil(o.rest_time_limit / o.rest_dt));
  const float h = static_cast<float>(o.rest_dt);
  RestTrial t;
  for (int step = 0; step < max_steps && body->IsAwake(); ++step) {
    world.Step(h, 8, 3);
  }
  t.settled = body->IsAwake() ? 0 : 1;
  const double a = body->GetAngle();
  t.up = {std::sin(a), std::cos(a)};  // R^T (0, 1)
  return t;
}

void cluster_rest_poses(Gather2dResult& r)
{
  const Gather2dOptions& o = r.options;
  struct Acc {
    Point2 sum;
    std::vector<std::size_t> members;
  };
  std::vector<Acc> acc;
  for (std::size_t i = 0; i < r.rest_ups.size(); ++i) {
    if (!r.rest_settled[i]) {
      continue;
    }
    const Point2 u = r.rest_ups[i];
    std::size_t best = acc.size();
    double best_angle = o.cluster_degrees;
    for (std::size_t k = 0; k < acc.size(); ++k) {
      const double a = angle_between(u, normalized(acc[k].sum));
      if (a <= best_angle) {
        best_angle = a;
        best = k;
      }
    }
    if (best == acc.size()) {
      acc.push_back({{0.0, 0.0}, {}});
    }
    acc[best].sum.x += u.x;
    acc[best].sum.y += u.y;
    acc[best].members.push_back(i);
  }
  // Up vectors of the faces of the convex hull: a polygon at rest lies on a hull edge.
  std::vector<Point2> faces;
  const std::vector<Point2>& hull = r.shape.hull;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Point2 a = hull[i], b = hull[(i + 1) % hull.size()];
    faces.push_back(normalized({-(b.y - a.y), b.x - a.x}));  // minus the outward normal
  }
  // The invariants of resting on hull edge f under the shape's symmetries (common/rest_families.hpp),
  // lengths in units of L: the rest height, the edge's length, how far the centroid's foot is
  // from the edge's middle, and the sorted heights of every hull vertex above the ground.
  const double L = r.shape.bounding_radius;
  const auto descriptor = [&](std::size_t f) {
    const Point2 up = faces[f], a = hull[f], b = hull[(f + 1) % hull.size()];
    const double h = r.shape.support_height(up);
    const Point2 along = {up.y, -up.x};
    const double mid = 0.5 * ((a.x + b.x) * along.x + (a.y + b.y) * along.y);
    std::vector<double> heights;
    for (const Point2& v : hull) heights.push_back((v.x * up.x + v.y * up.y + h) / L);
    std::sort(heights.begin(), heights.end());
    std::vector<double> d = {h / L, std::hypot(b.x - a.x, b.y - a.y) / L, std::fabs(mid) / L,
                             static_cast<double>(hull.size())};
    d.insert(d.end(), heights.begin(), heights.end());
    return d;
  };
  r.clusters.clear();
  std::vector<int> face_of;
  const double total = static_cast<double>(r.rest_ups.size());
  for (const Acc& a : acc) {
    RestCluster c;
    const Point2 mean = normalized(a.sum);
    c.normal = mean;
    c.count = static_cast<int>(a.members.size());
    c.frequency = static_cast<double>(c.count) / total;
    for (std::size_t m : a.members) {
      c.spread_degrees = std::max(c.spread_degrees, angle_between(r.rest_ups[m], mean));
    }
    // Snap to the nearest hull face within 3 degrees: Box2D leaves a resting body tilted by its
    // solver tolerances only, and the exact face gives the exact rest height.
    double best = 3.0;
    int face = -1;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const double d = angle_between(mean, faces[f]);
      if (d <= best) {
        best = d;
        c.normal = faces[f];
        c.snap_degrees = d;
        face = static_cast<int>(f);
      }
    }
    c.height = r.shape.support_height(c.normal);
    r.clusters.push_back(c);
    face_of.push_back(face);
  }
  std::vector<std::size_t> order(r.clusters.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto by_count = [&](std::size_t i, std::size_t j) {
    const RestCluster& a = r.clusters[i];
    const RestCluster& b = r.clusters[j];
    if (a.count != b.count) {
      return a.count > b.count;
    }
    return std::atan2(a.normal.x, a.normal.y) < std::atan2(b.normal.x, b.normal.y);
  };
  std::stable_sort(order.begin(), order.end(), by_count);
  std::vector<RestCandidate> candidates;
  for (std::size_t i : order) {
    RestCandidate k;
    k.frequency = r.clusters[i].frequency;
    k.count = r.clusters[i].count;
    if (face_of[i] >= 0) {
      k.descriptor = descriptor(static_cast<std::size_t>(face_of[i]));
    }
    candidates.push_back(k);
  }
  RestSelectionOptions so;
  so.min_frequency = o.min_frequency;
  so.max_dropped = o.max_dropped;
  const RestSelection sel = select_rest_poses(candidates, so);
  std::vector<RestCluster> sorted;
  for (std::size_t k = 0; k < order.size(); ++k) {
    RestCluster c = r.clusters[order[k]];
    c.kept = sel.kept[k] != 0;
    c.family = sel.family[k];
    c.family_frequency = sel.family_frequency[static_cast<std::size_t>(c.family)];
    sorted.push_back(c);
  }
  // Kept ones first, each part still most frequent first.
  std::stable_partition(sorted.begin(), sorted.end(), [](const RestCluster& c) { return c.kept; });
  r.clusters = sorted;
  r.rest_dropped = sel.dropped;
}

// fn(i) for every trial i < n on the options' worker threads, in order of i, with a progress
// line `label`.
template <class Fn>
auto run_trials(const char* label, std::size_t n, const Gather2dOptions& o, Fn&& fn)
{
  Progress progress(label, n, o.progress);
  auto trials = parallel_map(
      n,
      [&](std::size_t i) {
        auto t = fn(i);
        progress.add();
        return t;
      },
      o.threads);
  progress.finish();
  return trials;
}

void rest_experiment(const Context& ctx, Gather2dResult& r)
{
  const Gather2dOptions& o = r.options;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n = static_cast<std::size_t>(o.rest_drops);
  const std::vector<RestTrial> trials = run_trials("gather2d rest poses", n, o, [&](std::size_t i) {
    std::mt19937_64 rng = trial_rng(o.seed, kRestPoses, 0, i);
    return simulate_rest(ctx, o, rng);
  });
  r.rest_drops = static_cast<int>(n);
  r.rest_ups.clear();
  r.rest_settled.clear();
  r.rest_time_limited = 0;
  for (const RestTrial& t : trials) {
    r.rest_ups.push_back(t.up);
    r.rest_settled.push_back(t.settled);
    r.rest_time_limited += t.settled ? 0 : 1;
  }
  cluster_rest_poses(r);
  r.seconds_rest = seconds_since(start);
}

void warm_up_box2d(const Context& ctx)
{
  // Box2D 2.4.1 fills its contact-function table lazily on first use (b2Contact::Create): do that
  // on one thread before any worker starts.
  measure_first_contact(ctx.pieces, ctx.shape.bounding_radius + 0.1, 0.0, 1.0, 0.0, 1.0 / 60.0);
}

// A result with what every run records (the options, the shape, L and the restitution threshold),
// and Box2D ready for worker threads.
Gather2dResult start_result(const Gather2dOptions& options, const Context& ctx)
{
  Gather2dResult r;
  r.options = options;
  r.shape = ctx.shape;
  r.length = ctx.length;
  r.restitution_threshold = ctx.threshold;
  warm_up_box2d(ctx);
  return r;
}

}  // namespace

std::vector<double> default_height_ratios()
{
  // Below s ~ 1 the body turns by less than ~0.3 rad while crossing its height band (bounding
  // radius to inradius), so the heights barely change; beyond, the mean climbs slowly toward L.
  return {0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 13.0, 17.0, 23.0, 32.0};
}
std::vector<double> default_cos_thetas()
{
  return {0.15, 0.3, 0.5, 0.7, 0.85, 0.95, 1.0};
}
std::vector<double> default_signed_spins()
{
  return {-6.0, -3.0, -1.5, -0.5, 0.0, 0.5, 1.5, 3.0, 6.0};
}
std::vector<double> default_speeds()
{
  return {0.5, 1.5, 3.0, 5.0, 9.0};
}

Shape2 gather2d_shape(const Gather2dOptions& o)
{
  if (o.shape == "square") {
    return square_shape();
  }
  if (o.shape == "lshape") {
    return lshape_shape();
  }
  if (o.shape == "polygon") {
    const std::vector<Point2> v = parse_polygon(o.polygon);
    return make_shape(v, "polygon", "polygon " + format_polygon(v) + " (as given; centred on its centroid)");
  }
  throw std::invalid_argument("unknown shape '" + o.shape + "' (square, lshape or polygon)");
}

void validate_gather2d_options(const Gather2dOptions& o)
{
  const auto bad = [](const std::string& m) { throw std::invalid_argument(m); };
  if (!cpp_identifier(o.name)) {
    bad("the table name '" + o.name + "' is not a C++ identifier (use --name)");
  }
  if (!(o.restitution >= 0.0 && o.restitution <= 1.0)) {
    bad("--restitution must be in [0, 1]");
  }
  if (!(o.friction >= 0.0 && std::isfinite(o.friction))) {
    bad("--friction must be >= 0");
  }
  if (o.height_trials < 2 || o.trials < 2) {
    bad("need at least 2 trials per table entry (for a standard deviation)");
  }
  if (o.rest_drops < 20) {
    bad("--rest-drops must be at least 20");
  }
  if (!(o.min_frequency >= 0.0 && o.min_frequency < 1.0)) {
    bad("--rest-min-frequency must be in [0, 1)");
  }
  if (!(o.max_dropped >= 0.0 && o.max_dropped <= 1.0)) {
    bad("--rest-max-dropped must be in [0, 1]");
  }
  if (o.body_contacts) {
    if (o.support_size < 2 || o.support_size > static_cast<int>(statsim::max_support_size)) {
      bad("--support-size must be in [2, " + std::to_string(statsim::max_support_size) + "]");
    }
    if (o.contact_faces < 0 || o.contact_faces > static_cast<int>(statsim::max_contact_faces)) {
      bad("--contact-faces must be in [0, " + std::to_string(statsim::max_contact_faces) + "]");
    }
    if (o.pair_trials < 2) {
      bad("--pair-trials must be at least 2");
    }
    if (o.packing_piles < 0 || o.packing_count < 2 || o.packing_steps < 1) {
      bad("--packing-piles must be >= 0, --packing-count >= 2 and --packing-steps >= 1");
    }
  }
  const auto increasing = [&](const std::vector<double>& a, const char* what, double lo, double hi) {
    if (a.empty()) {
      bad(std::string(what) + ": need at least one value");
    }
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (!std::isfinite(a[i]) || a[i] < lo || a[i] > hi || (i > 0 && !(a[i] > a[i - 1]))) {
        bad(std::string(what) + ": values must be strictly increasing within [" + g6(lo) + ", " + g6(hi) + "]");
      }
    }
  };
  increasing(o.height_ratios, "height spin ratios", 0.0, 1e3);
  increasing(o.cos_thetas, "cos(theta) axis", 0.05, 1.0);
  increasing(o.signed_spins, "signed spin axis", -1e3, 1e3);
  increasing(o.speeds, "speed axis", 0.05, 100.0);
  if (!(o.height_speed > 0.0) || !(o.response_dt > 0.0) || !(o.rest_dt > 0.0) || !(o.response_time_limit > 0.0) ||
      !(o.rest_time_limit > 0.0)) {
    bad("speeds, time steps and time limits must be positive");
  }
  if (o.speeds.back() * o.response_dt >= 1.0) {
    bad("the largest speed moves too far per Box2D step (b2_maxTranslation is 2 m)");
  }
  (void)gather2d_shape(o);  // a bad polygon throws here
}

Gather2dResult run_rest_poses(const Gather2dOptions& options)
{
  validate_gather2d_options(options);
  const Context ctx = make_context(options);
  Gather2dResult r = start_result(options, ctx);
  rest_experiment(ctx, r);
  return r;
}

namespace {

// d / (the runtime's contact distance along the line of centres) of a touching pile pair: the
// least candidate distance that `find_hull_witness` finds on the table's own data, packing 1;
// with the candidate it found.
PackingSample packing_sample(const statsim::Shape<2>& shape, const Pile2dContact& c)
{
  statsim::Body<2> a{}, b{};
  a.orientation = statsim::Rot2::from_angle(static_cast<statsim::Scalar>(c.angle_a));
  b.orientation = statsim::Rot2::from_angle(static_cast<statsim::Scalar>(c.angle_b));
  const Eigen::Vector2d ab = c.cb - c.ca;
  const statsim::Vector2 e = ab.normalized().cast<statsim::Scalar>();
  // Distance 0 is below any positive reach, so the search always names its best candidate.
  std::uint32_t k = statsim::detail::find_hull_witness(shape, a, shape, b, e, statsim::Scalar(0), statsim::Scalar(1));
  if (k == statsim::detail::no_witness) k = 0;
  const statsim::detail::HullCandidate<2> h = statsim::detail::hull_candidate(shape, a, shape, b, e, k);
  PackingSample p;
  p.ratio = ab.norm() / (static_cast<double>(h.reach) / static_cast<double>(h.normal.dot(e)));
  p.up = ab.y() / ab.norm();
  p.witness = k;
  return p;
}

// 4. Body-body data (statsim::ContactView): pair distance, support map, hull edges, packing.
void body_contacts_experiment(const Context& ctx, Gather2dResult& r)
{
  const Gather2dOptions& o = r.options;
  const Shape2& sh = ctx.shape;
  BodyContactData& c = r.contact;
  c.dims = 2;
  // The body frame is the input's frame moved to its centroid, unrotated: R = I, c = offset.
  c.mesh_frame = {1, 0, 0, 1, sh.offset.x, sh.offset.y};

  const auto t0 = std::chrono::steady_clock::now();
  const PairDistances2d pd = pair_distances2d(sh, o.height_ratios, o.pair_trials, o.height_speed, o.seed, o.threads);
  c.pair_mean = pd.mean;
  c.pair_std = pd.std;
  c.pair_flights = pd.flights;
  c.pair_seconds = seconds_since(t0);

  std::vector<Eigen::Vector2d> hull;
  for (const Point2& p : sh.hull) hull.emplace_back(p.x, p.y);
  const SupportMap2 map = SupportMap2::build(hull, o.support_size);
  c.support_size = o.support_size;
  c.support = map.values;
  c.support_bound = map.error_bound(hull);
  // Hull edges (counter-clockwise), longest first; equal lengths in the hull's order.
  std::vector<std::pair<double, Eigen::Vector3d>> edges;
  for (std::size_t k = 0; k < hull.size(); ++k) {
    const Eigen::Vector2d d = hull[(k + 1) % hull.size()] - hull[k];
    const Eigen::Vector2d n = Eigen::Vector2d(d.y(), -d.x()).normalized();
    edges.emplace_back(d.norm(), Eigen::Vector3d(n.x(), n.y(), support(hull, n)));
  }
  std::stable_sort(edges.begin(), edges.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  c.hull_faces = static_cast<int>(edges.size());
  const std::size_t k = std::min(edges.size(), static_cast<std::size_t>(o.contact_faces));
  // The packing ratio of each edge (its last number) is measured below; 1 until then.
  for (std::size_t i = 0; i < k; ++i)
    c.faces.insert(c.faces.end(), {edges[i].second.x(), edges[i].second.y(), edges[i].second.z(), 1.0});

  // The table's own body-body data, as the runtime reads it from the header being written.
  std::vector<float> support, faces;
  for (double v : c.support) support.push_back(static_cast<float>(v) + 0.0f);
  for (double v : c.faces) faces.push_back(static_cast<float>(v) + 0.0f);
  statsim::SignatureView<2> view{};
  view.contact.support_size = static_cast<std::uint32_t>(c.support_size);
  view.contact.support = statsim::ValuesView{support.data(), nullptr, 1, 0};
  view.contact.faces = faces.empty() ? nullptr : faces.data();
  view.contact.face_count = static_cast<std::uint32_t>(k);
  statsim::Shape<2> shape{};
  shape.statistical = true;
  shape.signature = view;
  shape.support_floor = statsim::detail::support_bounds(view.contact).floor;

  // Packing: the piles of `statsim compare2d` with this table's material.
  const auto t1 = std::chrono::steady_clock::now();
  statsim::SignatureView<2> material{};
  material.material = ctx.material;
  material.restitution_threshold = ctx.threshold;
  c.piles = o.packing_piles;
  std::vector<std::vector<Pile2dContact>> piles(static_cast<std::size_t>(c.piles));
  std::vector<char> asleep(piles.size(), 0);
  parallel_for(
      piles.size(),
      [&](std::size_t i) {
        bool all = false;
        piles[i] = box2d_pile_contacts(sh, material, o.packing_count, o.packing_steps, i + 1, all);
        asleep[i] = all ? 1 : 0;
      },
      o.threads);
  std::vector<PackingSample> samples;
  for (std::size_t i = 0; i < piles.size(); ++i) {
    c.asleep += asleep[i];
    c.pile_steps += o.packing_steps;
    for (const Pile2dContact& pc : piles[i]) {
      samples.push_back(packing_sample(shape, pc));
    }
  }
  packing_statistics(samples, c);
  c.packing_seconds = seconds_since(t1);
}

}  // namespace

Gather2dResult run_gather2d(const Gather2dOptions& options)
{
  validate_gather2d_options(options);
  const Gather2dOptions& o = options;
  const Context ctx = make_context(o);
  Gather2dResult r = start_result(o, ctx);

  // 1. Height table.
  {
    const auto start = std::chrono::steady_clock::now();
    const double max_spin = o.height_ratios.back() * o.height_speed / ctx.length;
    r.height_dt = step_for_spin(1.0 / 60.0, max_spin);
    const std::size_t nr = o.height_ratios.size();
    const std::size_t per = static_cast<std::size_t>(o.height_trials);
    const std::vector<FirstContact> trials = run_trials("gather2d heights", nr * per, o, [&](std::size_t flat) {
      const std::size_t i = flat / per, k = flat % per;
      std::mt19937_64 rng = trial_rng(o.seed, kHeightTable, i, k);
      const double angle = 2.0 * kPi * uniform01(rng);
      const double sign = (rng() >> 63) != 0 ? 1.0 : -1.0;
      const double spin = sign * o.height_ratios[i] * o.height_speed / ctx.length;
      // Start clear of the skin and the fat-AABB margin, at a random phase of one step.
      const double height = ctx.shape.bounding_radius + 0.1 + uniform01(rng) * o.height_speed * r.height_dt;
      return measure_first_contact(ctx.pieces, height, angle, o.height_speed, spin, r.height_dt);
    });
    for (std::size_t i = 0; i < nr; ++i) {
      HeightRow row;
      row.ratio = o.height_ratios[i];
      std::vector<double> hs;
      for (std::size_t k = 0; k < per; ++k) {
        const FirstContact& t = trials[i * per + k];
        hs.push_back(t.height);
        row.late += t.late ? 1 : 0;
        row.missed += t.missed ? 1 : 0;
      }
      mean_std(hs, row.mean, row.std);
      row.min = *std::min_element(hs.begin(), hs.end());
      row.max = *std::max_element(hs.begin(), hs.end());
      row.trials = static_cast<int>(per);
      r.heights.push_back(row);
    }
    r.seconds_heights = seconds_since(start);
  }

  // 2. Response tables.
  {
    const auto start = std::chrono::steady_clock::now();
    double max_abs_spin = 0.0;
    for (double s : o.signed_spins) {
      max_abs_spin = std::max(max_abs_spin, std::fabs(s));
    }
    r.response_dt = step_for_spin(o.response_dt, max_abs_spin * o.speeds.back() / ctx.length);
    const std::size_t a0 = o.cos_thetas.size(), a1 = o.signed_spins.size(), a2 = o.speeds.size();
    const std::size_t cells = a0 * a1 * a2;
    const std::size_t per = static_cast<std::size_t>(o.trials);
    const std::vector<ResponseTrial> trials = run_trials("gather2d responses", cells * per, o, [&](std::size_t flat) {
      const std::size_t cell = flat / per, k = flat % per;
      const std::size_t i = cell / (a1 * a2), j = (cell / a2) % a1, l = cell % a2;
      std::mt19937_64 rng = trial_rng(o.seed, kResponseTable, cell, k);
      return simulate_response(ctx, o.cos_thetas[i], o.signed_spins[j], o.speeds[l], r.response_dt,
                               o.response_time_limit, rng);
    });
    for (std::size_t cell = 0; cell < cells; ++cell) {
      ResponseCell c;
      c.cos_theta = o.cos_thetas[cell / (a1 * a2)];
      c.spin = o.signed_spins[(cell / a2) % a1];
      c.speed = o.speeds[cell % a2];
      c.trials = static_cast<int>(per);
      double steps = 0.0;
      for (int comp = 0; comp < 3; ++comp) {
        std::vector<double> xs;
        for (std::size_t k = 0; k < per; ++k) {
          xs.push_back(trials[cell * per + k].out[comp]);
        }
        mean_std(xs, c.mean[static_cast<std::size_t>(comp)], c.std[static_cast<std::size_t>(comp)]);
      }
      for (std::size_t k = 0; k < per; ++k) {
        c.time_limited += trials[cell * per + k].time_limited;
        steps += trials[cell * per + k].steps;
      }
      c.mean_steps = steps / static_cast<double>(per);
      r.response_trials += c.trials;
      r.response_time_limited += c.time_limited;
      r.cells.push_back(c);
    }
    r.seconds_responses = seconds_since(start);
  }

  // 3. Rest poses.
  rest_experiment(ctx, r);

  // 4. Body-body data.
  if (o.body_contacts) body_contacts_experiment(ctx, r);
  return r;
}

std::string shell_quote(const std::string& s)
{
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./,+=:") ==
                        std::string::npos) {
    return s;
  }
  std::string q = "'";
  for (char c : s) {
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return q + "'";
}

std::string gather2d_header(const Gather2dResult& r, const std::string& command)
{
  const Gather2dOptions& o = r.options;
  const Shape2& sh = r.shape;
  std::vector<RestCluster> kept;
  for (const RestCluster& c : r.clusters) {
    if (c.kept) {
      kept.push_back(c);
    }
  }
  int late = 0, missed = 0;
  for (const HeightRow& h : r.heights) {
    late += h.late;
    missed += h.missed;
  }
  const auto dt_text = [](double dt) {
    const double inv = 1.0 / dt;
    return std::fabs(inv - std::round(inv)) < 1e-9 * inv ? "1/" + fmt("%.0f", inv) : g6(dt);
  };
  std::string s = table_banner("gather2d", command, o.target);
  s += "// seed " + std::to_string(o.seed) + "; reference: Box2D " + std::to_string(b2_version.major) + "." +
       std::to_string(b2_version.minor) + " (Debian libbox2d 2.4.1: polygon skin b2_polygonRadius = " +
       g6(static_cast<double>(b2_polygonRadius)) + " m, b2_linearSlop = " + g6(static_cast<double>(b2_linearSlop)) +
       " m)\n";
  s += "// shape: " + sh.description + "\n";
  s += "//   body frame (centroid at the origin), counter-clockwise: " + format_polygon(sh.outline) + "\n";
  s += "//   " + std::to_string(sh.pieces.size()) + " convex Box2D fixture(s); area " + g6(sh.area) +
       " m^2, density 1 kg/m^2, mass " + g6(sh.area) + " kg, polar inertia / mass " + g6(sh.polar_inertia / sh.area) +
       " m^2; bounding radius = L = " + g6(sh.bounding_radius) + " m\n";
  s += "// material: restitution " + g6(o.restitution) + ", friction " + g6(o.friction) +
       " on the body and on the ground (Box2D mixes restitution as max(a, b) and friction as sqrt(a b),\n"
       "//   so contacts use exactly these); restitution only above " +
       g6(static_cast<double>(r.restitution_threshold)) +
       " m/s of approach (b2FixtureDef::restitutionThreshold, recorded as\n"
       "//   restitution_threshold); rolling_resistance is the runtime's default (Box2D polygons do not roll)\n";
  s += "// height table (paper 3.2.1): " + std::to_string(r.heights.size()) + " spin ratios s = |w| L / |v| x " +
       std::to_string(o.height_trials) + " drops, |v| = " + g6(o.height_speed) + " m/s straight down, dt " +
       dt_text(r.height_dt) + " s, random orientation, spin sign and step phase;\n"
       "//   centre height at the first contact of the core shape, refined exactly (Box2D skin removed; Box2D noticed " +
       std::to_string(late) + " contacts\n//   a step late and missed " + std::to_string(missed) +
       ", covered by the refinement)\n";
  s += "// response tables (paper 3.2.2): " + std::to_string(o.cos_thetas.size()) + " cos(theta) x " +
       std::to_string(o.signed_spins.size()) + " signed spin ratios x " + std::to_string(o.speeds.size()) + " speeds = " +
       std::to_string(r.cells.size()) + " cells x " + std::to_string(o.trials) + " trials = " +
       std::to_string(r.response_trials) + " trials;\n"
       "//   no gravity, dt " + dt_text(r.response_dt) +
       " s, 8 velocity / 3 position iterations, random orientation at a fixed height, until separated;\n"
       "//   " + std::to_string(r.response_time_limited) + " trials had not separated " + g6(o.response_time_limit) +
       " s after first contact (time limit; their final velocities are used)\n";
  s += "// rest poses (paper 3.2.3): " + std::to_string(r.rest_drops) + " drops with gravity " + g6(kGravity) +
       " m/s^2, dt " + dt_text(o.rest_dt) + " s, until Box2D put the body to sleep; " +
       std::to_string(r.rest_time_limited) + " were still awake after " + g6(o.rest_time_limit) +
       " s;\n//   greedy clustering of body-frame up vectors at " + g6(o.cluster_degrees) +
       " degrees, snapped to hull faces within 3 degrees; kept: families (poses equivalent under the shape's "
       "symmetry) of frequency > " + g6(o.min_frequency) + ", then rarer ones while more than " + g6(o.max_dropped) +
       " of the settled drops is dropped; h_rest on the core shape\n";
  for (std::size_t i = 0; i < r.clusters.size(); ++i) {
    const RestCluster& c = r.clusters[i];
    s += "//   " + std::string(c.kept ? "pose " + std::to_string(i) : "(not kept)") + ": up (" + fmt("%.6f", c.normal.x) +
         ", " + fmt("%.6f", c.normal.y) + ") h_rest " + fmt("%.6f", c.height) + " m, " + std::to_string(c.count) +
         " drops, frequency " + fmt("%.4f", c.frequency) + ", family " + std::to_string(c.family) + "\n";
  }
  s += "//   dropped: " + fmt("%.4f", r.rest_dropped) + " of the settled drops\n";
  const BodyContactData& bc = r.contact;
  if (o.body_contacts) {
    s += "// body-body data: support map S = " + std::to_string(bc.support_size) + " (" +
         std::to_string(4 * bc.support_size) + " values; at most " + fmt("%.3g", bc.support_bound) +
         " m above the hull's support), " + std::to_string(bc.face_count()) + " of the hull's " +
         std::to_string(bc.hull_faces) + " edges, mesh frame: the input's frame at the centroid\n";
    s += "//   pair distance: " + std::to_string(bc.pair_flights) + " pair flights (" + std::to_string(o.pair_trials) +
         " per height-table spin ratio, head-on at " + g6(o.height_speed) + " m/s relative speed, exact outlines)\n";
    s += "//   packing: " + std::to_string(bc.piles) + " Box2D piles of " + std::to_string(o.packing_count) +
         " bodies (statsim compare2d's, seeds 1..), " + std::to_string(o.packing_steps) + " steps of 1/60 s; " +
         std::to_string(bc.asleep) + " of " + std::to_string(bc.piles) + " all asleep; " +
         std::to_string(bc.total_pairs) + " touching pairs\n";
    s += "//   packing d / the runtime's hull distance (find_hull_witness on this table, ratio 1):" + packing_line(bc) +
         "\n";
  }
  s += table_prologue(o.name, o.body_contacts ? 1 : 0, o.target);
  s += "// Signature<D, height samples, response axes (cos theta, signed spin ratio, speed, unused), rest poses,\n"
       "//           spread values per cell (the paper's model: one standard deviation per component)>\n";
  s += table_definition("Signature<2, " + std::to_string(r.heights.size()) + ", " + std::to_string(o.cos_thetas.size()) +
                            ", " + std::to_string(o.signed_spins.size()) + ", " + std::to_string(o.speeds.size()) +
                            ", 1, " + std::to_string(kept.size()) + ", 3" +
                            (o.body_contacts ? ", " + contact_type(bc, false) : std::string()) + ">",
                        o.name, o.target);
  statsim::Material defaults;
  const auto array = [&s](const std::string& comment, const std::vector<double>& values) {
    s += table_comment(comment) + table_entry(hex_array(values));
  };
  s += table_entry("\"" + o.name + "\"");
  s += table_entry(hex_float(r.length), "length L (bounding radius), m");
  s += table_entry(hex_float(sh.bounding_radius), "bounding_radius, m");
  s += table_entry(hex_float(sh.area), "mass, kg");
  s += table_entry("{{" + hex_floats({sh.polar_inertia / sh.area, 0.0, 0.0}) + "}}",
                   "unit_inertia (polar moment / mass), m^2");
  s += table_entry("{" + hex_floats({o.restitution, o.friction, static_cast<double>(defaults.rolling_resistance)}) + "}",
                   "material: restitution, friction, rolling");
  s += table_entry(hex_float(static_cast<double>(r.restitution_threshold)), "restitution_threshold, m/s");
  s += table_entry("ResponseLayout::with_speed");
  s += table_entry("ResponseModel::independent_gaussian");
  s += table_entry("3", "axis_count");
  std::vector<double> hm, hsd;
  for (const HeightRow& h : r.heights) {
    hm.push_back(h.mean);
    hsd.push_back(h.std);
  }
  array("height_axis: spin ratio |w| L / |v|", o.height_ratios);
  array("height_mean, m", hm);
  array("height_stddev, m", hsd);
  array("axis0: cos(theta)", o.cos_thetas);
  array("axis1: signed spin ratio", o.signed_spins);
  array("axis2: speed |V-|, m/s", o.speeds);
  array("axis3: unused", {0.0});
  std::vector<double> rm, rs;
  for (const ResponseCell& c : r.cells) {
    for (int k = 0; k < 3; ++k) {
      rm.push_back(c.mean[static_cast<std::size_t>(k)]);
      rs.push_back(c.std[static_cast<std::size_t>(k)]);
    }
  }
  array("response_mean: per cell (cos theta slowest, then spin, then speed) w+ L/|V-|, dv_x/|V-|, dv_y/|V-|", rm);
  array("response_spread: per cell the standard deviation of each component", rs);
  std::vector<double> rn, rh, rf;
  for (const RestCluster& c : kept) {
    rn.push_back(c.normal.x);
    rn.push_back(c.normal.y);
    rh.push_back(c.height);
    rf.push_back(c.frequency);
  }
  array("rest_normals: body-frame up vectors", rn);
  array("rest_heights, m", rh);
  array("rest_frequencies", rf);
  if (o.body_contacts) s += contact_entries(bc, false);
  return s + table_epilogue(o.target);
}

std::string gather2d_json(const Gather2dResult& r, const std::string& command)
{
  nlohmann::ordered_json j;
  j["command"] = command;
  j["name"] = r.options.name;
  j["seed"] = r.options.seed;
  j["length"] = r.length;
  j["area"] = r.shape.area;
  j["seconds"] = {{"heights", r.seconds_heights}, {"responses", r.seconds_responses}, {"rest", r.seconds_rest}};
  j["heights"] = nlohmann::ordered_json::array();
  for (const HeightRow& h : r.heights)
    j["heights"].push_back({{"ratio", h.ratio}, {"mean", h.mean}, {"std", h.std}, {"min", h.min}, {"max", h.max},
                            {"trials", h.trials}, {"late", h.late}, {"missed", h.missed}});
  if (r.options.body_contacts) {
    const BodyContactData& c = r.contact;
    j["mesh_frame"] = c.mesh_frame;
    j["body_contacts"] = {{"pair_mean", c.pair_mean},
                          {"pair_stddev", c.pair_std},
                          {"pair_flights", c.pair_flights},
                          {"support_size", c.support_size},
                          {"support", c.support},
                          {"support_bound", c.support_bound},
                          {"faces", c.faces},
                          {"hull_faces", c.hull_faces},
                          {"packing_bins_deg", {0, 30, 60, 90}},
                          {"packing_mean", c.packing_mean},
                          {"packing_stddev", c.packing_std},
                          {"packing_pairs", c.packing_pairs},
                          {"packing_pooled", c.packing_pooled},
                          {"piles", c.piles},
                          {"pile_bodies", r.options.packing_count},
                          {"piles_asleep", c.asleep},
                          {"seconds", {{"pairs", c.pair_seconds}, {"packing", c.packing_seconds}}}};
  }
  j["response_trials"] = r.response_trials;
  j["response_time_limited"] = r.response_time_limited;
  j["cells"] = nlohmann::ordered_json::array();
  for (const ResponseCell& c : r.cells)
    j["cells"].push_back({{"cos_theta", c.cos_theta},
                          {"spin", c.spin},
                          {"speed", c.speed},
                          {"mean", {c.mean[0], c.mean[1], c.mean[2]}},
                          {"std", {c.std[0], c.std[1], c.std[2]}},
                          {"time_limited", c.time_limited},
                          {"mean_steps", c.mean_steps}});
  j["rest_drops"] = r.rest_drops;
  j["rest_time_limited"] = r.rest_time_limited;
  j["rest_clusters"] = nlohmann::ordered_json::array();
  for (const RestCluster& c : r.clusters)
    j["rest_clusters"].push_back({{"normal", {c.normal.x, c.normal.y}},
                                  {"height", c.height},
                                  {"frequency", c.frequency},
                                  {"count", c.count},
                                  {"spread_degrees", c.spread_degrees},
                                  {"snap_degrees", c.snap_degrees},
                                  {"kept", c.kept},
                                  {"family", c.family},
                                  {"family_frequency", c.family_frequency}});
  j["rest_dropped"] = r.rest_dropped;
  return j.dump(2) + "\n";
}

std::string gather2d_summary(const Gather2dResult& r)
{
  std::string s = "gather2d " + r.options.name + ": " + r.shape.description + "\n";
  s += "  L = " + g6(r.length) + " m, area " + g6(r.shape.area) + " m^2, " + std::to_string(r.shape.pieces.size()) +
       " convex piece(s)\n";
  s += "  height table (" + fmt("%.1f", r.seconds_heights) + " s):\n    s      mean      std       min       max\n";
  for (const HeightRow& h : r.heights) {
    s += "    " + fmt("%-5g", h.ratio) + "  " + fmt("%.5f", h.mean) + "  " + fmt("%.5f", h.std) + "  " +
         fmt("%.5f", h.min) + "  " + fmt("%.5f", h.max) + "\n";
  }
  // Response: a digest over cells.
  double max_abs_mean[3] = {0, 0, 0}, mean_std[3] = {0, 0, 0};
  for (const ResponseCell& c : r.cells) {
    for (int k = 0; k < 3; ++k) {
      max_abs_mean[k] = std::max(max_abs_mean[k], std::fabs(c.mean[static_cast<std::size_t>(k)]));
      mean_std[k] += c.std[static_cast<std::size_t>(k)] / static_cast<double>(r.cells.size());
    }
  }
  s += "  response tables (" + fmt("%.1f", r.seconds_responses) + " s): " + std::to_string(r.cells.size()) +
       " cells, " + std::to_string(r.response_trials) + " trials, " + std::to_string(r.response_time_limited) +
       " hit the time limit\n";
  s += "    max |mean| (w L/|V|, dv_x/|V|, dv_y/|V|) = (" + fmt("%.3f", max_abs_mean[0]) + ", " +
       fmt("%.3f", max_abs_mean[1]) + ", " + fmt("%.3f", max_abs_mean[2]) + "), average std = (" +
       fmt("%.3f", mean_std[0]) + ", " + fmt("%.3f", mean_std[1]) + ", " + fmt("%.3f", mean_std[2]) + ")\n";
  s += "  rest poses (" + fmt("%.1f", r.seconds_rest) + " s): " + std::to_string(r.rest_drops) + " drops, " +
       std::to_string(r.rest_time_limited) + " still awake at the time limit\n";
  for (const RestCluster& c : r.clusters) {
    s += std::string("    ") + (c.kept ? "kept " : "     ") + " up (" + fmt("%+.4f", c.normal.x) + ", " +
         fmt("%+.4f", c.normal.y) + ")  h_rest " + fmt("%.5f", c.height) + " m  frequency " +
         fmt("%.3f", c.frequency) + "  (" + std::to_string(c.count) + " drops, spread " +
         fmt("%.2f", c.spread_degrees) + " deg" +
         (c.snap_degrees >= 0 ? ", snapped " + fmt("%.3f", c.snap_degrees) + " deg" : std::string(", not snapped")) +
         ", family " + std::to_string(c.family) + ")\n";
  }
  s += "    dropped: " + fmt("%.3f", r.rest_dropped) + " of the settled drops\n";
  if (r.options.body_contacts) {
    const BodyContactData& c = r.contact;
    s += "  body-body: pair distance " + fmt("%.5f", c.pair_mean.front()) + " m at s = 0 (" +
         std::to_string(c.pair_flights) + " flights, " + fmt("%.1f", c.pair_seconds) + " s); packing" +
         packing_line(c) + " (" + std::to_string(c.piles) + " piles, " + fmt("%.1f", c.packing_seconds) + " s)\n";
  }
  return s;
}

// ---- the command ---------------------------------------------------------------------------------

namespace {

struct Gather2dCommand {
  Gather2dOptions options;
  std::string out;
  std::string json;
  std::string name;
  std::string name_space = "statsim::tables";
  std::vector<std::pair<std::string, CLI::Option*>> recorded;  // options written into the command line
  bool no_body_contacts = false;
  CLI::Option* shape_opt = nullptr;
  CLI::Option* polygon_opt = nullptr;
};

// --out is written as the target records paths (a table of this repository as given, any other
// as its file name).
std::string recorded_command(const Gather2dCommand& cmd, const TableTarget& target)
{
  std::string s = target.program() + " gather2d";
  for (const auto& [flag, opt] : cmd.recorded) {
    if (opt->count() == 0) {
      continue;
    }
    if (opt->get_expected_max() == 0) {  // a flag
      s += " " + flag;
      continue;
    }
    for (const std::string& value : opt->results()) {
      s += " " + flag + " " + shell_quote(flag == "--out" ? target.path(value) : value);
    }
  }
  return s;
}

void run_gather2d_command(Gather2dCommand& cmd)
{
  try {
    Gather2dOptions& o = cmd.options;
    o.progress = true;
    const bool has_shape = cmd.shape_opt->count() > 0;
    const bool has_polygon = cmd.polygon_opt->count() > 0;
    if (has_shape == has_polygon) {
      throw std::invalid_argument("give exactly one of --shape square|lshape and --polygon \"x1,y1 x2,y2 ...\"");
    }
    if (has_polygon) {
      o.shape = "polygon";
    }
    const std::filesystem::path out(cmd.out);
    o.name = cmd.name.empty() ? out.stem().string() : cmd.name;
    o.body_contacts = !cmd.no_body_contacts;
    o.target = table_target(cmd.out, cmd.name_space);
    validate_gather2d_options(o);  // fail before a long run
    const std::filesystem::path dir = out.parent_path().empty() ? std::filesystem::path(".") : out.parent_path();
    if (!std::filesystem::is_directory(dir)) {
      throw std::invalid_argument("the directory of --out, '" + dir.string() + "', does not exist");
    }
    const std::string command = recorded_command(cmd, o.target);
    const auto start = std::chrono::steady_clock::now();
    const Gather2dResult r = run_gather2d(o);
    const std::string header = gather2d_header(r, command);
    write_file_atomic(out, header);
    if (!cmd.json.empty()) {
      write_file_atomic(cmd.json, gather2d_json(r, command));
    }
    std::fputs(gather2d_summary(r).c_str(), stdout);
    const double seconds = seconds_since(start);
    std::printf("wrote %s (%zu bytes) in %.1f s\n", out.c_str(), header.size(), seconds);
    std::fflush(stdout);
  } catch (const std::exception& e) {
    std::string message = e.what();
    std::fprintf(stderr, "statsim gather2d: error: %s\n", message.c_str());
    throw CLI::RuntimeError(1);
  }
}

}  // namespace

void register_gather2d_commands(CLI::App& app)
{
  auto cmd = std::make_shared<Gather2dCommand>();
  Gather2dOptions& o = cmd->options;
  CLI::App* g = app.add_subcommand(
      "gather2d",
      "Gather the statistical signature of a 2D shape with Box2D (collision heights, response tables, rest "
      "poses) into a C++ header tables/NAME2d.hpp");
  cmd->shape_opt = g->add_option("--shape", o.shape, "square (1 x 1 m) or lshape (1 m arms, 0.25 m thick)")
                       ->check(CLI::IsMember({"square", "lshape"}));
  cmd->polygon_opt = g->add_option("--polygon", o.polygon,
                                   "A simple polygon \"x1,y1 x2,y2 ...\" in metres (concave allowed; either orientation)");
  CLI::Option* out = g->add_option("--out", cmd->out, "Output header, e.g. tables/square2d.hpp")->required();
  CLI::Option* name = g->add_option("--name", cmd->name, "C++ name of the table (default: the file name's stem)");
  CLI::Option* name_space =
      g->add_option("--namespace", cmd->name_space, "C++ namespace of the table")->capture_default_str();
  CLI::Option* seed = g->add_option("--seed", o.seed, "Random seed")->capture_default_str();
  CLI::Option* trials =
      g->add_option("--trials", o.trials, "Trials per response cell")->capture_default_str()->check(CLI::Range(2, 100000));
  CLI::Option* height_trials = g->add_option("--height-trials", o.height_trials, "Drops per height-table spin ratio")
                                   ->capture_default_str()
                                   ->check(CLI::Range(2, 1000000));
  CLI::Option* rest = g->add_option("--rest-drops", o.rest_drops, "Drops for the rest poses")
                          ->capture_default_str()
                          ->check(CLI::Range(20, 10000000));
  CLI::Option* restitution = g->add_option("--restitution", o.restitution, "Restitution of body and ground")
                                 ->capture_default_str()
                                 ->check(CLI::Range(0.0, 1.0));
  CLI::Option* friction = g->add_option("--friction", o.friction, "Friction of body and ground")
                              ->capture_default_str()
                              ->check(CLI::Range(0.0, 10.0));
  CLI::Option* min_frequency =
      g->add_option("--rest-min-frequency", o.min_frequency,
                    "Rest poses: keep every pose of a family (poses equivalent under the shape's symmetry) seen in "
                    "more than this fraction of the drops together, in [0, 1)")
          ->capture_default_str();
  CLI::Option* max_dropped =
      g->add_option("--rest-max-dropped", o.max_dropped,
                    "Rest poses: then keep rarer families, most frequent first, while more than this fraction of the "
                    "settled drops is in poses not kept, in [0, 1] (1: never)")
          ->capture_default_str();
  CLI::Option* no_contacts = g->add_flag("--no-body-contacts", cmd->no_body_contacts,
                                         "Leave out the body-body data (a table of format 2.0, as written before it existed)");
  CLI::Option* support_size = g->add_option("--support-size", o.support_size, "Body-body: support map nodes a side, S")
                                  ->capture_default_str();
  CLI::Option* contact_faces =
      g->add_option("--contact-faces", o.contact_faces, "Body-body: longest hull edges stored")->capture_default_str();
  CLI::Option* pair_trials =
      g->add_option("--pair-trials", o.pair_trials, "Body-body: pair flights per height-table spin ratio")
          ->capture_default_str();
  CLI::Option* packing_piles =
      g->add_option("--packing-piles", o.packing_piles, "Body-body: Box2D piles for the packing ratios")
          ->capture_default_str();
  CLI::Option* packing_count =
      g->add_option("--packing-count", o.packing_count, "Body-body: bodies per pile")->capture_default_str();
  CLI::Option* packing_steps =
      g->add_option("--packing-steps", o.packing_steps, "Body-body: steps of 1/60 s per pile")->capture_default_str();
  g->add_option("--threads", o.threads, "Worker threads (0 = all); the output does not depend on it")
      ->capture_default_str();
  g->add_option("--json", cmd->json, "Also write a JSON summary (statistics, counts, timings) to this file");
  cmd->recorded = {{"--shape", cmd->shape_opt},
                   {"--polygon", cmd->polygon_opt},
                   {"--out", out},
                   {"--name", name},
                   {"--namespace", name_space},
                   {"--seed", seed},
                   {"--trials", trials},
                   {"--height-trials", height_trials},
                   {"--rest-drops", rest},
                   {"--restitution", restitution},
                   {"--friction", friction},
                   {"--rest-min-frequency", min_frequency},
                   {"--rest-max-dropped", max_dropped},
                   {"--no-body-contacts", no_contacts},
                   {"--support-size", support_size},
                   {"--contact-faces", contact_faces},
                   {"--pair-trials", pair_trials},
                   {"--packing-piles", packing_piles},
                   {"--packing-count", packing_count},
                   {"--packing-steps", packing_steps}};
  g->callback([cmd]() { run_gather2d_command(*cmd); });

  register_compare2d_command(app);
  register_pairs2d_command(app);
}

}  // namespace statsim::tools
