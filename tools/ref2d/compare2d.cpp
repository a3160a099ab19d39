// `statsim compare2d`: see compare2d.hpp.
#include "ref2d/compare2d.hpp"

#include "common/format.hpp"
#include "common/sample_stats.hpp"
#include "common/pi.hpp"

#include "common/atomic_file.hpp"
#include "common/progress.hpp"
#include "ref2d/box2d_util.hpp"
#include "scenes/frames.hpp"

#include "statsim/world2.hpp"

#include "tables/lshape2d.hpp"
#include "tables/square2d.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace statsim::tools {
namespace {

constexpr int kMaxBodies = 2048;
using StatWorld = statsim::World2<kMaxBodies>;

std::optional<statsim::SignatureView<2>> signature_for(const std::string& shape)
{
  if (shape == "square") return statsim::tables::square2d.view();
  if (shape == "lshape") return statsim::tables::lshape2d.view();
  return std::nullopt;
}

Shape2 shape_for(const std::string& shape)
{
  if (shape == "square") {
    return square_shape();
  }
  if (shape == "lshape") {
    return lshape_shape();
  }
  throw std::invalid_argument("unknown shape '" + shape + "' (square or lshape)");
}

double median(std::vector<double> v)
{
  if (v.empty()) {
    return 0.0;
  }
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// Fills the statistics of a method from its final states.
void analyse(MethodResult& m, const Shape2& shape, const statsim::SignatureView<2>& sig, int falling_steps,
             int active_steps)
{
  const std::size_t n = m.final.size();
  m.median_ms = median(m.step_ms);
  m.mean_ms = 0.0;
  for (double t : m.step_ms) {
    m.mean_ms += t / static_cast<double>(m.step_ms.size());
  }
  m.falling_median_ms = median(std::vector<double>(m.step_ms.begin(), m.step_ms.begin() + falling_steps));
  m.active_mean_ms = 0.0;
  for (int i = 0; i < active_steps; ++i) {
    m.active_mean_ms += m.step_ms[static_cast<std::size_t>(i)] / active_steps;
  }
  m.histogram.assign(sig.rest.count + 1, 0.0);
  m.pile_height = -std::numeric_limits<double>::infinity();
  m.lowest = std::numeric_limits<double>::infinity();
  m.mean_x = 0.0;
  m.max_speed = 0.0;
  m.kinetic_energy = 0.0;
  for (const Body2State& b : m.final) {
    const double c = std::cos(b.angle), s = std::sin(b.angle);
    const double ux = s, uy = c;  // body-frame up vector R^T (0, 1)
    std::size_t best = sig.rest.count;
    double best_angle = 15.0;
    for (std::uint32_t k = 0; k < sig.rest.count; ++k) {
      const double nx = static_cast<double>(sig.rest.normals[2 * k]), ny = static_cast<double>(sig.rest.normals[2 * k + 1]);
      const double a = std::atan2(std::fabs(ux * ny - uy * nx), ux * nx + uy * ny) * 180.0 / kPi;
      if (a <= best_angle) {
        best_angle = a;
        best = k;
      }
    }
    m.histogram[best] += 1.0 / static_cast<double>(n);
    for (const Point2& p : shape.outline) {
      const double y = b.y + s * p.x + c * p.y;
      m.pile_height = std::max(m.pile_height, y);
      m.lowest = std::min(m.lowest, y);
    }
    m.mean_x += b.x / static_cast<double>(n);
    const double speed = std::hypot(b.vx, b.vy);
    m.max_speed = std::max(m.max_speed, speed);
    m.kinetic_energy += 0.5 * shape.area * (speed * speed + shape.polar_inertia / shape.area * b.w * b.w);
  }
  m.mad_x = 0.0;
  for (const Body2State& b : m.final) {
    m.mad_x += std::fabs(b.x - m.mean_x) / static_cast<double>(n);
  }
  std::vector<double> nearest;
  for (std::size_t i = 0; i < n; ++i) {
    double d2 = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i) {
        d2 = std::min(d2, (m.final[i].x - m.final[j].x) * (m.final[i].x - m.final[j].x) +
                              (m.final[i].y - m.final[j].y) * (m.final[i].y - m.final[j].y));
      }
    }
    if (n > 1) {
      nearest.push_back(std::sqrt(d2));
    }
  }
  m.neighbour_median = nearest.empty() ? 0.0 : median(nearest);
}

