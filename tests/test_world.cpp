#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"
#include "support/world_states.hpp"

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <cmath>
#include <limits>
#include <memory>

using namespace statsim;

namespace {
constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();
constexpr float inf_f = std::numeric_limits<float>::infinity();

/// Adds one shape of plain spheres of radius `radius` (bounding radius `bounding`, 0: the
/// radius), then the ground: the plane with normal up at height `ground`, m.
template <class World>
ShapeId add_ground_and_spheres(World& w, float radius, float bounding = 0, float ground = 0)
{
  ShapeDef s;
  s.radius = radius;
  s.bounding_radius = bounding;
  const Added<ShapeId> shape = w.add_shape(s);
  REQUIRE(shape.ok());
  REQUIRE(w.add_plane(World::Vec::Unit(World::Vec::RowsAtCompileTime - 1), ground).ok());
  return shape.id;
}

template <class World>
void fill_scene(World& w, int n, std::uint32_t seed)
{
  add_ground_and_spheres(w, 0.1f, 0.12f);
  Pcg32 g(seed, 0);
  for (int i = 0; i < n; ++i) {
    BodyDef<World::Vec::RowsAtCompileTime> b;
    for (int k = 0; k < b.position.size(); ++k) b.position[k] = g.uniform(-1, 1);
    b.position[b.position.size() - 1] = g.uniform(0.2f, 3);
    for (int k = 0; k < b.position.size(); ++k) b.linear_velocity[k] = g.uniform(-2, 2);
    REQUIRE(w.add_body(b).ok());
  }
}
}  // namespace

TEST_CASE("bad input is rejected with its status and the world is unchanged (3D)")
{
  World3<4, 2> w;
  fill_scene(w, 3, 1);
  for (int i = 0; i < 10; ++i) REQUIRE(w.step(1.0f / 60).status == Status::ok);
  const std::uint64_t before = w.state_hash();
  const std::uint32_t bodies = w.body_count();

  BodyDef3 ok;
  ok.position = Vector3(0, 0, 1);
  auto expect_rejected = [&](const BodyDef3& d, Status s) {
    CHECK(w.add_body(d).status == s);
    CHECK(w.body_count() == bodies);
    CHECK(w.state_hash() == before);
  };
  BodyDef3 d = ok;
  d.position.x() = nan_f;
  expect_rejected(d, Status::non_finite);
  d = ok;
  d.position.z() = inf_f;
  expect_rejected(d, Status::non_finite);
  d = ok;
  d.linear_velocity.y() = nan_f;
  expect_rejected(d, Status::non_finite);
  d = ok;
  d.angular_velocity.x() = -inf_f;
  expect_rejected(d, Status::non_finite);
  d = ok;
  d.orientation = Quaternion(0, 0, 0, 0);
  expect_rejected(d, Status::zero_quaternion);
  d = ok;
  d.orientation = Quaternion(2, 0, 0, 0);
  expect_rejected(d, Status::non_unit_quaternion);
  d = ok;
  d.orientation = Quaternion(nan_f, 0, 0, 0);
  expect_rejected(d, Status::non_finite);
  d = ok;
  d.shape = ShapeId(5);
  expect_rejected(d, Status::invalid_shape);
  d = ok;
  d.mass = -1;
  expect_rejected(d, Status::invalid_mass);
  d = ok;
  d.mass = nan_f;
  expect_rejected(d, Status::non_finite);

  CHECK(w.step(0).status == Status::invalid_time_step);
  CHECK(w.step(-1.0f / 60).status == Status::invalid_time_step);
  CHECK(w.step(nan_f).status == Status::invalid_time_step);
  CHECK(w.step(inf_f).status == Status::invalid_time_step);
  CHECK(w.state_hash() == before);

  CHECK(w.add_plane(Vector3::Zero(), 0).status == Status::invalid_plane);
  CHECK(w.add_plane(Vector3(0, nan_f, 1), 0).status == Status::invalid_plane);
  CHECK(w.add_plane(Vector3(0, 0, 1), inf_f).status == Status::invalid_plane);
  CHECK(w.plane_count() == 1);

  ShapeDef bad;
  bad.radius = -1;
  CHECK(w.add_shape(bad).status == Status::invalid_radius);
  bad.radius = 0.2f;
  bad.bounding_radius = 0.1f;
  CHECK(w.add_shape(bad).status == Status::invalid_radius);
  bad.bounding_radius = 0;
  bad.material.restitution = 1.5f;
  CHECK(w.add_shape(bad).status == Status::invalid_material);
  bad.material.restitution = 0.5f;
  bad.material.friction = nan_f;
  CHECK(w.add_shape(bad).status == Status::non_finite);
  CHECK(w.shape_count() == 1);

  CHECK(w.set_velocity(7, Vector3::Zero(), Vector3::Zero()) == Status::invalid_body);
  CHECK(w.set_velocity(0, Vector3(nan_f, 0, 0), Vector3::Zero()) == Status::non_finite);
  CHECK(w.set_transform(0, Vector3::Zero(), Quaternion(0, 0, 0, 0)) == Status::zero_quaternion);
  CHECK(w.state_hash() == before);

  WorldDef3 def = w.def();
  def.sleep_time = -1;
  CHECK(w.configure(def) == Status::invalid_parameter);
  def = w.def();
  def.gravity.x() = nan_f;
  CHECK(w.configure(def) == Status::non_finite);
  def = w.def();
  def.sweep_axis = 3;
  CHECK(w.configure(def) == Status::invalid_parameter);
  CHECK(w.def().sweep_axis == 0);

  // Filling to capacity works; one more is reported, not dropped silently or overwritten.
  CHECK(w.add_body(ok).ok());
  CHECK(w.add_body(ok).status == Status::capacity_exceeded);
  CHECK(w.body_count() == 4);
  CHECK(w.add_plane(Vector3(1, 0, 0), -5).ok());
  CHECK(w.add_plane(Vector3(-1, 0, 0), -5).status == Status::capacity_exceeded);
}

