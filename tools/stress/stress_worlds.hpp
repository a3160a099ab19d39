// The worlds a stress cell runs: in 3D the benchmark's Bullet simulator or a statsim World3 with
// the scene's planes, gravity, material and body contacts (Setup3, make_sim3); in 2D Box2D's
// polygon or a statsim World2 (Sim2). With the methods' names and the checks every family uses.
#pragma once

#include "bench/bench_internal.hpp"
#include "scenes/body_def.hpp"
#include "scenes/scenes.hpp"
#include "tables/bunny.hpp"
#include "tables/square2d.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <box2d/box2d.h>

#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace statsim::tools::stress {

using bench::Body3;
using Clock = std::chrono::steady_clock;
constexpr double kG = 9.81;
constexpr double kInf = std::numeric_limits<double>::infinity();

inline const std::vector<std::string> kMethods3 = {"full", "low", "spheres7", "sphere", "statistical"};
inline const std::vector<std::string> kMethods2 = {"polygon", "statistical2d"};

inline bool finite3(const Eigen::Vector3d& v)
{
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

/// The largest of `vmax` and the speeds of the bodies now; infinite once one is not finite.
inline double max_speed(const bench::Sim& sim, double vmax)
{
  for (std::size_t i = 0; i < sim.body_count(); ++i) {
    const double v = sim.body_state(i).linear_velocity.norm();
    vmax = std::isfinite(v) ? std::max(vmax, v) : kInf;
  }
  return vmax;
}


struct Setup3 {
  std::vector<bullet::Plane> planes{{Eigen::Vector3d(0, 0, 1), 0.0}};
  Eigen::Vector3d gravity{0, 0, -kG};
  /// Bullet material; statsim uses the table's (or `particle`'s).
  double restitution = -1, friction = -1;  // < 0: the table's
  bool sleeping = true;
  /// statsim: plain spheres of the table's zero-spin radius with this material instead of the
  /// statistical shape (the particle model).
  bool particle = false;
  /// statsim: where bodies touch (`StressOptions::hull_contacts`).
  BodyContacts body_contacts = BodyContacts::automatic;
  /// statsim: `WorldDef::ground_hulls` (`StressOptions::ground_hulls`).
  bool ground_hulls = false;
  /// statsim: the table; null: the bunny's. Bullet takes the `Body3` it is given.
  const SignatureView<3>* signature = nullptr;
  /// Body i has the shape's mass (and inertia) times `mass_scale[i]`; empty: all 1.
  std::vector<double> mass_scale;
};

// statsim 3D: the benchmark's statsim world has one ground plane, gravity and the table's shape;
// the stress scenes need walls, no gravity and the particle model.
template <std::uint32_t Cap>
class StatsimSim3 final : public bench::Sim {
public:
  using WorldT = World3<Cap, 8, Cap * 32, 2>;

  StatsimSim3(const Setup3& setup, const std::vector<scenes::BodyState3>& states, double dt)
      : sig_(setup.signature ? *setup.signature : tables::bunny.view()), particle_(setup.particle),
        dt_(static_cast<Scalar>(dt))
  {
    if (states.size() > Cap) throw std::runtime_error("stress: statsim world too small");
    WorldDef3 def;
    def.gravity = setup.gravity.cast<Scalar>();
    def.body_contacts = setup.body_contacts;
    def.ground_hulls = setup.ground_hulls;
    world_ = std::make_unique<WorldT>(def);
    Added<ShapeId> shape;
    if (setup.particle) {
      ShapeDef sd;
      sd.radius = sig_.height.mean[0];
      sd.material.restitution = static_cast<Scalar>(setup.restitution >= 0 ? setup.restitution : 0.3);
      sd.material.friction = static_cast<Scalar>(setup.friction >= 0 ? setup.friction : 0.5);
      sd.material.rolling_resistance = setup.friction == 0 ? 0 : sd.material.rolling_resistance;
      shape = world_->add_shape(sd);
    } else {
      shape = world_->add_shape(sig_);
    }
    if (!shape.ok()) throw std::runtime_error(std::string("statsim add_shape: ") + to_string(shape.status));
    for (const bullet::Plane& p : setup.planes) {
      const auto added = world_->add_plane(p.normal.cast<Scalar>(), static_cast<Scalar>(p.offset));
      if (!added.ok()) throw std::runtime_error(std::string("statsim add_plane: ") + to_string(added.status));
    }
    mass_ = static_cast<double>(sig_.mass);
    for (std::size_t i = 0; i < states.size(); ++i) {
      const scenes::BodyState3& s = states[i];
      BodyDef3 b = scenes::body_def(s);
      b.shape = shape.id;
      b.mass = static_cast<Scalar>(mass_ * (setup.mass_scale.empty() ? 1.0 : setup.mass_scale[i]));
      const Added<BodyId> added = world_->add_body(b);
      if (!added.ok()) throw std::runtime_error(std::string("statsim add_body: ") + to_string(added.status));
    }
  }
  void step() override
  {
    last_ = world_->step(dt_);
    if (last_.status != Status::ok) throw std::runtime_error(std::string("statsim step: ") + to_string(last_.status));
    dropped_ = std::max(dropped_, last_.pairs_dropped);
  }
  std::size_t asleep() const override { return world_->count(MotionState::asleep); }
  bench::EndState end_state() const override
  {
    bench::EndState e;
    e.asleep = asleep();
    double h = 0;
    for (std::uint32_t i = 0; i < world_->body_count(); ++i) h += double(world_->body(i).position.z());
    e.mean_height = world_->body_count() ? h / world_->body_count() : 0.0;
    e.contacts = last_.contacts;
    return e;
  }
  std::size_t body_count() const override { return world_->body_count(); }
  scenes::BodyState3 body_state(std::size_t i) const override
  {
    const Body<3>& b = world_->body(static_cast<BodyId>(i));
    scenes::BodyState3 s;
    s.position = b.position.cast<double>();
    s.orientation = b.orientation.cast<double>();
    s.linear_velocity = b.linear_velocity.cast<double>();
    s.angular_velocity = b.angular_velocity.cast<double>();
    return s;
  }
  bool body_asleep(std::size_t i) const override
  {
    return world_->body(static_cast<BodyId>(i)).state == MotionState::asleep;
  }
  double kinetic_energy() const override
  {
    double ke = 0;
    for (std::uint32_t i = 0; i < world_->body_count(); ++i) {
      const Body<3>& b = world_->body(i);
      ke += particle_ ? 0.5 * mass_ * double(b.linear_velocity.squaredNorm())
                      : mass_ * double(kinetic_energy_per_mass<3>(sig_, b.orientation, b.linear_velocity,
                                                                  b.angular_velocity));
    }
    return ke;
  }
  double overlap() const override
  {
    // Every pair, asleep or not (the broad phase skips sleeping pairs): a sweep along x. With
    // collision spheres the overlap is that of the spheres over the sum of their radii; with
    // hull contacts that of the hulls over the separation at which the runtime's own rule lets
    // them touch (the closest hull candidate times its packing ratio), as tests/test_hull_contacts does.
    const bool hulls = world_->def().body_contacts != BodyContacts::collision_spheres;  // Features::all
    const std::uint32_t n = world_->body_count();
    std::vector<std::pair<double, std::uint32_t>> xs(n);
    double rmax = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const Body<3>& b = world_->body(i);
      xs[i] = {double(b.position.x()), i};
      rmax = std::max({rmax, double(b.radius), hulls ? double(world_->shape(ShapeId(b.shape)).bounding_radius) : 0.0});
    }
    std::sort(xs.begin(), xs.end());
    double deepest = 0;
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t j = i + 1; j < n && xs[j].first - xs[i].first < 2 * rmax; ++j) {
        const Body<3>& a = world_->body(xs[i].second);
        const Body<3>& b = world_->body(xs[j].second);
        deepest = std::max(deepest, hulls ? hull_overlap(a, b) : sphere_overlap(a, b));
      }
    return deepest;
  }
  static double sphere_overlap(const Body<3>& a, const Body<3>& b)
  {
    const double sum = double(a.radius) + double(b.radius);
    const double d = double((a.position - b.position).norm());
    return (sum - d) / sum;
  }
  double hull_overlap(const Body<3>& a, const Body<3>& b) const
  {
    const Shape<3>& sa = world_->shape(ShapeId(a.shape));
    const Shape<3>& sb = world_->shape(ShapeId(b.shape));
    const Vector3 d = b.position - a.position;
    const Scalar dist = d.norm();
    if (!(dist > 0)) return 1;
    const Vector3 e = d / dist;
    const Scalar packing = std::max(sa.largest_packing, sb.largest_packing);
    const std::uint32_t k = detail::find_hull_witness(sa, a, sb, b, e, dist, packing);
    if (k == detail::no_witness) return 0;
    const detail::HullCandidate<3> h = detail::hull_candidate(sa, a, sb, b, e, k);
    const Scalar reach = (k == 0 ? detail::pair_packing(sa, sb, a.shape == b.shape, e) : h.packing) * h.reach;
    return double((reach - d.dot(h.normal)) / reach);
  }
  double lowest(std::size_t i) const override
  {
    const Body<3>& b = world_->body(static_cast<BodyId>(i));
    return double(b.position.z()) - double(b.radius);
  }
  std::uint32_t pairs_dropped() const { return dropped_; }
  std::uint64_t hash() const { return world_->state_hash(); }

