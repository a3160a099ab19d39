#include "ref2d/box2d_util.hpp"

#include "common/pi.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace statsim::tools {
namespace {

constexpr int kMaxSteps = 1000000;

double wrap_angle(double a)
{
  return std::remainder(a, 2.0 * kPi);
}

}  // namespace

std::mt19937_64 trial_rng(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c)
{
  return std::mt19937_64(mix64(mix64(mix64(mix64(seed) ^ a) ^ b) ^ c));
}

double uniform01(std::mt19937_64& rng)
{
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

std::vector<b2PolygonShape> box2d_pieces(const Shape2& shape)
{
  std::vector<b2PolygonShape> out;
  for (const std::vector<Point2>& piece : shape.pieces) {
    b2Vec2 v[b2_maxPolygonVertices];
    for (std::size_t k = 0; k < piece.size(); ++k) {
      v[k].Set(static_cast<float>(piece[k].x), static_cast<float>(piece[k].y));
    }
    b2PolygonShape p;
    p.Set(v, static_cast<int32>(piece.size()));
    out.push_back(p);
  }
  return out;
}

b2Body* create_body(b2World& world, const b2BodyDef& def, const std::vector<b2PolygonShape>& pieces,
                    const Surface& surface)
{
  b2Body* body = world.CreateBody(&def);
  for (const b2PolygonShape& p : pieces) {
    b2FixtureDef f;
    f.shape = &p;
    f.density = surface.density;
    f.friction = surface.friction;
    f.restitution = surface.restitution;
    f.restitutionThreshold = surface.restitution_threshold;
    body->CreateFixture(&f);
  }
  return body;
}

b2Body* create_ground(b2World& world, const Surface& surface, float half_length)
{
  b2BodyDef def;
  b2Body* ground = world.CreateBody(&def);
  b2EdgeShape line;
  line.SetTwoSided(b2Vec2(-half_length, 0.0f), b2Vec2(half_length, 0.0f));
  b2FixtureDef f;
  f.shape = &line;
  f.density = 0.0f;
  f.friction = surface.friction;
  f.restitution = surface.restitution;
  f.restitutionThreshold = surface.restitution_threshold;
  ground->CreateFixture(&f);
  return ground;
}

bool touching_anything(b2Body* body)
{
  for (b2ContactEdge* e = body->GetContactList(); e != nullptr; e = e->next) {
    if (e->contact->IsTouching()) {
      return true;
    }
  }
  return false;
}

std::vector<Point2> core_vertices(const b2Body* body)
{
  const b2Vec2 c = body->GetLocalCenter();
  std::vector<Point2> verts;
  for (const b2Fixture* f = body->GetFixtureList(); f != nullptr; f = f->GetNext()) {
    const auto* poly = static_cast<const b2PolygonShape*>(f->GetShape());
    for (int i = 0; i < poly->m_count; ++i) {
      verts.push_back({static_cast<double>(poly->m_vertices[i].x) - static_cast<double>(c.x),
                       static_cast<double>(poly->m_vertices[i].y) - static_cast<double>(c.y)});
    }
  }
  return verts;
}

FreeState read_state(const b2Body* body)
{
  const b2Vec2 c = body->GetWorldCenter();
  const b2Vec2 v = body->GetLinearVelocity();
  return {c.x, c.y, body->GetAngle(), v.x, v.y, body->GetAngularVelocity()};
}

double core_gap(const FreeState& s, const std::vector<Point2>& verts, double t, double offset)
{
  const double a = s.angle + s.w * t;
  const double sn = std::sin(a);
  const double cs = std::cos(a);
  double lowest = std::numeric_limits<double>::infinity();
  for (const Point2& p : verts) {
    lowest = std::min(lowest, sn * p.x + cs * p.y);
  }
  return s.cy + s.vy * t + lowest - offset;
}

std::optional<double> first_contact_time(const FreeState& s, const std::vector<Point2>& verts, double t_max,
                                         double offset)
{
  double r_max = 0.0;
  for (const Point2& p : verts) {
    r_max = std::max(r_max, std::hypot(p.x, p.y));
  }
  // Lipschitz bound of core_gap in t, slightly inflated against rounding.
  const double lipschitz = (std::fabs(s.vy) + std::fabs(s.w) * r_max) * (1.0 + 1e-9) + 1e-300;
  // Steps never shrink below the time to move 1e-10 m: a dip shallower than that could be missed,
  // which is far below Box2D's float32 resolution of the state.
  const double min_step = 1e-10 / lipschitz;
  double t = 0.0;
  double g = core_gap(s, verts, 0.0, offset);
  if (g <= 0.0) {
    return 0.0;
  }
  for (long it = 0; it < 100000000L; ++it) {
    double next = t + std::max(g / lipschitz, min_step);
    if (next > t_max) {
      next = t_max;
    }
    const double g_next = core_gap(s, verts, next, offset);
    if (g_next <= 0.0) {
      double lo = t;
      double hi = next;
      for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi)) {
          break;
        }
        (core_gap(s, verts, mid, offset) <= 0.0 ? hi : lo) = mid;
      }
      return hi;
    }
    if (next >= t_max) {
      return std::nullopt;
    }
    t = next;
    g = g_next;
  }
  throw std::runtime_error("first-contact search did not converge");
}

