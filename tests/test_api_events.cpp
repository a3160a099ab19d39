// Impact events: what a step records (bodies, plane, point, normal, approach speed), the
// threshold, overflow of the buffer, and that recording leaves the simulation's bits alone.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/random.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"

#include <cmath>
#include <memory>

using namespace statsim;

TEST_CASE("a ball dropped on the ground records its impacts with the plane")
{
  auto w = std::make_unique<World3<4, 8, 24, 8, 4>>();
  ShapeDef ball;
  ball.radius = 0.1f;
  BodyDef3 bd;
  bd.shape = w->add_shape(ball).id;
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  bd.position = Vector3(0.5f, -0.25f, 2);
  const BodyId id = w->add_body(bd).id;
  CHECK(w->impact_capacity() == 4);
  int steps_with_impacts = 0;
  bool first = true;
  for (int i = 0; i < 300; ++i) {
    const float vz = w->body(id).linear_velocity.z() - 9.81f / 60;  // as it enters the contact
    const StepResult r = w->step(1.0f / 60);
    REQUIRE(r.ok());
    CHECK(r.impacts_found == w->impact_count());
    if (w->impact_count() == 0) continue;
    ++steps_with_impacts;
    REQUIRE(w->impact_count() == 1);
    const Impact<3>& e = w->impacts()[0];
    CHECK(e.a == id);
    CHECK(e.b == no_body);
    CHECK(e.plane == 0);
    CHECK(e.normal == Vector3(0, 0, 1));
    CHECK(e.approach_speed > WorldDef3{}.impact_threshold);
    CHECK(std::fabs(e.point.z()) < 1e-5f);
    CHECK(std::fabs(e.point.x() - w->body(id).position.x()) < 1e-4f);
    if (first) {
      // Dropped from 1.9 m above the contact: it arrives at about sqrt(2 g 1.9) = 6.1 m/s.
      CHECK(std::fabs(e.approach_speed + vz) < 1e-4f);
      CHECK(e.approach_speed > 5.5f);
      first = false;
    }
  }
  // The first impact and a few bounces (restitution 0.3), none once it rolls or rests.
  CHECK(steps_with_impacts >= 2);
  CHECK(steps_with_impacts <= 4);
  CHECK(w->impact_count() == 0);
}

TEST_CASE("two bodies meeting head on record one impact between them")
{
  WorldDef2 def;
  def.gravity = Vector2::Zero();
  auto w = std::make_unique<World2<4, 8, 24, 8, 4>>(def);
  ShapeDef small, large;
  small.radius = 0.1f;
  large.radius = 0.3f;
  BodyDef2 bd;
  bd.shape = w->add_shape(small).id;
  bd.position = Vector2(-1, 0);
  bd.linear_velocity = Vector2(2, 0);
  const BodyId a = w->add_body(bd).id;
  bd.shape = w->add_shape(large).id;
  bd.position = Vector2(1, 0);
  bd.linear_velocity = Vector2(-1, 0);
  const BodyId b = w->add_body(bd).id;
  int impacts = 0;
  for (int i = 0; i < 60; ++i) {
    REQUIRE(w->step(1.0f / 60).ok());
    for (std::uint32_t k = 0; k < w->impact_count(); ++k) {
      const Impact<2>& e = w->impacts()[k];
      ++impacts;
      CHECK(e.a == a);
      CHECK(e.b == b);
      CHECK(e.normal.isApprox(Vector2(1, 0)));
      CHECK(std::fabs(e.approach_speed - 3) < 1e-4f);
      // A quarter of the way from a's centre to b's (radii 0.1 and 0.3).
      const Vector2 pa = w->body(a).position, pb = w->body(b).position;
      CHECK(e.point.y() == 0);
      CHECK(e.point.x() > pa.x() - 0.2f);
      CHECK(e.point.x() < pb.x());
    }
  }
  CHECK(impacts == 1);
}

namespace {
/// 60 spheres and cubes dropped into a box; returns the state hash after `steps` steps and
/// counts the impacts and overflowing steps.
template <class W>
std::uint64_t drop_pile(W& w, int steps, std::uint32_t& impacts, int& overflows, bool hulls = false)
{
  WorldDef3 def;
  if (hulls) def.body_contacts = BodyContacts::hulls;
  REQUIRE(w.configure(def) == Status::ok);
  const ShapeId cube = w.add_shape(hulls ? tables::box.view() : testing::cube_synthetic.view()).id;
  ShapeDef ball;
  ball.radius = 0.12f;
  const ShapeId sphere = w.add_shape(ball).id;
  REQUIRE(w.add_plane(Vector3(0, 0, 1), 0).ok());
  REQUIRE(w.add_plane(Vector3(1, 0, 0), -1).ok());
  REQUIRE(w.add_plane(Vector3(-1, 0, 0), -1).ok());
  Pcg32 g(7, 3);
  for (int i = 0; i < 60; ++i) {
    BodyDef3 b;
    b.shape = i % 2 ? sphere : cube;
    const float x = g.uniform(-0.8f, 0.8f), y = g.uniform(-0.8f, 0.8f), z = g.uniform(0.3f, 3);
    b.position = Vector3(x, y, z);
    REQUIRE(w.add_body(b).ok());
  }
  impacts = 0;
  overflows = 0;
  for (int i = 0; i < steps; ++i) {
    const StepResult r = w.step(1.0f / 60);
    REQUIRE(r.status == Status::ok);
    CHECK(!(r.overflow & overflow_pairs));
    CHECK(r.impacts_found == w.impact_count() + r.impacts_dropped);
    CHECK(w.impact_count() <= w.impact_capacity());
    impacts += r.impacts_found;
    if (r.overflow & overflow_impacts) {
      ++overflows;
      CHECK(w.impact_count() == w.impact_capacity());
      CHECK(r.impacts_dropped > 0);
    }
  }
  return w.state_hash();
}
}  // namespace