private:
  SignatureView<3> sig_;
  bool particle_;
  Scalar dt_;
  double mass_ = 1;
  std::unique_ptr<WorldT> world_;
  StepResult last_{};
  std::uint32_t dropped_ = 0;
};

/// A 3D world of `method` stepped by dt: Bullet through the benchmark's simulator (its settings,
/// with the setup's planes, gravity, material and sleeping), statsim through a World3.
std::unique_ptr<bench::Sim> make_sim3(const Body3& body, const std::shared_ptr<bench::BulletShapes>& shapes,
                                      const std::string& method, const Setup3& setup,
                                      const std::vector<scenes::BodyState3>& states, double dt);

// ---- 2D: Box2D polygon and statsim ------------------------------------------------------------------
struct State2 {
  Eigen::Vector2d x, v;
  double lowest = 0;  ///< height of the lowest point above y = 0
  bool asleep = false;
};

class Sim2 {
public:
  virtual ~Sim2() = default;
  virtual void step(double dt) = 0;
  virtual std::size_t size() const = 0;
  virtual State2 state(std::size_t i) const = 0;
};

class Box2dSim final : public Sim2 {
public:
  /// The ground is the line y = 0, or with `slope` (rad) the line through the origin that falls
  /// along +x at that angle.
  Box2dSim(const std::vector<scenes::BodyState2>& states, double mass, double e, double mu, double slope = 0)
      : world_(b2Vec2(0.0f, float(-kG)))
  {
    b2BodyDef gd;
    b2Body* ground = world_.CreateBody(&gd);
    b2EdgeShape edge;
    if (slope == 0) {
      edge.SetTwoSided(b2Vec2(-1000.0f, 0.0f), b2Vec2(1000.0f, 0.0f));
    } else {
      const float cx = float(1000 * std::cos(slope)), cy = float(1000 * std::sin(slope));
      edge.SetTwoSided(b2Vec2(-cx, cy), b2Vec2(cx, -cy));
    }
    b2FixtureDef gf;
    gf.shape = &edge;
    gf.friction = float(mu);
    gf.restitution = float(e);
    ground->CreateFixture(&gf);
    box_.SetAsBox(0.5f, 0.5f);
    for (const auto& s : states) {
      b2BodyDef bd;
      bd.type = b2_dynamicBody;
      bd.position.Set(float(s.position.x()), float(s.position.y()));
      bd.angle = float(s.angle);
      bd.linearVelocity.Set(float(s.linear_velocity.x()), float(s.linear_velocity.y()));
      bd.angularVelocity = float(s.angular_velocity);
      b2Body* b = world_.CreateBody(&bd);
      b2FixtureDef fd;
      fd.shape = &box_;
      fd.density = float(mass);  // unit area
      fd.friction = float(mu);
      fd.restitution = float(e);
      b->CreateFixture(&fd);
      bodies_.push_back(b);
    }
  }
  void step(double dt) override { world_.Step(float(dt), 8, 3); }
  std::size_t size() const override { return bodies_.size(); }
  State2 state(std::size_t i) const override
  {
    const b2Body* b = bodies_[i];
    State2 s;
    s.x = Eigen::Vector2d(b->GetPosition().x, b->GetPosition().y);
    s.v = Eigen::Vector2d(b->GetLinearVelocity().x, b->GetLinearVelocity().y);
    s.lowest = kInf;
    for (int k = 0; k < box_.m_count; ++k)
      s.lowest = std::min(s.lowest, double(b->GetWorldPoint(box_.m_vertices[k]).y));
    s.asleep = !b->IsAwake();
    return s;
  }

private:
  b2World world_;
  b2PolygonShape box_;
  std::vector<b2Body*> bodies_;
};