// Whole steps between two history samples (0: no history).
int history_steps(const Compare2dOptions& o)
{
  return o.history_every > 0.0 ? std::max(1, static_cast<int>(std::lround(o.history_every / o.dt))) : 0;
}

MethodResult run_box2d_once(const Compare2dOptions& o, const Shape2& shape, const statsim::SignatureView<2>& sig,
                            const std::vector<Body2State>& init)
{
  MethodResult m;
  m.method = "box2d";
  b2World world(b2Vec2(0.0f, -9.81f));
  world.SetAllowSleeping(true);
  const std::vector<b2Body*> bodies = add_box2d_pile(world, shape, sig, init);
  const float h = static_cast<float>(o.dt);
  const int every = history_steps(o);
  for (int step = 0; step < o.steps; ++step) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int sub = 0; sub < o.box2d_substeps; ++sub) world.Step(h / static_cast<float>(o.box2d_substeps), 8, 3);
    const auto t1 = std::chrono::steady_clock::now();
    m.step_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    int awake = 0;
    for (b2Body* b : bodies) {
      awake += b->IsAwake() ? 1 : 0;
    }
    if (m.first_sleep_step < 0 && awake < static_cast<int>(bodies.size())) {
      m.first_sleep_step = step;
    }
    if (awake == 0 && m.all_asleep_step < 0) {
      m.all_asleep_step = step;
    } else if (awake > 0) {
      m.all_asleep_step = -1;
    }
    if (every > 0 && (step + 1) % every == 0) {
      double highest = -std::numeric_limits<double>::infinity();
      for (b2Body* b : bodies) {
        highest = std::max(highest, static_cast<double>(b->GetPosition().y));
      }
      m.history.push_back({(step + 1) * o.dt, highest, static_cast<double>(awake)});
    }
  }
  for (b2Body* b : bodies) {
    const b2Vec2 p = b->GetPosition();
    const b2Vec2 v = b->GetLinearVelocity();
    m.final.push_back({p.x, p.y, b->GetAngle(), v.x, v.y, b->GetAngularVelocity()});
    m.asleep += b->IsAwake() ? 0 : 1;
    m.final_asleep.push_back(b->IsAwake() ? 0 : 1);
  }
  return m;
}

MethodResult run_statsim_once(const Compare2dOptions& o, const statsim::SignatureView<2>& sig,
                              const std::vector<Body2State>& init)
{
  MethodResult m;
  m.method = "statsim";
  statsim::WorldDef2 def;
  def.restitution_threshold = sig.restitution_threshold;  // as Box2D's (1 m/s)
  def.pile_rest = o.pile_rest;
  def.sleep_islands = o.sleep_islands;  // the default, hull contacts where the table has body-body data, kept
  def.ground_hulls = o.ground_hulls;
  auto world = std::make_unique<StatWorld>(def);
  if (world->construction_status() != statsim::Status::ok) {
    throw std::runtime_error("statsim world rejected its parameters");
  }
  const auto shape = world->add_shape(sig);
  if (shape.status != statsim::Status::ok) {
    throw std::runtime_error("statsim rejected the signature " + std::string(sig.name));
  }
  if (!world->add_plane(statsim::Vector2(0.0f, 1.0f), 0.0f).ok()) {
    throw std::runtime_error("statsim rejected the ground plane");
  }
  for (const Body2State& s : init) {
    statsim::BodyDef2 b;
    b.position = statsim::Vector2(static_cast<float>(s.x), static_cast<float>(s.y));
    b.orientation = statsim::Rot2::from_angle(static_cast<float>(s.angle));
    b.linear_velocity = statsim::Vector2(static_cast<float>(s.vx), static_cast<float>(s.vy));
    b.angular_velocity = static_cast<float>(s.w);
    b.shape = shape.id;
    b.mass = sig.mass;
    if (world->add_body(b).status != statsim::Status::ok) {
      throw std::runtime_error("statsim rejected a body");
    }
  }
  const float h = static_cast<float>(o.dt);
  const int every = history_steps(o);
  for (int step = 0; step < o.steps; ++step) {
    const auto t0 = std::chrono::steady_clock::now();
    const statsim::StepResult r = world->step(h);
    const auto t1 = std::chrono::steady_clock::now();
    if (r.status != statsim::Status::ok) {
      throw std::runtime_error("statsim step failed");
    }
    m.step_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    const std::uint32_t asleep = world->count(statsim::MotionState::asleep);
    if (m.first_sleep_step < 0 && asleep > 0) {
      m.first_sleep_step = step;
    }
    if (asleep == world->body_count() && m.all_asleep_step < 0) {
      m.all_asleep_step = step;
    } else if (asleep < world->body_count()) {
      m.all_asleep_step = -1;
    }
    if (every > 0 && (step + 1) % every == 0) {
      double highest = -std::numeric_limits<double>::infinity();
      for (std::uint32_t i = 0; i < world->body_count(); ++i) {
        highest = std::max(highest, static_cast<double>(world->body(i).position.y()));
      }
      m.history.push_back({(step + 1) * o.dt, highest, static_cast<double>(world->body_count() - asleep)});
    }
  }
  for (std::uint32_t i = 0; i < world->body_count(); ++i) {
    const statsim::Body2& b = world->body(i);
    m.final.push_back({b.position.x(), b.position.y(), b.orientation.angle(), b.linear_velocity.x(),
                       b.linear_velocity.y(), b.angular_velocity});
    m.asleep += b.state == statsim::MotionState::asleep ? 1 : 0;
    m.final_asleep.push_back(b.state == statsim::MotionState::asleep ? 1 : 0);
  }
  return m;
}