TEST_CASE("recording impacts leaves the simulation's bits alone; a full buffer is reported")
{
  auto plain = std::make_unique<World3<60>>();
  auto small = std::make_unique<World3<60, 8, 360, 8, 2>>();
  auto large = std::make_unique<World3<60, 8, 360, 8, 256>>();
  std::uint32_t none = 0, few = 0, all = 0;
  int o_none = 0, o_few = 0, o_all = 0;
  const std::uint64_t h = drop_pile(*plain, 240, none, o_none);
  CHECK(drop_pile(*small, 240, few, o_few) == h);
  CHECK(drop_pile(*large, 240, all, o_all) == h);
  CHECK(none == 0);  // no buffer: nothing recorded, nothing reported
  CHECK(o_none == 0);
  CHECK(all > 60);   // every body lands at least once
  CHECK(few == all);
  CHECK(o_few > 0);
  CHECK(o_all == 0);

  // With hull contacts (the box table's body-body data), whose witnesses recording finds too.
  auto plain_hulls = std::make_unique<World3<60>>();
  auto small_hulls = std::make_unique<World3<60, 8, 360, 8, 2>>();
  const std::uint64_t hh = drop_pile(*plain_hulls, 240, none, o_none, true);
  CHECK(drop_pile(*small_hulls, 240, few, o_few, true) == hh);
  CHECK(hh != h);
  CHECK(few > 60);
}

TEST_CASE("the impact threshold is a world parameter")
{
  WorldDef3 def;
  def.impact_threshold = -1;
  auto w = std::make_unique<World3<4, 8, 24, 8, 4>>(def);
  CHECK(w->construction_status() == Status::invalid_parameter);
  def.impact_threshold = 100;
  REQUIRE(w->configure(def) == Status::ok);
  ShapeDef ball;
  BodyDef3 bd;
  bd.shape = w->add_shape(ball).id;
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  bd.position = Vector3(0, 0, 2);
  REQUIRE(w->add_body(bd).ok());
  for (int i = 0; i < 120; ++i) {
    REQUIRE(w->step(1.0f / 60).ok());
    CHECK(w->impact_count() == 0);  // it lands at 6 m/s, below 100
  }
}

TEST_CASE("a box tumbling down a slope records the strikes of its faces")
{
  // A body rolling on a slope moves through the step in substeps with its slope contacts
  // (statsim/detail/slope_contact.hpp), and the step's own recording leaves those contacts to them: the
  // strikes come from the substeps. A box resting on a face of 20 degrees, rolled about its
  // downhill edge fast enough to tumble over the next faces, strikes the plane with them.
  WorldDef3 def;
  def.impact_threshold = 0.3f;
  auto w = std::make_unique<World3<4, 8, 24, 8, 16>>(def);
  const SignatureView<3> sig = tables::box.view();
  const float a = 20 * 3.14159265f / 180;
  const Vector3 normal(0, std::sin(a), std::cos(a)), downhill(0, std::cos(a), -std::sin(a));
  const PlaneId plane = w->add_plane(normal, 0).id;
  BodyDef3 bd;
  bd.shape = w->add_shape(sig).id;
  const float half = sig.rest.heights[0];
  bd.orientation = snap_to_rest(Quaternion::Identity(), sig.rest.normal(0), normal);
  bd.angular_velocity = normal.cross(downhill) * 12.44f;
  bd.linear_velocity = bd.angular_velocity.cross(Vector3(normal * half - downhill * half));
  bd.position = normal * half;
  const BodyId id = w->add_body(bd).id;
  int strikes = 0;
  for (int i = 0; i < 120; ++i) {
    const StepResult r = w->step(1.0f / 60);
    REQUIRE(r.ok());
    CHECK(r.impacts_found == w->impact_count());
    for (std::uint32_t k = 0; k < w->impact_count(); ++k) {
      const Impact<3>& e = w->impacts()[k];
      CHECK(e.a == id);
      CHECK(e.b == no_body);
      CHECK(e.plane == plane);
      CHECK((e.normal - normal).norm() < 1e-6f);
      CHECK(e.approach_speed > 0.3f);
      CHECK(std::fabs(e.point.dot(normal)) < 1e-5f);  // the foot of the centre on the plane
      ++strikes;
    }
  }
  CHECK(strikes >= 1);
}