FirstContact measure_first_contact(const std::vector<b2PolygonShape>& pieces, double height, double angle,
                                   double speed, double spin, double dt)
{
  b2World world(b2Vec2(0.0f, 0.0f));
  world.SetAllowSleeping(false);

  b2BodyDef ground_def;
  b2Body* ground = world.CreateBody(&ground_def);
  b2EdgeShape line;
  line.SetTwoSided(b2Vec2(-20.0f, 0.0f), b2Vec2(20.0f, 0.0f));
  ground->CreateFixture(&line, 0.0f);

  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position.Set(0.0f, static_cast<float>(height));
  def.angle = static_cast<float>(angle);
  def.linearVelocity.Set(0.0f, static_cast<float>(-speed));
  def.angularVelocity = static_cast<float>(spin);
  def.linearDamping = 0.0f;
  def.angularDamping = 0.0f;
  def.allowSleep = false;
  b2Body* body = world.CreateBody(&def);
  for (const b2PolygonShape& p : pieces) {
    b2FixtureDef fixture;
    fixture.shape = &p;
    fixture.density = 1.0f;
    fixture.friction = 0.0f;
    fixture.restitution = 0.0f;
    body->CreateFixture(&fixture);
  }
  // The core shape, exactly as Box2D stores it (the skin m_radius is not part of it).
  const std::vector<Point2> verts = core_vertices(body);

  const float h = static_cast<float>(dt);
  FirstContact trial;
  std::vector<FreeState> starts;  // Box2D's state at the start of each step
  int report = -1;
  for (int step = 0; step < kMaxSteps; ++step) {
    const FreeState s0 = read_state(body);
    starts.push_back(s0);
    world.Step(h, 8, 3);
    if (touching_anything(body)) {
      report = step;
      break;
    }
    // No contact: the step must have been pure free flight.
    const FreeState s1 = read_state(body);
    const double hd = h;
    const double err = std::max({std::fabs(s1.cx - (s0.cx + s0.vx * hd)), std::fabs(s1.cy - (s0.cy + s0.vy * hd)),
                                 std::fabs(wrap_angle(s1.angle - (s0.angle + s0.w * hd))),
                                 std::fabs(s1.vx - s0.vx), std::fabs(s1.vy - s0.vy), std::fabs(s1.w - s0.w)});
    trial.free_flight_error = std::max(trial.free_flight_error, err);
    if (err > 1e-4) {
      throw std::runtime_error("Box2D did not move the body in free flight (deviation " + std::to_string(err) +
                               " in one step)");
    }
  }
  if (report < 0) {
    throw std::runtime_error("Box2D never reported contact with the line");
  }
  trial.steps = report + 1;
  trial.naive_height = body->GetWorldCenter().y;
  trial.report_gap = core_gap(starts[static_cast<std::size_t>(report)], verts, 0.0);

  // Refine from the start of the step before the report, under free flight, until the core
  // touches (the search may run past the end of the reporting step if Box2D reported early).
  const std::size_t from_index = report > 0 ? static_cast<std::size_t>(report - 1) : 0;
  const FreeState& from = starts[from_index];
  const std::optional<double> t_star = first_contact_time(from, verts, from.cy / speed + 1.0);
  if (!t_star) {
    throw std::runtime_error("no core contact found after Box2D's report");
  }
  trial.height = from.cy + from.vy * *t_star;

  // Cross-check against the exact free flight from the initial state (Box2D's float32 initial
  // state, moved in double precision). Both describe the same motion up to Box2D's float32
  // rounding (a few 1e-7 m per step), so they find the same contact -- except that a corner
  // grazing the line by less than that noise may touch in one and not in the other. The first
  // contact is the earlier of the two.
  const FreeState& initial = starts.front();
  const std::optional<double> t_initial = first_contact_time(initial, verts, initial.cy / speed + 1.0);
  if (!t_initial) {
    throw std::runtime_error("no core contact in the free flight from the initial state");
  }
  const double height_initial = initial.cy + initial.vy * *t_initial;
  const double window_start = static_cast<double>(from_index) * static_cast<double>(h);
  const double t_refined = window_start + *t_star;
  const double tolerance = 1e-5 / speed;  // the time to travel 10 micrometres
  double t_first = t_refined;
  if (*t_initial < window_start - tolerance) {
    // A fast corner dipped through the line and out again between steps, unseen by Box2D.
    trial.missed = true;
    trial.height = height_initial;
    t_first = *t_initial;
  } else if (std::fabs(*t_initial - t_refined) > tolerance) {
    trial.grazing = true;
    if (*t_initial < t_refined) {
      trial.height = height_initial;
      t_first = *t_initial;
    }
  } else {
    trial.float_drift = std::fabs(trial.height - height_initial);
  }
  trial.late = report > 0 && !trial.missed && t_first < static_cast<double>(report) * static_cast<double>(h) - tolerance;
  return trial;
}

}  // namespace statsim::tools