TEST_CASE("bad input is rejected with state unchanged (2D)")
{
  World2<2, 1> w;
  fill_scene(w, 1, 2);
  REQUIRE(w.step(1.0f / 60).status == Status::ok);
  const std::uint64_t before = w.state_hash();
  BodyDef2 d;
  d.orientation = Rot2{0, 0};
  CHECK(w.add_body(d).status == Status::zero_quaternion);
  d.orientation = Rot2{0.5f, 0.5f};
  CHECK(w.add_body(d).status == Status::non_unit_quaternion);
  d.orientation = Rot2::from_angle(0.3f);
  d.angular_velocity = nan_f;
  CHECK(w.add_body(d).status == Status::non_finite);
  CHECK(w.add_plane(Vector2(0, 0), 1).status == Status::invalid_plane);
  CHECK(w.step(-0.1f).status == Status::invalid_time_step);
  CHECK(w.state_hash() == before);
  WorldDef2 bad;
  bad.sweep_axis = 2;
  World2<2, 1> w2(bad);
  CHECK(w2.construction_status() == Status::invalid_parameter);
  CHECK(w2.def().sweep_axis == 0);
}

TEST_CASE("a body dropped on the ground comes to rest at height r and falls asleep")
{
  World3<1, 1> w3;
  add_ground_and_spheres(w3, 0.25f);
  BodyDef3 b;
  b.position = Vector3(0.3f, -0.2f, 2);
  b.linear_velocity = Vector3(0.5f, 0, 0);
  REQUIRE(w3.add_body(b).ok());
  int steps = 0;
  while (w3.body(0).state != MotionState::asleep && steps < 60 * 10) {
    REQUIRE(w3.step(1.0f / 60).ok());
    REQUIRE(w3.body(0).position.z() >= 0.25f - 1e-5f);
    ++steps;
  }
  CHECK(w3.body(0).state == MotionState::asleep);
  CHECK(w3.body(0).position.z() == doctest::Approx(0.25).epsilon(1e-4));
  CHECK(w3.body(0).linear_velocity.norm() == 0);
  // Asleep means asleep: more steps change nothing.
  const Vector3 rest = w3.body(0).position;
  for (int i = 0; i < 100; ++i) REQUIRE(w3.step(1.0f / 60).status == Status::ok);
  CHECK(w3.body(0).position == rest);

  World2<1, 1> w2;
  add_ground_and_spheres(w2, 0.25f, 0, -1);
  BodyDef2 b2;
  b2.position = Vector2(0, 3);
  b2.angular_velocity = 2;
  REQUIRE(w2.add_body(b2).ok());
  for (int i = 0; i < 60 * 10 && w2.body(0).state != MotionState::asleep; ++i)
    REQUIRE(w2.step(1.0f / 60).status == Status::ok);
  CHECK(w2.body(0).state == MotionState::asleep);
  CHECK(w2.body(0).position.y() == doctest::Approx(-0.75).epsilon(1e-4));
}