class StatsimSim2 final : public Sim2 {
public:
  /// The ground's normal is (0, 1), or with `slope` (rad) (sin, cos): falling along +x.
  StatsimSim2(const std::vector<scenes::BodyState2>& states, BodyContacts contacts, bool ground_hulls, double slope = 0)
  {
    WorldDef2 def;
    def.body_contacts = contacts;
    def.ground_hulls = ground_hulls;
    world_ = std::make_unique<World2<256, 4, 256 * 16, 2>>(def);
    const SignatureView<2> sig = tables::square2d.view();
    const auto shape = world_->add_shape(sig);
    const Vector2 normal = slope == 0 ? Vector2(0, 1) : Vector2(float(std::sin(slope)), float(std::cos(slope)));
    if (!shape.ok() || !world_->add_plane(normal, 0).ok()) throw std::runtime_error("statsim 2D set-up failed");
    for (const auto& s : states) {
      BodyDef<2> b;
      b.position = s.position.cast<Scalar>();
      b.orientation = Rot2{Scalar(std::cos(s.angle)), Scalar(std::sin(s.angle))};
      b.linear_velocity = s.linear_velocity.cast<Scalar>();
      b.angular_velocity = Scalar(s.angular_velocity);
      b.shape = shape.id;
      b.mass = sig.mass;
      if (!world_->add_body(b).ok()) throw std::runtime_error("statsim 2D add_body failed");
    }
  }
  void step(double dt) override
  {
    if (world_->step(static_cast<Scalar>(dt)).status != Status::ok) throw std::runtime_error("statsim 2D step failed");
  }
  std::size_t size() const override { return world_->body_count(); }
  State2 state(std::size_t i) const override
  {
    const Body<2>& b = world_->body(static_cast<BodyId>(i));
    State2 s;
    s.x = b.position.cast<double>();
    s.v = b.linear_velocity.cast<double>();
    s.lowest = double(b.position.y()) - double(b.radius);
    s.asleep = b.state == MotionState::asleep;
    return s;
  }

private:
  std::unique_ptr<World2<256, 4, 256 * 16, 2>> world_;
};

}  // namespace statsim::tools::stress
