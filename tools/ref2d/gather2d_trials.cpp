// See gather2d_trials.hpp.
#include "ref2d/gather2d_trials.hpp"

#include "common/pi.hpp"
#include "ref2d/fig3.hpp"
#include "statsim/detail/response.hpp"
#include "statsim/statistical.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace statsim::tools {

namespace {

// Box2D's skins: contact is reported (and resolved) once the cores are within 2 * 0.01 m.
constexpr double kSkin = 2.0 * static_cast<double>(b2_polygonRadius);

}  // namespace

Gather2dContext make_context(const Gather2dOptions& o)
{
  Gather2dContext c;
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

double step_for_spin(double dt, double max_spin)
{
  return max_spin > 0.0 ? std::min(dt, 0.4 / max_spin) : dt;
}

ResponseTrial2d simulate_response(const Gather2dContext& ctx, double cos_theta, double spin_ratio, double speed, double dt,
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
  ResponseTrial2d trial;
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

RestTrial2d simulate_rest(const Gather2dContext& ctx, const Gather2dOptions& o, std::mt19937_64& rng)
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
  RestTrial2d t;
  for (int step = 0; step < max_steps && body->IsAwake(); ++step) {
    world.Step(h, 8, 3);
  }
  t.settled = body->IsAwake() ? 0 : 1;
  const double a = body->GetAngle();
  t.up = {std::sin(a), std::cos(a)};  // R^T (0, 1)
  return t;
}

void warm_up_box2d(const Gather2dContext& ctx)
{
  measure_first_contact(ctx.pieces, ctx.shape.bounding_radius + 0.1, 0.0, 1.0, 0.0, 1.0 / 60.0);
}

}  // namespace statsim::tools