// Runs a simulation `repeat` times from the same initial states: every run must end in the same
// final states (both engines are deterministic), and each step's time is the least over the runs,
// which removes most of the noise of a shared machine.
template <class Run>
MethodResult repeated(int repeat, Run run)
{
  MethodResult best = run();
  for (int k = 1; k < repeat; ++k) {
    const MethodResult m = run();
    for (std::size_t i = 0; i < best.final.size(); ++i) {
      const Body2State& a = best.final[i];
      const Body2State& b = m.final[i];
      if (a.x != b.x || a.y != b.y || a.angle != b.angle) {
        throw std::runtime_error(best.method + " did not repeat itself from the same initial states");
      }
    }
    for (std::size_t i = 0; i < best.step_ms.size(); ++i) {
      best.step_ms[i] = std::min(best.step_ms[i], m.step_ms[i]);
    }
  }
  return best;
}

}  // namespace

std::vector<b2Body*> add_box2d_pile(b2World& world, const Shape2& shape, const statsim::SignatureView<2>& sig,
                                    const std::vector<Body2State>& init)
{
  Surface surface;
  surface.friction = sig.material.friction;
  surface.restitution = sig.material.restitution;
  surface.restitution_threshold = sig.restitution_threshold;
  surface.density = 1.0f;
  create_ground(world, surface, 1000.0f);
  const std::vector<b2PolygonShape> pieces = box2d_pieces(shape);
  std::vector<b2Body*> bodies;
  for (const Body2State& s : init) {
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position.Set(static_cast<float>(s.x), static_cast<float>(s.y));
    def.angle = static_cast<float>(s.angle);
    def.linearVelocity.Set(static_cast<float>(s.vx), static_cast<float>(s.vy));
    def.angularVelocity = static_cast<float>(s.w);
    bodies.push_back(create_body(world, def, pieces, surface));
  }
  return bodies;
}

bool compare2d_has_table(const std::string& shape)
{
  return signature_for(shape).has_value();
}

