// WorldDef::sleep_islands: touching bodies fall asleep together, once all of them are still, and a
// moving body wakes a sleeper it touches at any approach speed; a body that never comes to rest
// holds its neighbours awake for a bounded time only.
#include <doctest/doctest.h>

#include "statsim/snapshot.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/square2d.hpp"

#include <memory>
#include <vector>

using namespace statsim;

namespace {

using IslandWorld = World3<8>;

/// A world with the ground and one shape, a ball of 0.1 m.
std::unique_ptr<IslandWorld> ball_world(bool islands)
{
  WorldDef3 def;
  def.sleep_islands = islands;
  auto w = std::make_unique<IslandWorld>(def);
  ShapeDef ball;
  ball.radius = 0.1f;
  REQUIRE(w->add_shape(ball).ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  return w;
}

/// A ball at rest on the ground and a second one on top of it, thrown up by `hop` m/s: the lower
/// one is still from the first step, the upper one only after it lands again.
std::unique_ptr<IslandWorld> ball_on_ball(bool islands, Scalar hop, BodyId& lower, BodyId& upper)
{
  auto w = ball_world(islands);
  BodyDef3 bd;
  bd.shape = ShapeId(0);
  bd.position = Vector3(0, 0, 0.1f);
  lower = w->add_body(bd).id;
  bd.position = Vector3(0, 0, 0.3f);
  bd.linear_velocity = Vector3(0, 0, hop);
  upper = w->add_body(bd).id;
  return w;
}

/// Steps until both bodies sleep; returns the step in which each fell asleep (-1: not within 600).
std::vector<int> sleep_steps(IslandWorld& w, BodyId a, BodyId b)
{
  std::vector<int> at{-1, -1};
  for (int i = 0; i < 600 && (at[0] < 0 || at[1] < 0); ++i) {
    REQUIRE(w.step(1.0f / 60).ok());
    if (at[0] < 0 && w.body(a).state == MotionState::asleep) at[0] = i;
    if (at[1] < 0 && w.body(b).state == MotionState::asleep) at[1] = i;
  }
  return at;
}

/// A ball asleep on the ground and, overlapping it by 1 mm at its side, an awake one moving at `v`.
std::unique_ptr<IslandWorld> beside_sleeper(bool islands, const Vector3& v, BodyId& sleeper, BodyId& other)
{
  auto w = ball_world(islands);
  BodyDef3 bd;
  bd.shape = ShapeId(0);
  bd.position = Vector3(0, 0, 0.1f);
  bd.asleep = true;
  sleeper = w->add_body(bd).id;
  bd.asleep = false;
  bd.position = Vector3(0.199f, 0, 0.1f);
  bd.linear_velocity = v;
  other = w->add_body(bd).id;
  return w;
}

}  // namespace

TEST_CASE("sleep islands: a still body waits for the body on it, and they fall asleep in the same step")
{
  BodyId lower, upper;
  auto alone = ball_on_ball(false, 0.6f, lower, upper);
  const std::vector<int> apart = sleep_steps(*alone, lower, upper);
  REQUIRE(apart[0] >= 0);
  REQUIRE(apart[1] >= 0);
  CHECK(apart[0] < apart[1]);  // each on its own: the lower one first

  auto together = ball_on_ball(true, 0.6f, lower, upper);
  const std::vector<int> island = sleep_steps(*together, lower, upper);
  REQUIRE(island[0] >= 0);
  CHECK(island[0] == island[1]);
  CHECK(island[1] == apart[1]);  // the upper one is not held back
  CHECK(together->body(upper).position.z() == doctest::Approx(0.3).epsilon(0.01));
}

TEST_CASE("sleep islands: a moving body wakes a sleeper it touches, however slowly it approaches")
{
  for (bool islands : {false, true}) {
    CAPTURE(islands);
    BodyId sleeper, mover;
    // Passing along it at 1 m/s: no approach along the line of centres.
    auto w = beside_sleeper(islands, Vector3(0, 1, 0), sleeper, mover);
    REQUIRE(w->step(1.0f / 60).ok());
    CHECK(w->body(mover).state != MotionState::asleep);
    CHECK((w->body(sleeper).state != MotionState::asleep) == islands);
  }
}

TEST_CASE("sleep islands: a body at rest beside a sleeper leaves it asleep")
{
  BodyId sleeper, still;
  auto w = beside_sleeper(true, Vector3::Zero(), sleeper, still);
  const Vector3 at = w->body(sleeper).position;
  int awake_late = 0;
  for (int i = 0; i < 240; ++i) {
    REQUIRE(w->step(1.0f / 60).ok());
    if (i >= 120) awake_late += w->body(sleeper).state != MotionState::asleep;
  }
  CHECK(awake_late == 0);
  CHECK(w->body(still).state == MotionState::asleep);
  CHECK((w->body(sleeper).position - at).norm() < 1e-3f);
}

TEST_CASE("sleep islands: a pile of statistical bodies comes to rest, in 3D and 2D, and a snapshot keeps the option")
{
  WorldDef3 d3;
  d3.sleep_islands = true;
  d3.body_contacts = BodyContacts::hulls;
  auto w3 = std::make_unique<World3<64>>(d3);
  const ShapeId s3 = w3->add_shape(tables::box.view()).id;
  REQUIRE(w3->add_plane(Vector3(0, 0, 1), 0).ok());
  WorldDef2 d2;
  d2.sleep_islands = true;
  auto w2 = std::make_unique<World2<64>>(d2);
  const ShapeId s2 = w2->add_shape(tables::square2d.view()).id;
  REQUIRE(w2->add_plane(Vector2(0, 1), 0).ok());
  Pcg32 g(11, 3);
  for (int i = 0; i < 40; ++i) {
    BodyDef3 b3;
    b3.shape = s3;
    b3.position = Vector3(Scalar(i % 4) * 0.3f, Scalar((i / 4) % 2) * 0.3f, 0.5f + Scalar(i / 8) * 0.35f);
    b3.orientation = random_orientation<3>(g);
    REQUIRE(w3->add_body(b3).ok());
    BodyDef2 b2;
    b2.shape = s2;
    b2.position = Vector2(Scalar(i % 5) * 1.6f, 1 + Scalar(i / 5) * 1.6f);  // unit squares
    b2.orientation = random_orientation<2>(g);
    REQUIRE(w2->add_body(b2).ok());
  }
  int steps3 = -1, steps2 = -1;
  for (int i = 0; i < 3000 && (steps3 < 0 || steps2 < 0); ++i) {
    if (steps3 < 0) {
      REQUIRE(w3->step(1.0f / 60).ok());
      if (w3->count(MotionState::asleep) == 40) steps3 = i;
    }
    if (steps2 < 0) {
      REQUIRE(w2->step(1.0f / 60).ok());
      if (w2->count(MotionState::asleep) == 40) steps2 = i;
    }
  }
  CHECK(steps3 > 0);
  CHECK(steps2 > 0);

  std::vector<unsigned char> buf(snapshot_size(*w3));
  std::size_t n = 0;
  REQUIRE(save(*w3, buf.data(), buf.size(), &n) == Status::ok);
  auto loaded = std::make_unique<World3<64>>();
  REQUIRE(loaded->add_shape(tables::box.view()).ok());
  REQUIRE(load(*loaded, buf.data(), n) == Status::ok);
  CHECK(loaded->def().sleep_islands);
}
