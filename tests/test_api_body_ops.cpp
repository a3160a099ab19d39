// Impulses, wake and sleep: velocity changes through the body's inverse mass and inertia, the
// statuses of bad input (and that a rejected call changes nothing), and the awake set.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <cmath>
#include <limits>
#include <memory>

using namespace statsim;

namespace {
constexpr float tol = 1e-5f;

}  // namespace

TEST_CASE("an impulse at the centre changes the velocity by J / m, off the centre the spin by I^-1 (r x J)")
{
  WorldDef3 def;
  def.gravity = Vector3::Zero();
  auto w = std::make_unique<World3<4>>(def);
  ShapeDef ball;
  ball.radius = 0.2f;
  ball.mass = 2;
  BodyDef3 bd;
  bd.shape = w->add_shape(ball).id;
  bd.position = Vector3(1, 2, 3);
  const BodyId id = w->add_body(bd).id;

  REQUIRE(w->apply_impulse(id, Vector3(4, 0, 0), Vector3(1, 2, 3)) == Status::ok);
  CHECK(w->body(id).linear_velocity.isApprox(Vector3(2, 0, 0)));
  CHECK(w->body(id).angular_velocity.norm() == 0);

  // r = (0, 0, 0.2), J = (4, 0, 0): r x J = (0, 0.8, 0); I = 2/5 m r^2 = 0.032 kg m^2.
  REQUIRE(w->apply_impulse(id, Vector3(4, 0, 0), Vector3(1, 2, 3.2f)) == Status::ok);
  CHECK(w->body(id).linear_velocity.isApprox(Vector3(4, 0, 0)));
  CHECK(std::fabs(w->body(id).angular_velocity.y() - 0.8f / 0.032f) < 1e-3f);
  CHECK(std::fabs(w->body(id).angular_velocity.x()) < tol);

  REQUIRE(w->apply_angular_impulse(id, Vector3(0, -0.8f, 0.032f)) == Status::ok);
  CHECK(std::fabs(w->body(id).angular_velocity.y()) < 1e-3f);
  CHECK(std::fabs(w->body(id).angular_velocity.z() - 1) < 1e-4f);
}

TEST_CASE("a 2D disc turns with I = 1/2 m r^2")
{
  WorldDef2 def;
  def.gravity = Vector2::Zero();
  auto w = std::make_unique<World2<4>>(def);
  ShapeDef ball;
  ball.radius = 0.5f;
  ball.mass = 4;
  BodyDef2 bd;
  bd.shape = w->add_shape(ball).id;
  const BodyId id = w->add_body(bd).id;
  // r = (0.5, 0), J = (0, 1): r x J = 0.5; I = 0.5 * 4 * 0.25 = 0.5.
  REQUIRE(w->apply_impulse(id, Vector2(0, 1), Vector2(0.5f, 0)) == Status::ok);
  CHECK(std::fabs(w->body(id).angular_velocity - 1) < tol);
  CHECK(w->body(id).linear_velocity.isApprox(Vector2(0, 0.25f)));
}

TEST_CASE("a statistical body turns with its table's inertia about its own axes")
{
  WorldDef3 def;
  def.gravity = Vector3::Zero();
  auto w = std::make_unique<World3<4>>(def);
  Signature<3, 2, 2, 2, 2, 1, 6> sig = testing::cube_synthetic;
  sig.unit_inertia = {0.01f, 0.02f, 0.04f};
  BodyDef3 bd;
  bd.shape = w->add_shape(sig.view()).id;
  bd.mass = 1;
  // A quarter turn about z: the body's y axis points along world -x.
  bd.orientation = Quaternion(std::sqrt(0.5f), 0, 0, std::sqrt(0.5f));
  const BodyId id = w->add_body(bd).id;
  const Vector3 before = w->body(id).angular_velocity;
  REQUIRE(w->apply_angular_impulse(id, Vector3(0.02f, 0, 0)) == Status::ok);
  const Vector3 dw = w->body(id).angular_velocity - before;
  CHECK(std::fabs(dw.x() - 1) < 1e-4f);  // about the body's y axis: 0.02 / (1 kg 0.02 m^2)
  CHECK(std::fabs(dw.y()) < 1e-4f);
  CHECK(std::fabs(dw.z()) < 1e-4f);
  REQUIRE(w->apply_angular_impulse(id, Vector3(0, 0, 0.04f)) == Status::ok);
  CHECK(std::fabs(w->body(id).angular_velocity.z() - before.z() - 1) < 1e-4f);
}

TEST_CASE("bad ids and bad input are refused and change nothing")
{
  auto w = std::make_unique<World3<4>>();
  ShapeDef ball;
  BodyDef3 bd;
  bd.shape = w->add_shape(ball).id;
  bd.position = Vector3(0, 0, 1);
  const BodyId id = w->add_body(bd).id;
  const std::uint64_t h = w->state_hash();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  CHECK(w->apply_impulse(id + 1, Vector3(1, 0, 0), Vector3::Zero()) == Status::invalid_body);
  CHECK(w->apply_angular_impulse(id + 1, Vector3(1, 0, 0)) == Status::invalid_body);
  CHECK(w->wake(id + 1) == Status::invalid_body);
  CHECK(w->sleep(id + 1) == Status::invalid_body);
  CHECK(w->apply_impulse(id, Vector3(nan, 0, 0), Vector3::Zero()) == Status::non_finite);
  CHECK(w->apply_impulse(id, Vector3(1, 0, 0), Vector3(0, nan, 0)) == Status::non_finite);
  CHECK(w->apply_angular_impulse(id, Vector3(0, 0, nan)) == Status::non_finite);
  CHECK(w->apply_impulse(id, Vector3(1e30f, 0, 0), Vector3::Zero()) == Status::out_of_range);
  CHECK(w->apply_impulse(id, Vector3(1, 0, 0), Vector3(1e7f, 0, 0)) == Status::out_of_range);
  CHECK(w->apply_angular_impulse(id, Vector3(0, 0, 1e30f)) == Status::out_of_range);
  CHECK(w->state_hash() == h);
}

TEST_CASE("sleep takes a body off the awake set and holds it still; wake and impulses put it back")
{
  auto w = std::make_unique<World3<4>>();
  ShapeDef ball;
  BodyDef3 bd;
  bd.shape = w->add_shape(ball).id;
  bd.position = Vector3(0, 0, 5);
  bd.linear_velocity = Vector3(1, 0, 0);
  const BodyId id = w->add_body(bd).id;
  REQUIRE(w->sleep(id) == Status::ok);
  CHECK(w->body(id).state == MotionState::asleep);
  CHECK(w->body(id).linear_velocity.norm() == 0);
  CHECK(w->sleep(id) == Status::ok);  // already asleep: no change
  StepResult r = w->step(1.0f / 60);
  CHECK(r.bodies_integrated == 0);
  CHECK(w->body(id).position == Vector3(0, 0, 5));  // a sleeper in the air stays there

  REQUIRE(w->wake(id) == Status::ok);
  CHECK(w->body(id).state == MotionState::moving);
  r = w->step(1.0f / 60);
  CHECK(r.bodies_integrated == 1);
  CHECK(w->body(id).position.z() < 5);

  REQUIRE(w->sleep(id) == Status::ok);
  REQUIRE(w->apply_impulse(id, Vector3(0, 0, 1), w->body(id).position) == Status::ok);
  CHECK(w->body(id).state == MotionState::moving);
  CHECK(w->body(id).linear_velocity.z() > 0);
  r = w->step(1.0f / 60);
  CHECK(r.bodies_integrated == 1);
}