std::vector<Body2State> compare2d_initial_states(const Compare2dOptions& o, double bounding_radius)
{
  // Random positions, not a grid: bodies dropped in aligned columns land exactly on top of each
  // other, which says more about the columns than about either simulation. The region is as wide
  // as a square grid of the bodies at 2R + 0.2 m spacing and twice as tall; each body takes the
  // first of up to 1000 random spots clear of the others' bounding circles by 0.05 m (the region
  // grows by a row when that fails).
  const int columns = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(o.n)))));
  const double spacing = 2.0 * bounding_radius + 0.2;
  const double width = columns * spacing;
  double height = 2.0 * std::ceil(static_cast<double>(o.n) / columns) * spacing;
  const double clear = 2.0 * bounding_radius + 0.05;
  std::vector<Body2State> out;
  for (int i = 0; i < o.n; ++i) {
    std::mt19937_64 rng = trial_rng(o.seed, 4, static_cast<std::uint64_t>(o.n), static_cast<std::uint64_t>(i));
    Body2State s;
    for (int attempt = 0;; ++attempt) {
      if (attempt > 0 && attempt % 1000 == 0) {
        height += spacing;
      }
      s.x = (uniform01(rng) - 0.5) * (width - spacing);
      s.y = bounding_radius + 0.5 + uniform01(rng) * height;
      bool free = true;
      for (const Body2State& t : out) {
        if (std::hypot(t.x - s.x, t.y - s.y) < clear) {
          free = false;
          break;
        }
      }
      if (free) {
        break;
      }
    }
    s.angle = 2.0 * kPi * uniform01(rng);
    s.vx = 2.0 * uniform01(rng) - 1.0;
    s.vy = -uniform01(rng);
    s.w = 4.0 * uniform01(rng) - 2.0;
    out.push_back(s);
  }
  return out;
}

namespace {

// Pools the per-drop results of one method (each already analysed): step figures are means over
// the drops, the histogram the mean of equal-sized drops (so the pooled histogram), the final
// states concatenated; the first drop's step times and sleep steps are kept for display.
MethodResult pool(const std::vector<MethodResult>& drops)
{
  MethodResult p = drops.front();
  const double k = static_cast<double>(drops.size());
  p.final.clear();
  p.final_asleep.clear();
  for (HistorySample& h : p.history) {
    h.highest = h.awake = 0.0;  // the times stay; every drop samples the same steps
  }
  p.asleep = 0;
  p.median_ms = p.mean_ms = p.falling_median_ms = p.active_mean_ms = 0.0;
  p.pile_height = p.mean_x = p.mad_x = p.kinetic_energy = p.max_speed = p.neighbour_median = 0.0;
  p.lowest = std::numeric_limits<double>::infinity();
  std::fill(p.histogram.begin(), p.histogram.end(), 0.0);
  for (const MethodResult& d : drops) {
    p.median_ms += d.median_ms / k;
    p.mean_ms += d.mean_ms / k;
    p.falling_median_ms += d.falling_median_ms / k;
    p.active_mean_ms += d.active_mean_ms / k;
    p.pile_height += d.pile_height / k;
    p.neighbour_median += d.neighbour_median / k;
    p.mean_x += d.mean_x / k;
    p.mad_x += d.mad_x / k;
    p.kinetic_energy += d.kinetic_energy / k;
    p.max_speed = std::max(p.max_speed, d.max_speed);
    p.lowest = std::min(p.lowest, d.lowest);
    p.asleep += d.asleep;
    p.final.insert(p.final.end(), d.final.begin(), d.final.end());
    p.final_asleep.insert(p.final_asleep.end(), d.final_asleep.begin(), d.final_asleep.end());
    for (std::size_t t = 0; t < p.history.size(); ++t) {
      p.history[t].highest += d.history[t].highest / k;
      p.history[t].awake += d.history[t].awake / k;
    }
    for (std::size_t c = 0; c < p.histogram.size(); ++c) {
      p.histogram[c] += d.histogram[c] / k;
    }
  }
  p.pile_height_sd = mean_std(drops.size(), [&](std::size_t i) { return drops[i].pile_height; }).std;
  return p;
}

double tvd(const std::vector<double>& a, const std::vector<double>& b)
{
  double t = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    t += 0.5 * std::fabs(a[k] - b[k]);
  }
  return t;
}

// 1-Wasserstein distance of two equal-sized samples of x: the mean gap of their order statistics.
double w1_x(const std::vector<Body2State>& a, const std::vector<Body2State>& b)
{
  std::vector<double> xa, xb;
  for (const Body2State& s : a) {
    xa.push_back(s.x);
  }
  for (const Body2State& s : b) {
    xb.push_back(s.x);
  }
  std::sort(xa.begin(), xa.end());
  std::sort(xb.begin(), xb.end());
  double w1 = 0.0;
  for (std::size_t i = 0; i < xa.size(); ++i) {
    w1 += std::fabs(xa[i] - xb[i]) / static_cast<double>(xa.size());
  }
  return w1;
}

}  // namespace