TEST_CASE("a fast body hitting a sleeper wakes it - a slow one rests on it")
{
  // A sleeping sphere of radius 0.5 m on the ground; another falls on it from above, at 3 m/s or
  // at under 0.4 m/s (wake_speed is 0.5 m/s). Bodies sleep on their own here: by islands, any
  // approach joins the sleeper (tests/test_sleep_islands.cpp).
  WorldDef3 alone;
  alone.sleep_islands = false;
  for (const bool fast : {true, false}) {
    CAPTURE(fast);
    World3<2, 1> w(alone);
    add_ground_and_spheres(w, 0.5f);
    BodyDef3 sleeper;
    sleeper.position = Vector3(0, 0, 0.5f);
    sleeper.asleep = true;
    REQUIRE(w.add_body(sleeper).ok());
    BodyDef3 faller;
    faller.position = fast ? Vector3(0.3f, 0, 1.6f) : Vector3(0, 0, 1.501f);
    faller.linear_velocity = Vector3(0, 0, fast ? -3.0f : -0.2f);
    REQUIRE(w.add_body(faller).ok());
    if (fast) {
      for (int i = 0; i < 10; ++i) REQUIRE(w.step(1.0f / 60).ok());
      CHECK(w.body(0).state != MotionState::asleep);
      continue;
    }
    // The slow one: the sleeper stays asleep where it is, a static support, and the faller
    // comes to rest on top of it (centres one diameter apart, up to the contact slop) and falls
    // asleep there.
    for (int i = 0; i < 60 * 5 && w.body(1).state != MotionState::asleep; ++i) {
      REQUIRE(w.step(1.0f / 60).ok());
      REQUIRE(w.body(0).state == MotionState::asleep);
      REQUIRE(w.body(0).position == sleeper.position);
    }
    CHECK(w.body(1).state == MotionState::asleep);
    CHECK(w.body(1).position.z() == doctest::Approx(1.5).epsilon(0.01));
    CHECK(Vector2(w.body(1).position.x(), w.body(1).position.y()).norm() < 1e-3f);
  }
}

TEST_CASE("two worlds with the same seed stay bit-identical - another seed differs")
{
  // Statistical cubes: every impact draws its response from the body's random stream, so the
  // seed decides the trajectories. (Plain spheres draw nothing: only the streams' hashed states
  // would differ between seeds.) Same initial states in all three worlds.
  auto make = [](std::uint64_t seed) {
    WorldDef3 def;
    def.seed = seed;
    auto w = std::make_unique<World3<300>>(def);
    const ShapeId cube = w->add_shape(testing::cube_synthetic.view()).id;
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
    Pcg32 g(5, 0);
    for (int i = 0; i < 300; ++i) {
      BodyDef3 b;
      b.shape = cube;
      b.position = Vector3(g.uniform(-2, 2), g.uniform(-2, 2), g.uniform(0.3f, 3));
      b.linear_velocity = Vector3(g.uniform(-2, 2), g.uniform(-2, 2), g.uniform(-2, 2));
      REQUIRE(w->add_body(b).ok());
    }
    return w;
  };
  auto a = make(1), b = make(1), c = make(99);
  REQUIRE(testing::same_body_states(*a, *c));
  int first_difference = -1;
  for (int i = 0; i < 400; ++i) {
    REQUIRE(a->step(1.0f / 60).ok());
    REQUIRE(b->step(1.0f / 60).ok());
    REQUIRE(c->step(1.0f / 60).ok());
    REQUIRE(testing::same_body_states(*a, *b));
    REQUIRE(a->state_hash() == b->state_hash());
    if (first_difference < 0 && !testing::same_body_states(*a, *c)) first_difference = i;
  }
  MESSAGE("seeds 1 and 99: first different body states after step " << first_difference);
  CHECK(first_difference >= 0);  // the per-body random streams differ, and so do the trajectories
  CHECK_FALSE(testing::same_body_states(*a, *c));
  CHECK(a->count(MotionState::asleep) > 0);
}

TEST_CASE("a pile on the ground settles: nothing below the ground - most bodies asleep")
{
  auto w = std::make_unique<World3<300>>();
  fill_scene(*w, 300, 8);
  REQUIRE(w->add_plane(Vector3(1, 0, 0), -1.2f).ok());
  REQUIRE(w->add_plane(Vector3(-1, 0, 0), -1.2f).ok());
  REQUIRE(w->add_plane(Vector3(0, 1, 0), -1.2f).ok());
  REQUIRE(w->add_plane(Vector3(0, -1, 0), -1.2f).ok());
  for (int i = 0; i < 60 * 15; ++i) REQUIRE(w->step(1.0f / 60).ok());
  for (std::uint32_t i = 0; i < w->body_count(); ++i) {
    REQUIRE(std::isfinite(w->body(i).position.z()));
    REQUIRE(w->body(i).position.z() >= 0.1f - 1e-4f);
  }
  CHECK(w->count(MotionState::asleep) > 150);
}
