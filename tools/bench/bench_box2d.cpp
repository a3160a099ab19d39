// The Box2D methods of `statsim bench --dim 2`: polygon (the unit square as a b2PolygonShape) and
// circle (one b2CircleShape). Box2D is tuned for bodies of 0.1 to 10 m, so the 1 m square needs no
// rescaling; its sleep tolerances are compile-time constants of the library.
#include "bench/bench_internal.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace statsim::tools::bench {
namespace {

constexpr int kVelocityIterations = 8;
constexpr int kPositionIterations = 3;

class Box2dSim final : public Sim {
public:
  Box2dSim(const Body2& body, const std::string& method, const scenes::DropScene2& scene, double dt)
      : dt_(static_cast<float>(dt))
  {
    world_ = std::make_unique<b2World>(b2Vec2(0.0f, -9.81f));
    b2BodyDef gd;
    b2Body* ground = world_->CreateBody(&gd);
    // The ground reaches far beyond the scene: Box2D's circles roll without resistance and would
    // otherwise roll off its ends.
    const float reach = static_cast<float>(std::max(1000.0, 20 * scene.bounds_hi.x()));
    b2EdgeShape edge;
    edge.SetTwoSided(b2Vec2(-reach, 0.0f), b2Vec2(reach, 0.0f));
    b2FixtureDef gf;
    gf.shape = &edge;
    gf.friction = static_cast<float>(body.surface.friction);
    gf.restitution = static_cast<float>(body.surface.restitution);
    gf.restitutionThreshold = static_cast<float>(body.surface.restitution_threshold);
    ground->CreateFixture(&gf);

    b2PolygonShape square;
    square.SetAsBox(static_cast<float>(body.half_side), static_cast<float>(body.half_side));
    b2CircleShape circle;
    circle.m_radius = static_cast<float>(body.circle_radius);
    b2FixtureDef f;
    if (method == "polygon") {
      f.shape = &square;
      f.density = static_cast<float>(body.mass / (4 * body.half_side * body.half_side));
    } else if (method == "circle") {
      f.shape = &circle;
      f.density = static_cast<float>(body.mass / (3.14159265358979 * body.circle_radius * body.circle_radius));
    } else {
      throw std::runtime_error("Box2D: unknown method " + method);
    }
    f.friction = static_cast<float>(body.surface.friction);
    f.restitution = static_cast<float>(body.surface.restitution);
    f.restitutionThreshold = static_cast<float>(body.surface.restitution_threshold);
    bodies_.reserve(scene.bodies.size());
    for (const scenes::BodyState2& s : scene.bodies) {
      b2BodyDef d;
      d.type = b2_dynamicBody;
      d.position.Set(static_cast<float>(s.position.x()), static_cast<float>(s.position.y()));
      d.angle = static_cast<float>(s.angle);
      d.linearVelocity.Set(static_cast<float>(s.linear_velocity.x()), static_cast<float>(s.linear_velocity.y()));
      d.angularVelocity = static_cast<float>(s.angular_velocity);
      b2Body* b = world_->CreateBody(&d);
      b->CreateFixture(&f);
      bodies_.push_back(b);
    }
  }

  void step() override { world_->Step(dt_, kVelocityIterations, kPositionIterations); }
  PhaseTimes phases() const override
  {
    // b2Profile, ms: `collide` is the narrow phase (contact updates), `broadphase` the pair search
    // after the solver moved the bodies.
    const b2Profile& p = world_->GetProfile();
    PhaseTimes t;
    t.broad = static_cast<std::int64_t>(static_cast<double>(p.broadphase) * 1e6);
    t.narrow = static_cast<std::int64_t>(static_cast<double>(p.collide) * 1e6);
    return t;
  }
  std::size_t asleep() const override
  {
    std::size_t k = 0;
    for (const b2Body* b : bodies_) k += !b->IsAwake();
    return k;
  }
  EndState end_state() const override
  {
    EndState e;
    e.asleep = asleep();
    double y = 0;
    for (const b2Body* b : bodies_) y += static_cast<double>(b->GetWorldCenter().y);
    e.mean_height = bodies_.empty() ? 0.0 : y / static_cast<double>(bodies_.size());
    for (const b2Contact* c = world_->GetContactList(); c; c = c->GetNext()) e.contacts += c->IsTouching();
    return e;
  }

private:
  float dt_;
  std::unique_ptr<b2World> world_;
  std::vector<b2Body*> bodies_;
};

std::string fmt(const char* format, double a)
{
  char buf[256];
  std::snprintf(buf, sizeof buf, format, a);
  return buf;
}

}  // namespace

std::unique_ptr<Sim> make_box2d(const Body2& body, const std::string& method, const scenes::DropScene2& scene,
                                double dt)
{
  return std::make_unique<Box2dSim>(body, method, scene, dt);
}

std::vector<std::string> box2d_settings(const Body2& body)
{
  std::vector<std::string> s;
  s.push_back(fmt("Box2D 2.4.1 (Debian libbox2d-dev): velocity iterations %g, ", kVelocityIterations) +
              fmt("position iterations %g (the testbed's), continuous collision on (default), gravity (0, -9.81)",
                  kPositionIterations));
  s.push_back(fmt("Box2D shapes: polygon = b2PolygonShape box of side %.3g m (skin 0.01 m, b2_polygonRadius); ",
                  2 * body.half_side) +
              fmt("circle = b2CircleShape of radius %.4g m, ", body.circle_radius) + body.circle_radius_note +
              "; ground: two-sided b2EdgeShape y = 0 from x = -max(1000 m, 20 x the scene's reach) to +");
  s.push_back(fmt("Box2D material: friction %.3g ", body.surface.friction) +
              fmt("(Box2D mixes sqrt(a b)), restitution %.3g (mixes max), ", body.surface.restitution) +
              fmt("restitution threshold %.3g m/s (default 1)", body.surface.restitution_threshold));
  s.push_back("Box2D sleeping: library constants (b2_linearSleepTolerance 0.01 m/s, b2_angularSleepTolerance "
              "2 deg/s, b2_timeToSleep 0.5 s), islands; no rolling resistance in Box2D (circles roll until "
              "friction between them stops them)");
  s.push_back("Box2D timing: collision = b2Profile::collide (contact update, narrow) + b2Profile::broadphase "
              "(pair search); response = the rest of Step (solver, integration, TOI); b2Timer resolution limits "
              "small N");
  return s;
}

}  // namespace statsim::tools::bench