Compare2dResult run_compare2d(const Compare2dOptions& o)
{
  if (o.n < 1 || o.n > kMaxBodies) {
    throw std::invalid_argument("--n must be in 1.." + std::to_string(kMaxBodies));
  }
  if (o.steps < 1) {
    throw std::invalid_argument("--steps must be at least 1");
  }
  if (o.repeat < 1) {
    throw std::invalid_argument("--repeat must be at least 1");
  }
  if (o.drops < 1 || o.drops > 1000) {
    throw std::invalid_argument("--drops must be in 1..1000");
  }
  if (!(o.dt > 0.0 && o.dt <= 0.1)) {
    throw std::invalid_argument("--dt must be in (0, 0.1] s");
  }
  if (o.box2d_substeps < 1 || o.box2d_substeps > 64) {
    throw std::invalid_argument("--box2d-substeps must be in 1..64");
  }
  const Shape2 shape = shape_for(o.shape);
  const std::optional<statsim::SignatureView<2>> sig = signature_for(o.shape);
  if (!sig) {
    throw std::invalid_argument("no committed table for '" + o.shape + "'");
  }
  Compare2dResult r;
  r.options = o;
  r.table = sig->name;
  for (std::uint32_t k = 0; k < sig->rest.count; ++k) {
    r.categories.push_back("pose" + std::to_string(k) + " (" + fmt("%+.2f", static_cast<double>(sig->rest.normals[2 * k])) +
                           "," + fmt("%+.2f", static_cast<double>(sig->rest.normals[2 * k + 1])) + ")");
  }
  r.categories.push_back("other");
  std::vector<MethodResult> box2d, statsim_runs, box2d_b;
  double falling = 0.0, active = 0.0, tvd_single = 0.0;
  Progress progress("compare2d", static_cast<std::uint64_t>(2 * o.drops));
  for (int k = 0; k < o.drops; ++k) {
    Compare2dOptions ok = o;
    ok.seed = o.seed + static_cast<std::uint64_t>(k);
    const std::vector<Body2State> init = compare2d_initial_states(ok, shape.bounding_radius);
    MethodResult b = repeated(o.repeat, [&] { return run_box2d_once(o, shape, *sig, init); });
    MethodResult s = repeated(o.repeat, [&] { return run_statsim_once(o, *sig, init); });
    const int bs = b.first_sleep_step < 0 ? o.steps : b.first_sleep_step;
    const int ss = s.first_sleep_step < 0 ? o.steps : s.first_sleep_step;
    const int falling_steps = std::max(1, std::min(bs, ss));
    const int ba = b.all_asleep_step < 0 ? o.steps : b.all_asleep_step + 1;
    const int sa = s.all_asleep_step < 0 ? o.steps : s.all_asleep_step + 1;
    const int active_steps = std::max(ba, sa);
    analyse(b, shape, *sig, falling_steps, active_steps);
    analyse(s, shape, *sig, falling_steps, active_steps);
    falling += falling_steps / static_cast<double>(o.drops);
    active += active_steps / static_cast<double>(o.drops);
    tvd_single += tvd(s.histogram, b.histogram) / o.drops;
    box2d.push_back(std::move(b));
    statsim_runs.push_back(std::move(s));
    progress.add();
    // The second reference sample: the next `drops` seeds, timed once (its times are not shown).
    ok.seed = o.seed + static_cast<std::uint64_t>(o.drops + k);
    const std::vector<Body2State> init_b = compare2d_initial_states(ok, shape.bounding_radius);
    MethodResult bb = run_box2d_once(o, shape, *sig, init_b);
    const int bbs = bb.first_sleep_step < 0 ? o.steps : bb.first_sleep_step;
    const int bba = bb.all_asleep_step < 0 ? o.steps : bb.all_asleep_step + 1;
    analyse(bb, shape, *sig, std::max(1, bbs), bba);
    bb.method = "box2d_b";
    box2d_b.push_back(std::move(bb));
    progress.add();
  }
  progress.finish();
  r.falling_steps = static_cast<int>(std::lround(falling));
  r.active_steps = static_cast<int>(std::lround(active));
  r.box2d = pool(box2d);
  r.statsim = pool(statsim_runs);
  r.box2d_b = pool(box2d_b);
  // Distances from Box2D's pooled result: statsim's, and the noise floor of Box2D's second sample.
  for (MethodResult* m : {&r.statsim, &r.box2d_b}) {
    m->rest_tvd = tvd(m->histogram, r.box2d.histogram);
    const double w1 = w1_x(m->final, r.box2d.final);
    m->spread_w1 = r.box2d.mad_x > 0.0 ? w1 / r.box2d.mad_x : w1;
  }
  r.statsim.rest_tvd_single = tvd_single;
  double tvd_single_b = 0.0;
  for (int k = 0; k < o.drops; ++k) {
    tvd_single_b += tvd(box2d_b[static_cast<std::size_t>(k)].histogram, box2d[static_cast<std::size_t>(k)].histogram) / o.drops;
  }
  r.box2d_b.rest_tvd_single = tvd_single_b;
  return r;
}

std::string compare2d_table(const Compare2dResult& r)
{
  const Compare2dOptions& o = r.options;
  const MethodResult& b = r.box2d;
  const MethodResult& s = r.statsim;
  const MethodResult& bb = r.box2d_b;
  std::string t;
  t += "compare2d: " + std::to_string(o.n) + " x " + o.shape + " (table " + r.table + "), " + std::to_string(o.drops) +
       " drops (seeds " + std::to_string(o.seed) + ".." + std::to_string(o.seed + static_cast<std::uint64_t>(o.drops) - 1) +
       ") of " + std::to_string(o.steps) + " steps of " + fmt("%.5g", o.dt) +
       " s; step times: least of " + std::to_string(o.repeat) + " identical runs, mean over the drops" +
       (o.pile_rest ? "; statsim with pile_rest" : "") + (o.sleep_islands ? "" : "; statsim without sleep_islands") +
       (o.ground_hulls ? "; statsim with ground_hulls" : "") +
       (o.box2d_substeps > 1 ? "; Box2D in " + std::to_string(o.box2d_substeps) + " substeps per step" : "") + "\n";
  t += "box2d_b: Box2D on seeds " + std::to_string(o.seed + static_cast<std::uint64_t>(o.drops)) + ".." +
       std::to_string(o.seed + static_cast<std::uint64_t>(2 * o.drops) - 1) +
       ", a second sample of the reference: its distances are the noise floor\n";
  t += "                                    box2d      statsim      box2d_b\n";
  const auto row = [&](const std::string& label, const std::string& x, const std::string& y, const std::string& z) {
    char buf[240];
    std::snprintf(buf, sizeof buf, "  %-30s %11s  %11s  %11s\n", label.c_str(), x.c_str(), y.c_str(), z.c_str());
    t += buf;
  };
  row("step time, median (ms)", fmt("%.4f", b.median_ms), fmt("%.4f", s.median_ms), "");
  row("step time, mean (ms)", fmt("%.4f", b.mean_ms), fmt("%.4f", s.mean_ms), "");
  row("falling: ~" + std::to_string(r.falling_steps) + " steps, median", fmt("%.4f", b.falling_median_ms),
      fmt("%.4f", s.falling_median_ms), "");
  row("until all asleep: ~" + std::to_string(r.active_steps) + " steps, mean", fmt("%.4f", b.active_mean_ms),
      fmt("%.4f", s.active_mean_ms), "");
  row("first drop: first sleeper at step", std::to_string(b.first_sleep_step), std::to_string(s.first_sleep_step),
      std::to_string(bb.first_sleep_step));
  row("first drop: all asleep from step", std::to_string(b.all_asleep_step), std::to_string(s.all_asleep_step),
      std::to_string(bb.all_asleep_step));
  row("asleep at the end, all drops", std::to_string(b.asleep), std::to_string(s.asleep), std::to_string(bb.asleep));
  for (std::size_t k = 0; k < r.categories.size(); ++k) {
    row("rest " + r.categories[k], fmt("%.3f", b.histogram[k]), fmt("%.3f", s.histogram[k]), fmt("%.3f", bb.histogram[k]));
  }
  row("rest-orientation TVD, pooled", "0", fmt("%.3f", s.rest_tvd), fmt("%.3f", bb.rest_tvd));
  row("rest TVD per drop, mean", "0", fmt("%.3f", s.rest_tvd_single), fmt("%.3f", bb.rest_tvd_single));
  row("mean x (m)", fmt("%.3f", b.mean_x), fmt("%.3f", s.mean_x), fmt("%.3f", bb.mean_x));
  row("mean |x - mean| (m)", fmt("%.3f", b.mad_x), fmt("%.3f", s.mad_x), fmt("%.3f", bb.mad_x));
  row("spread W1 / box2d spread", "0", fmt("%.3f", s.spread_w1), fmt("%.3f", bb.spread_w1));
  row("pile height (m)", fmt("%.3f", b.pile_height), fmt("%.3f", s.pile_height), fmt("%.3f", bb.pile_height));
  row("pile height, sd over drops (m)", fmt("%.3f", b.pile_height_sd), fmt("%.3f", s.pile_height_sd),
      fmt("%.3f", bb.pile_height_sd));
  row("lowest point (m)", fmt("%.4f", b.lowest), fmt("%.4f", s.lowest), fmt("%.4f", bb.lowest));
  row("nearest neighbour, median (m)", fmt("%.3f", b.neighbour_median), fmt("%.3f", s.neighbour_median),
      fmt("%.3f", bb.neighbour_median));
  row("largest final speed (m/s)", fmt("%.4f", b.max_speed), fmt("%.4f", s.max_speed), fmt("%.4f", bb.max_speed));
  row("final kinetic energy (J)", fmt("%.4g", b.kinetic_energy), fmt("%.4g", s.kinetic_energy), fmt("%.4g", bb.kinetic_energy));
  const auto sample = [](const MethodResult& m, std::size_t k) {
    return k < m.history.size() ? fmt("%.2f", m.history[k].highest) + " (" + fmt("%.0f", m.history[k].awake) + ")" : "-";
  };
  for (std::size_t k = 0; k < b.history.size(); ++k) {
    row("highest centre at " + fmt("%g", b.history[k].time) + " s (m; awake)", sample(b, k), sample(s, k), sample(bb, k));
  }
  t += "  speed-up per step: " + fmt("%.1f", b.median_ms / std::max(s.median_ms, 1e-12)) + "x (median), " +
       fmt("%.1f", b.mean_ms / std::max(s.mean_ms, 1e-12)) + "x (mean), " +
       fmt("%.1f", b.falling_median_ms / std::max(s.falling_median_ms, 1e-12)) + "x while falling, " +
       fmt("%.1f", b.active_mean_ms / std::max(s.active_mean_ms, 1e-12)) + "x until all asleep\n";
  return t;
}

std::string compare2d_csv(const Compare2dResult& r)
{
  std::string s =
      "method,n,steps,step_ms,step_ms_mean,falling_ms,active_ms,rest_tvd,spread_w1,pile_height,asleep,drops,"
      "rest_tvd_single,neighbour_median,pile_height_sd\n";
  for (const MethodResult* m : {&r.box2d, &r.box2d_b, &r.statsim}) {
    s += m->method + "," + std::to_string(r.options.n) + "," + std::to_string(r.options.steps) + "," +
         fmt("%.6f", m->median_ms) + "," + fmt("%.6f", m->mean_ms) + "," + fmt("%.6f", m->falling_median_ms) + "," +
         fmt("%.6f", m->active_mean_ms) + "," + fmt("%.6f", m->rest_tvd) + "," + fmt("%.6f", m->spread_w1) + "," +
         fmt("%.6f", m->pile_height) + "," + std::to_string(m->asleep) + "," + std::to_string(r.options.drops) + "," +
         fmt("%.6f", m->rest_tvd_single) + "," + fmt("%.6f", m->neighbour_median) + "," +
         fmt("%.6f", m->pile_height_sd) + "\n";
  }
  return s;
}

void write_compare2d_frames(const Compare2dResult& r, const std::string& dir)
{
  std::filesystem::create_directories(dir);
  const auto n = static_cast<std::size_t>(r.options.n);
  const int step = r.options.steps - 1;
  const double time = r.options.steps * r.options.dt;
  const std::optional<statsim::SignatureView<2>> sig = signature_for(r.options.shape);
  // The radius column is the collision sphere's, which Box2D bodies do not have: the shape's
  // bounding radius stands in for both (`statsim render` draws spheres only when asked).
  const double radius = sig ? static_cast<double>(sig->bounding_radius) : 0.0;
  for (const MethodResult* m : {&r.box2d, &r.statsim}) {
    const std::string path = (std::filesystem::path(dir) / (m->method + ".csv")).string();
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (f == nullptr) throw std::runtime_error("cannot write " + path);
    scenes::write_frames_header(f);
    for (std::size_t i = 0; i < n && i < m->final.size(); ++i) {
      const Body2State& b = m->final[i];
      scenes::write_frame_row(f, step, time, static_cast<std::uint32_t>(i), r.table.c_str(), Eigen::Vector2d(b.x, b.y),
                              b.angle, m->final_asleep[i] ? 2 : 0, radius);
    }
    if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
  }
}

void register_compare2d_command(CLI::App& app)
{
  struct Command {
    Compare2dOptions options;
    std::string csv;
    std::string frames;
  };
  auto cmd = std::make_shared<Command>();
  CLI::App* c = app.add_subcommand(
      "compare2d",
      "Drop N bodies in Box2D (full polygons) and in statsim (statistical bodies from tables/NAME2d.hpp) from the "
      "same initial states; compare time per step, rest orientations, spread and pile height");
  c->add_option("--shape", cmd->options.shape, "square or lshape")
      ->check(CLI::IsMember({"square", "lshape"}))
      ->capture_default_str();
  c->add_option("--n", cmd->options.n, "Number of bodies")->check(CLI::Range(1, kMaxBodies))->capture_default_str();
  c->add_option("--steps", cmd->options.steps, "Steps of 1/60 s for each simulation")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  c->add_option("--seed", cmd->options.seed, "Seed of the initial states")->capture_default_str();
  c->add_option("--repeat", cmd->options.repeat, "Run each simulation this many times; a step's time is the least")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  c->add_option("--drops", cmd->options.drops,
                 "Independent drops per method (seeds seed, seed+1, ...), pooled; Box2D also runs the next "
                 "drops seeds as a second reference sample, the noise floor")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  c->add_option("--box2d-substeps", cmd->options.box2d_substeps,
                "Box2D takes this many steps of dt / N for each step (its convergence); statsim steps dt")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  c->add_flag("--pile-rest", cmd->options.pile_rest,
              "statsim: bodies settling on other bodies blend to the mean rest height (WorldDef::pile_rest)");
  c->add_flag("!--no-sleep-islands", cmd->options.sleep_islands,
              "statsim: each body falls asleep on its own (WorldDef::sleep_islands off; the default: touching "
              "bodies fall asleep together, once all are still)");
  c->add_flag("--ground-hulls", cmd->options.ground_hulls,
              "statsim: bodies meet level ground with their hull after the first impact (WorldDef::ground_hulls)");
  c->add_option("--history-every", cmd->options.history_every,
                "Also show the highest centre and the bodies awake every this many seconds (mean over the drops)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  c->add_option("--csv", cmd->csv, "Also write one CSV row per method to this file");
  c->add_option("--frames", cmd->frames,
                "Also write the first drop's final state of each engine as a frame file, DIR/box2d.csv and "
                "DIR/statsim.csv, for `statsim render`");
  c->callback([cmd]() {
    const Compare2dResult r = run_compare2d(cmd->options);
    std::fputs(compare2d_table(r).c_str(), stdout);
    if (!cmd->csv.empty()) {
      write_file_atomic(cmd->csv, compare2d_csv(r));
      std::printf("wrote %s\n", cmd->csv.c_str());
    }
    if (!cmd->frames.empty()) {
      write_compare2d_frames(r, cmd->frames);
      std::printf("wrote %s/box2d.csv and %s/statsim.csv\n", cmd->frames.c_str(), cmd->frames.c_str());
    }
    std::fflush(stdout);
  });
}

}  // namespace statsim::tools
