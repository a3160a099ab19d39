#include <doctest/doctest.h>

#include "scenes/drop_pattern.hpp"
#include "scenes/synthetic_signatures.hpp"
#include "support/world_states.hpp"

#include "statsim/random.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"
#include "tables/lshape2d.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace statsim;
using statsim::testing::cube_synthetic;
using statsim::testing::square2d_synthetic;

TEST_CASE("statistical shapes: a malformed signature is rejected")
{
  World2<4> w;
  SignatureView<2> bad = square2d_synthetic.view();
  bad.response.axis_count = 2;  // a with-speed 2D table has 3 axes
  CHECK(w.add_shape(bad).status == Status::invalid_shape);
  bad = square2d_synthetic.view();
  bad.length = 0;
  CHECK(w.add_shape(bad).status == Status::invalid_radius);
  CHECK(w.shape_count() == 0);
  const Added<ShapeId> ok = w.add_shape(square2d_synthetic.view());
  CHECK(ok.ok());
  // The broad phase gets a radius that holds every collision radius the body can take.
  CHECK(w.shape(ok.id).bounding_radius >= 0.70f);
}

TEST_CASE("statistical squares dropped on the ground rest face down at height 0.5")
{
  auto w = std::make_unique<World2<64>>();
  const ShapeId square = w->add_shape(square2d_synthetic.view()).id;
  REQUIRE(w->add_plane(Vector2(0, 1), 0).ok());
  Pcg32 g(3, 0);
  for (int i = 0; i < 40; ++i) {
    BodyDef2 b;
    b.shape = square;
    b.position = Vector2(3.0f * float(i), g.uniform(1, 4));  // far apart: ground contacts only
    b.orientation = Rot2::from_angle(g.uniform(-3.14f, 3.14f));
    b.linear_velocity = Vector2(g.uniform(-2, 2), g.uniform(-2, 0));
    b.angular_velocity = g.uniform(-6, 6);
    REQUIRE(w->add_body(b).ok());
  }
  int poses[4] = {};
  for (int i = 0; i < 60 * 30 && w->count(MotionState::asleep) < w->body_count(); ++i) REQUIRE(w->step(1.0f / 60).ok());
  CHECK(w->count(MotionState::asleep) == w->body_count());
  for (std::uint32_t i = 0; i < w->body_count(); ++i) {
    const Body2& b = w->body(i);
    REQUIRE(b.rest_pose < 4);
    ++poses[b.rest_pose];
    // Resting conditions: the pose's normal points up and the centre sits at h_rest.
    const Vector2 up = b.orientation * square2d_synthetic.view().rest.normal(b.rest_pose);
    CHECK(up.y() > std::cos(1.0f * 3.14159265f / 180));
    CHECK(b.position.y() == doctest::Approx(0.5).epsilon(0.01));
  }
  for (int p : poses) CHECK(p > 0);  // random drops reach every side
}

TEST_CASE("pile rest - a square settled on another square blends to the mean rest height only when asked")
{
  // Square 1 falls on square 0, which rests on the ground: with pile_rest off it keeps its h_coll
  // sphere (over 0.6 m for a unit square at low spin), with pile_rest on it blends to the table's
  // frequency-weighted mean rest height (0.5 m: all four sides rest at 0.5 m).
  for (const bool pile_rest : {false, true}) {
    CAPTURE(pile_rest);
    WorldDef2 def;
    def.pile_rest = pile_rest;
    auto w = std::make_unique<World2<8>>(def);
    const ShapeId square = w->add_shape(square2d_synthetic.view()).id;
    REQUIRE(w->add_plane(Vector2(0, 1), 0).ok());
    BodyDef2 b;
    b.shape = square;
    b.position = Vector2(0, 0.6f);
    REQUIRE(w->add_body(b).ok());
    b.position = Vector2(0, 2.5f);
    REQUIRE(w->add_body(b).ok());
    for (int i = 0; i < 60 * 20 && w->count(MotionState::asleep) < 2; ++i) REQUIRE(w->step(1.0f / 60).ok());
    REQUIRE(w->count(MotionState::asleep) == 2);
    const Body2& top = w->body(1);
    CHECK(top.rest_pose == no_rest_pose);
    CHECK(top.pile_rest == pile_rest);
    if (pile_rest) {
      CHECK(top.radius == doctest::Approx(0.5).epsilon(0.01));
      // It rests on the lower body's sphere: 0.5 m of ground sphere plus the two radii.
      CHECK(top.position.y() < 0.5f + 0.5f + 0.5f + 0.02f);
    } else {
      CHECK(top.radius > 0.6f);
    }
  }
}

TEST_CASE("statistical cubes rest on a face at half the side - with resting conditions only")
{
  for (bool rest : {true, false}) {
    WorldDef3 def;
    def.rest_conditions = rest;
    auto w = std::make_unique<World3<32>>(def);
    const ShapeId cube = w->add_shape(cube_synthetic.view()).id;
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
    Pcg32 g(4, 0);
    for (int i = 0; i < 20; ++i) {
      BodyDef3 b;
      b.shape = cube;
      b.position = Vector3(float(i), 0, g.uniform(0.5f, 2));
      const Vector3 axis(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1));
      b.orientation = Quaternion(Eigen::AngleAxisf(g.uniform(0, 3.14f), axis.normalized()));
      b.angular_velocity = Vector3(g.uniform(-5, 5), g.uniform(-5, 5), g.uniform(-5, 5));
      REQUIRE(w->add_body(b).ok());
    }
    for (int i = 0; i < 60 * 30 && w->count(MotionState::asleep) < w->body_count(); ++i)
      REQUIRE(w->step(1.0f / 60).status == Status::ok);
    int face_down = 0;
    for (std::uint32_t i = 0; i < w->body_count(); ++i) {
      const Body3& b = w->body(i);
      CHECK(b.state == MotionState::asleep);
      bool on_face = false;
      for (std::uint32_t p = 0; p < 6; ++p)
        on_face = on_face || (b.orientation * cube_synthetic.view().rest.normal(p)).z() > std::cos(0.0175f);
      face_down += on_face && std::fabs(b.position.z() - 0.1f) < 0.001f;
    }
    if (rest) CHECK(face_down == 20);
    else CHECK(face_down < 20);  // without resting conditions bodies stop in arbitrary poses
  }
}

namespace {
/// A uniformly random orientation: a normalised 4D Gaussian.
Quaternion random_orientation(Pcg32& g)
{
  float a, b, c, d;
  g.gaussian_pair(a, b);
  g.gaussian_pair(c, d);
  return Quaternion(a, b, c, d).normalized();
}

/// Adds `sig` and the ground plane z = 0 to the empty world `w`, drops `n` bodies of that shape
/// from random heights with random orientations and spins, 6 m apart so that each falls alone
/// (checked: no two ever come near), and steps until all sleep or 30 simulated seconds pass.
void drop_apart(WorldCore3& w, const SignatureView<3>& sig, int n, std::uint64_t seed)
{
  const Added<ShapeId> shape = w.add_shape(sig);
  REQUIRE(shape.ok());
  REQUIRE(w.add_plane(Vector3(0, 0, 1), 0).ok());
  Pcg32 g(seed, 3);
  for (int i = 0; i < n; ++i) {
    BodyDef3 b;
    b.shape = shape.id;
    const float z = g.uniform(0.3f, 1.5f);
    b.position = Vector3(6.0f * float(i % 32), 6.0f * float(i / 32), z);
    b.orientation = random_orientation(g);
    const float wx = g.uniform(-10, 10), wy = g.uniform(-10, 10), wz = g.uniform(-10, 10);
    b.angular_velocity = Vector3(wx, wy, wz);
    REQUIRE(w.add_body(b).ok());
  }
  for (int s = 0; s < 60 * 30 && w.count(MotionState::asleep) < w.body_count(); ++s) {
    REQUIRE(w.step(1.0f / 60).ok());
    REQUIRE(w.pair_count() == 0);  // independent drops: no two bounding spheres ever overlap
  }
}

/// Angle between a body's nearest rest pose (by angle alone) and up, in degrees.
float degrees_from_rest(const SignatureView<3>& sig, const Body3& b)
{
  const std::uint32_t p = nearest_rest_pose<3>(sig, b.orientation, Vector3(0, 0, 1));
  const float c = (b.orientation * sig.rest.normal(p)).z();
  return std::acos(std::min(1.0f, c)) * 57.2957795f;
}
}  // namespace

TEST_CASE("1000 single bunny drops end in the table's rest poses - total variation at most 0.10")
{
  const SignatureView<3> sig = tables::bunny.view();
  auto w = std::make_unique<World3<1000>>();
  drop_apart(*w, sig, 1000, 5);
  REQUIRE(w->count(MotionState::asleep) == 1000);
  std::uint32_t hits[max_rest_poses] = {};
  for (std::uint32_t i = 0; i < w->body_count(); ++i) {
    REQUIRE(w->body(i).rest_pose < sig.rest.count);
    ++hits[w->body(i).rest_pose];
  }
  // The table keeps poses seen in more than 5% of its drops; its frequencies are compared as
  // shares of the kept ones.
  float total = 0, tv = 0;
  for (std::uint32_t p = 0; p < sig.rest.count; ++p) total += sig.rest.frequencies[p];
  for (std::uint32_t p = 0; p < sig.rest.count; ++p) {
    const float share = float(hits[p]) / 1000, expected = sig.rest.frequencies[p] / total;
    MESSAGE("pose " << p << ": " << share << " (table " << expected << ")");
    tv += std::fabs(share - expected) / 2;
  }
  MESSAGE("total variation distance " << tv);
  CHECK(tv <= 0.10f);
}

TEST_CASE("bunny resting conditions off vs on - in a pose at h_rest only with them")
{
  const SignatureView<3> sig = tables::bunny.view();
  for (bool rest : {true, false}) {
    WorldDef3 def;
    def.rest_conditions = rest;
    auto w = std::make_unique<World3<100>>(def);
    drop_apart(*w, sig, 100, 8);
    CHECK(w->count(MotionState::asleep) == 100);
    int in_pose = 0, at_height = 0;
    float worst_angle = 0, worst_height = 0;
    for (std::uint32_t i = 0; i < w->body_count(); ++i) {
      const Body3& b = w->body(i);
      const float angle = degrees_from_rest(sig, b);
      const std::uint32_t p = nearest_rest_pose<3>(sig, b.orientation, Vector3(0, 0, 1));
      const float height = std::fabs(b.position.z() - sig.rest.heights[p]) / sig.rest.heights[p];
      worst_angle = std::max(worst_angle, angle);
      worst_height = std::max(worst_height, height);
      in_pose += angle <= 5;
      at_height += height <= 0.01f;
    }
    MESSAGE(std::string(rest ? "with" : "without") << " resting conditions: " << in_pose << " of 100 within 5 degrees of a rest pose (worst "
                                        << worst_angle << "), " << at_height << " within 1% of its h_rest (worst "
                                        << 100 * worst_height << "%)");
    if (rest) {
      CHECK(in_pose == 100);
      CHECK(at_height == 100);
    } else {
      // Without them a bunny stops in whatever orientation it has, on its collision sphere.
      CHECK(in_pose < 50);
      CHECK(at_height == 0);
    }
  }
}

TEST_CASE("slow contacts of statistical bodies bounce down to the table's threshold - and the bodies still sleep")
{
  // Bunnies 6 m apart land at 0.3 m/s (0.46 m/s once the step's gravity is added): above the
  // table's threshold (0.02 m/s, as gathered), below the world's (0.5 m/s). With the table's
  // threshold the landing is a collision, sampled from the table; with the world's it is
  // inelastic and nothing leaves the ground. Either way every body comes to rest.
  const SignatureView<3> sig = tables::bunny.view();
  REQUIRE(sig.restitution_threshold < 0.1f);
  for (const bool table : {true, false}) {
    CAPTURE(table);
    WorldDef3 def;
    def.table_restitution_threshold = table;
    auto w = std::make_unique<World3<32>>(def);
    const ShapeId shape = w->add_shape(sig).id;
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
    Pcg32 g(16, 4);
    const int n = 20;
    for (int i = 0; i < n; ++i) {
      BodyDef3 b;
      b.shape = shape;
      b.orientation = random_orientation(g);
      b.linear_velocity = Vector3(0, 0, -0.3f);
      // Touching the ground after one step: the centre falls 0.46 / 60 m.
      b.position = Vector3(6.0f * float(i), 0, collision_radius<3>(sig, b.linear_velocity, Vector3::Zero()) + 0.002f);
      REQUIRE(w->add_body(b).ok());
    }
    REQUIRE(w->step(1.0f / 60).ok());
    int rising = 0;
    for (std::uint32_t i = 0; i < w->body_count(); ++i) {
      CHECK(w->body(i).touching);
      rising += w->body(i).linear_velocity.z() > 0.05f;
    }
    MESSAGE("table threshold " << table << ": " << w->statistical_response_count() << " sampled responses, "
                               << rising << " of " << n << " leave the ground");
    if (table) {
      CHECK(w->statistical_response_count() == std::uint64_t(n));
      CHECK(rising >= n / 2);
    } else {
      CHECK(w->statistical_response_count() == 0);
      CHECK(rising == 0);
    }
    for (int s = 0; s < 60 * 10 && w->count(MotionState::asleep) < w->body_count(); ++s) REQUIRE(w->step(1.0f / 60).ok());
    CHECK(w->count(MotionState::asleep) == w->body_count());
    for (std::uint32_t i = 0; i < w->body_count(); ++i) {
      const Body3& b = w->body(i);
      REQUIRE(b.rest_pose < sig.rest.count);
      CHECK(b.position.z() == doctest::Approx(sig.rest.heights[b.rest_pose]).epsilon(0.01));
    }
  }
}

TEST_CASE("cubes with the gathered box table rest face down at half the side")
{
  const SignatureView<3> sig = tables::box.view();
  auto w = std::make_unique<World3<40>>();
  drop_apart(*w, sig, 40, 11);
  CHECK(w->count(MotionState::asleep) == 40);
  int poses[6] = {};
  for (std::uint32_t i = 0; i < w->body_count(); ++i) {
    const Body3& b = w->body(i);
    REQUIRE(b.rest_pose < 6);
    ++poses[b.rest_pose];
    // Face down: one of the cube's body axes points straight down (within 1 degree), whatever
    // the table says its poses are.
    const Eigen::Matrix3f r = b.orientation.toRotationMatrix();
    float lowest = 0;
    for (int k = 0; k < 3; ++k) lowest = std::min({lowest, r(2, k), -r(2, k)});
    CHECK(lowest < -std::cos(0.0175f));
    CHECK(b.position.z() == doctest::Approx(0.1).epsilon(0.01));  // half the 0.2 m side
  }
  int used = 0;
  for (int p : poses) used += p > 0;
  CHECK(used >= 5);  // random drops reach (nearly) every face
}

// A box tilted 30 degrees about y onto the edge at body (+a, -a) and let go there, alone or
// with a second box 0.3 m away (near enough to be a candidate pair, too far to touch): the
// horizontal distance its centre moves (m) by the time it sleeps, and its last rest pose.
// A box (the committed table) on level ground as `d` places it (its shape set here), with
// another box resting 0.3 m away when `neighbour`: the two are a candidate pair.
static std::unique_ptr<World3<4>> box_on_ground(BodyDef3 d, bool neighbour, BodyId& id)
{
  auto w = std::make_unique<World3<4>>();
  d.shape = w->add_shape(tables::box.view()).id;
  REQUIRE(w->add_plane(Vector3::UnitZ(), 0).ok());
  id = w->add_body(d).id;
  if (neighbour) {
    BodyDef3 n;
    n.shape = d.shape;
    n.position = Vector3(0, 0.3f, 0.1f);
    REQUIRE(w->add_body(n).ok());
  }
  return w;
}

static Scalar tip_from_edge(bool neighbour, std::uint8_t& pose)
{
  BodyDef3 d;
  d.orientation = Quaternion(Eigen::AngleAxisf(0.5236f, Vector3::UnitY()));
  d.position = Vector3(0, 0, 0.14f);  // the edge stands 0.137 m below the centre
  BodyId tipping;
  auto w = box_on_ground(d, neighbour, tipping);
  for (int k = 0; k < 240; ++k) REQUIRE(w->step(1.0f / 60).ok());
  const Body3& b = w->body(tipping);
  CHECK(b.state == MotionState::asleep);
  pose = b.rest_pose;
  return b.position.x();
}

TEST_CASE("a lone body's rest turn pivots about the edge it stands on; near another body about its centre")
{
  // Falling flat about that edge (at x = a (cos 30 - sin 30) = +0.037 m) takes the centre to a
  // = 0.1 m on the other side of it, x = -0.063 m; a turn about the centre leaves it at x = 0.
  std::uint8_t alone_pose = no_rest_pose, near_pose = no_rest_pose;
  const Scalar alone = tip_from_edge(false, alone_pose);
  const Scalar near = tip_from_edge(true, near_pose);
  MESSAGE("centre moved along x: alone " << alone << " m, near another body " << near << " m");
  CHECK(alone_pose == near_pose);  // the same face down either way
  CHECK(alone < -0.04f);
  CHECK(alone > -0.08f);
  CHECK(std::fabs(near) < 0.01f);
}

// A box let go corner-down on the ground (its hull's support 0.173 m below the centre, above its
// collision radius), sliding at `speed`: the highest its centre gets over a second, less where it
// was after the first step.
static Scalar rise_corner_down(bool neighbour, Scalar speed)
{
  BodyDef3 d;
  d.orientation = Quaternion::FromTwoVectors(Vector3(1, 1, 1).normalized(), Vector3(0, 0, -1));
  d.position = Vector3(0, 0, 0.12f);
  d.linear_velocity = Vector3(speed, 0, 0);
  BodyId box;
  auto w = box_on_ground(d, neighbour, box);
  REQUIRE(w->step(1.0f / 60).ok());
  const Scalar start = w->body(box).position.z();
  Scalar top = start;
  for (int k = 0; k < 60; ++k) {
    REQUIRE(w->step(1.0f / 60).ok());
    top = std::max(top, w->body(box).position.z());
  }
  return top - start;
}

TEST_CASE("a lone body starting to settle on the ground is held no higher than its kinetic energy lifts it")
{
  // e / g: 0.05 m/s lifts 0.13 mm, 1 m/s 5.1 cm (more than the 2 to 3 cm from the collision
  // radius to the corner); the rest turn's own spin, up to the settle speed at the farthest
  // point, adds a few millimetres. Held whole, the centre rises the full 2 to 3 cm.
  const Scalar slow = rise_corner_down(false, 0.05f), fast = rise_corner_down(false, 1.0f);
  const Scalar near = rise_corner_down(true, 0.05f);
  MESSAGE("rise of the centre: alone at 0.05 m/s " << slow << " m, at 1 m/s " << fast << " m; near another body "
                                                   << near << " m");
  CHECK(slow < 0.01f);
  CHECK(fast > 0.01f);
  CHECK(near > 0.01f);  // propped bodies are held at their hull's support, as before
}

TEST_CASE("a flight is the exact parabola at any step (3D and 2D)")
{
  // x + (v + v') dt / 2 under constant gravity: semi-implicit Euler's x + v' dt would lie
  // g t dt / 2 lower, 4 cm after a second at 60 Hz.
  const float dt = 1.0f / 60, g = 9.81f;
  auto w3 = std::make_unique<World3<1>>();
  ShapeDef ball;
  const ShapeId s3 = w3->add_shape(ball).id;
  BodyDef3 b3;
  b3.shape = s3;
  b3.position = Vector3(0, 0, 10);
  b3.linear_velocity = Vector3(1, 0, 3);
  const BodyId id3 = w3->add_body(b3).id;
  auto w2 = std::make_unique<World2<1>>();
  const ShapeId s2 = w2->add_shape(ball).id;
  BodyDef2 b2;
  b2.shape = s2;
  b2.position = Vector2(0, 10);
  b2.linear_velocity = Vector2(1, 3);
  const BodyId id2 = w2->add_body(b2).id;
  for (int k = 1; k <= 60; ++k) {
    REQUIRE(w3->step(dt).ok());
    REQUIRE(w2->step(dt).ok());
    const float t = float(k) * dt, z = 10 + 3 * t - g * t * t / 2;
    CHECK(std::fabs(w3->body(id3).position.z() - z) < 1e-4f);
    CHECK(std::fabs(w3->body(id3).position.x() - t) < 1e-4f);
    CHECK(std::fabs(w2->body(id2).position.y() - z) < 1e-4f);
  }
}

TEST_CASE("a statistical impact is looked up at the velocity the body crossed the ground with, at any phase of the step")
{
  // The cube's table without spread answers a fall straight down without spin deterministically:
  // V+ = (e + dv_z) |V-| up, e = 0.3 the restitution, dv_z = 0.05 the offset's mean. Released
  // from heights a step's fall apart, the cube crosses its collision radius at every phase of
  // the step; looked up at the step's end instead of the crossing, |V-| would be up to g dt
  // (0.16 m/s, 5% here) too large, by the phase.
  auto sig = cube_synthetic;
  for (Scalar& s : sig.response_spread) s = 0;
  const SignatureView<3> view = sig.view();
  const Scalar dt = 1.0f / 60, g = 9.81f, ratio = 0.35f;
  const Scalar radius = collision_radius<3>(view, Vector3(0, 0, -1), Vector3::Zero());
  Scalar lowest = 2, highest = 0;
  for (int k = 0; k < 16; ++k) {
    auto w = std::make_unique<World3<1>>();
    const ShapeId shape = w->add_shape(view).id;
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
    BodyDef3 b;
    b.shape = shape;
    b.position = Vector3(0, 0, 0.5f + 0.003f * Scalar(k));
    const BodyId id = w->add_body(b).id;
    int steps = 0;
    while (!(w->body(id).linear_velocity.z() > 0) && steps < 60) {
      REQUIRE(w->step(dt).ok());
      ++steps;
    }
    REQUIRE(w->statistical_response_count() == 1);
    const Scalar crossing = std::sqrt(2 * g * (b.position.z() - radius));
    const Scalar measured = w->body(id).linear_velocity.z() / (ratio * crossing);
    CAPTURE(k);
    CAPTURE(measured);
    lowest = std::min(lowest, measured);
    highest = std::max(highest, measured);
  }
  MESSAGE("rebound over the table's answer at the crossing speed, 16 phases: " << lowest << " to " << highest);
  CHECK(lowest > 0.995f);
  CHECK(highest < 1.005f);
}

TEST_CASE("a pile of 600 bunnies holds - sphere overlaps under 10% of the radius and none below the ground")
{
  // The paper's collision spheres between bodies: with hull contacts bodies overlap at their
  // spheres by design (tests/test_hull_contacts.cpp measures their hulls).
  WorldDef3 def;
  def.body_contacts = BodyContacts::collision_spheres;
  auto w = std::make_unique<World3<600, 8, 12000>>(def);  // a deep pile has up to 8 candidate pairs per body
  const ShapeId bunny = w->add_shape(tables::bunny.view()).id;
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  Pcg32 g(1, 0);
  // A column 0.8 m in radius, 10 m high: the pile is several bodies deep in the middle.
  for (int i = 0; i < 600; ++i) {
    BodyDef3 b;
    b.shape = bunny;
    const float x = g.uniform(-0.8f, 0.8f), y = g.uniform(-0.8f, 0.8f);
    if (x * x + y * y > 0.64f) {
      --i;
      continue;
    }
    const float z = 0.3f + float(i) / 60;
    b.position = Vector3(x, y, z);
    b.orientation = random_orientation(g);
    const float wx = g.uniform(-5, 5), wy = g.uniform(-5, 5), wz = g.uniform(-5, 5);
    b.angular_velocity = Vector3(wx, wy, wz);
    REQUIRE(w->add_body(b).ok());
  }
  for (int s = 0; s < 60 * 20 && w->count(MotionState::asleep) < w->body_count(); ++s) REQUIRE(w->step(1.0f / 60).ok());
  CHECK(w->count(MotionState::asleep) >= 540);
  float deepest = 0, lowest = 1;
  for (std::uint32_t i = 0; i < w->body_count(); ++i) {
    const Body3& a = w->body(i);
    lowest = std::min(lowest, a.position.z() - a.radius);
    for (std::uint32_t j = i + 1; j < w->body_count(); ++j) {
      const Body3& b = w->body(j);
      const float gap = (a.position - b.position).norm() - a.radius - b.radius;
      if (gap < 0) deepest = std::max(deepest, -gap / std::min(a.radius, b.radius));
    }
  }
  MESSAGE("asleep " << w->count(MotionState::asleep) << ", deepest overlap " << 100 * deepest << "% of the radius, lowest sphere bottom " << lowest << " m");
  CHECK(deepest < 0.10f);
  CHECK(lowest > -0.001f);
}

TEST_CASE("statistical bodies never end a step below the ground - at any speed up to 50 m/s")
{
  auto w = std::make_unique<World3<64>>();
  const ShapeId cube = w->add_shape(cube_synthetic.view()).id;
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  for (int i = 0; i < 50; ++i) {
    BodyDef3 b;
    b.shape = cube;
    b.position = Vector3(float(i), 0, 1);
    b.linear_velocity = Vector3(0.3f * float(i % 7), 0, -1.0f - float(i));
    b.angular_velocity = Vector3(0, float(i % 5), 0);
    REQUIRE(w->add_body(b).ok());
  }
  for (int s = 0; s < 240; ++s) {
    REQUIRE(w->step(1.0f / 60).ok());
    for (std::uint32_t i = 0; i < w->body_count(); ++i) {
      const Body3& b = w->body(i);
      REQUIRE(std::isfinite(b.position.z()));
      REQUIRE(b.position.z() >= b.radius - 1e-4f);
    }
  }
}

TEST_CASE("statistical worlds: same seed gives bit-identical steps - the energy guard is counted")
{
  auto make = [](std::uint64_t seed) {
    WorldDef3 def;
    def.seed = seed;
    auto w = std::make_unique<World3<200>>(def);
    const Added<ShapeId> cube = w->add_shape(cube_synthetic.view());
    REQUIRE(cube.ok());
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
    Pcg32 g(9, 0);
    for (int i = 0; i < 200; ++i) {
      BodyDef3 b;
      b.shape = cube.id;
      b.position = Vector3(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(0.3f, 4));
      b.angular_velocity = Vector3(g.uniform(-9, 9), g.uniform(-9, 9), g.uniform(-9, 9));
      REQUIRE(w->add_body(b).ok());
    }
    return w;
  };
  auto a = make(1), b = make(1), c = make(2);
  // Bit for bit: every position and orientation, not only the hash (which also covers the
  // random streams' states, different between seeds before any step).
  using testing::same_body_states;
  REQUIRE(same_body_states(*a, *c));  // the seeds differ, the initial states do not
  for (int i = 0; i < 300; ++i) {
    REQUIRE(a->step(1.0f / 60).ok());
    REQUIRE(b->step(1.0f / 60).ok());
    REQUIRE(c->step(1.0f / 60).ok());
    REQUIRE(same_body_states(*a, *b));
    REQUIRE(a->state_hash() == b->state_hash());
  }
  CHECK_FALSE(same_body_states(*a, *c));  // the other seed's draws give other trajectories
  CHECK(a->energy_clamp_count() > 0);  // spin std 0.5 L/|v| makes some samples too energetic
  CHECK(a->energy_clamp_count() == b->energy_clamp_count());
}

namespace {
statsim::World3<300> lshape_world;  // static storage: about 80 KB
}

TEST_CASE("L-shapes that keep a rest pose on top of others fall asleep")
{
  // 300 L-shapes dropped as examples/drop_lshapes drops them: one picks a rest pose on the
  // ground, is then held up by others and can no longer turn into it; it must sleep where it is.
  WorldDef3 def;
  def.seed = 1;
  REQUIRE(tools::scenes::drop_on_ground(lshape_world, def, tables::lshape.view(), {300, 0.4f, 0.3f, 0.012f}).ok());
  int steps = 0;
  while (steps < 1200 && lshape_world.count(MotionState::asleep) < 300) {
    REQUIRE(lshape_world.step(1.0f / 60).status == Status::ok);
    ++steps;
  }
  MESSAGE("all asleep after ", steps, " steps");
  CHECK(lshape_world.count(MotionState::asleep) == 300);
}

namespace {
/// Drops `n` bodies of table `sig` apart onto level ground, each alone, with `WorldDef::ground_hulls`
/// as `hulls`, and counts the steps that begin with a body on the ground and end with it awake
/// (`on_ground`), those of them that end with its hull in the ground (the centre below the hull's
/// support toward the ground by more than a thousandth of the bounding radius), those that end
/// with it settling on the ground without a rest pose, and the statistical responses of all
/// steps.
template <int D, class World>
void ground_steps(const SignatureView<D>& sig, int n, bool hulls, int& grounded, int& sunk, int& poseless,
                  std::uint64_t& responses)
{
  using Vec = typename Space<D>::Vec;
  constexpr int up = Space<D>::up_axis;
  WorldDef<D> def;
  def.ground_hulls = hulls;
  auto w = std::make_unique<World>(def);
  REQUIRE(w->construction_status() == Status::ok);
  const ShapeId shape = w->add_shape(sig).id;
  REQUIRE(w->add_plane(Vec::Unit(up), 0).ok());
  const Scalar bound = w->shape(shape).bounding_radius;
  Pcg32 g(19, 7);
  for (int i = 0; i < n; ++i) {
    BodyDef<D> b;
    b.shape = shape;
    b.position = Vec::Zero();
    b.position[0] = Scalar(6) * Scalar(i);
    b.position[up] = bound + g.uniform(0.1f, 0.6f);
    b.orientation = statsim::random_orientation<D>(g);
    REQUIRE(w->add_body(b).ok());
  }
  grounded = sunk = poseless = 0;
  responses = 0;
  std::vector<char> before(std::size_t(n), 0);
  for (int s = 0; s < 600; ++s) {
    for (int i = 0; i < n; ++i) before[std::size_t(i)] = w->body(std::uint32_t(i)).on_ground;
    const StepResult r = w->step(Scalar(1) / 60);
    REQUIRE(r.ok());
    responses += r.statistical_responses;
    for (int i = 0; i < n; ++i) {
      const Body<D>& b = w->body(std::uint32_t(i));
      if (!before[std::size_t(i)] || b.state == MotionState::asleep) continue;
      ++grounded;
      const Scalar support = detail::support_along(sig.contact, detail::to_body(b.orientation, Vec(-Vec::Unit(up))));
      sunk += b.position[up] < support - Scalar(1e-3) * bound;
      poseless += b.state == MotionState::settling && b.on_ground && b.rest_pose == no_rest_pose;
    }
  }
}
}  // namespace

TEST_CASE("ground hulls: after the first impact a body on level ground stands on its hull, not in it (3D and 2D)")
{
  // The first impact from flight is the table's response; with `WorldDef::ground_hulls` a body
  // that was on the ground as a step began meets it with its hull (`detail::ground_hull`), as a
  // rigid body tumbles over its edges, where its collision sphere lets its corners sink in. Once
  // settling (slower than the settle speed) it takes a rest pose, with the option as without.
  for (const bool hulls : {true, false}) {
    CAPTURE(hulls);
    int grounded = 0, sunk = 0, poseless = 0;
    std::uint64_t responses = 0;
    ground_steps<3, World3<32>>(tables::lshape.view(), 32, hulls, grounded, sunk, poseless, responses);
    MESSAGE("3D: " << grounded << " steps on the ground, " << sunk << " of them sunk, " << poseless
                   << " settling without a pose, " << responses << " responses");
    CHECK(grounded > 200);
    CHECK(responses >= 32);
    CHECK(poseless == 0);
    if (hulls) CHECK(sunk == 0);
    else CHECK(sunk > 20);  // the spheres' rule, which the option replaces
    ground_steps<2, World2<32>>(tables::lshape2d.view(), 32, hulls, grounded, sunk, poseless, responses);
    MESSAGE("2D: " << grounded << " steps on the ground, " << sunk << " of them sunk, " << poseless
                   << " settling without a pose, " << responses << " responses");
    CHECK(grounded > 200);
    CHECK(responses >= 32);
    CHECK(poseless == 0);
    if (hulls) CHECK(sunk == 0);
    else CHECK(sunk > 20);
  }
}

namespace {
/// Statistical responses of `n` bodies of table `sig` that fall onto level ground at random
/// orientations, without spin or horizontal speed, each alone, their hull's lowest point `drop` m
/// above the ground, at `speed` m/s downwards, in their first second, with
/// `WorldDef::ground_hulls` as `hulls`. Their hulls land at sqrt(speed^2 + 2 |g| drop).
std::uint64_t landing_responses(const SignatureView<3>& sig, int n, bool hulls, Scalar drop, Scalar speed)
{
  WorldDef3 def;
  def.ground_hulls = hulls;
  auto w = std::make_unique<World3<32>>(def);
  REQUIRE(w->construction_status() == Status::ok);
  const ShapeId shape = w->add_shape(sig).id;
  REQUIRE(w->add_plane(Vector3::UnitZ(), 0).ok());
  Pcg32 g(23, 5);
  for (int i = 0; i < n; ++i) {
    BodyDef3 b;
    b.shape = shape;
    b.orientation = random_orientation(g);
    const Scalar support = detail::support_along(sig.contact, detail::to_body(b.orientation, Vector3(-Vector3::UnitZ())));
    b.position = Vector3(Scalar(6) * Scalar(i), 0, support + drop);
    b.linear_velocity = Vector3(0, 0, -speed);
    REQUIRE(w->add_body(b).ok());
  }
  std::uint64_t responses = 0;
  for (int s = 0; s < 60; ++s) {
    const StepResult r = w->step(Scalar(1) / 60);
    REQUIRE(r.ok());
    responses += r.statistical_responses;
  }
  return responses;
}
}  // namespace

TEST_CASE("ground hulls: a landing slower than a hop's is the hull's, a faster one the table's, whatever the landing axis")
{
  // `detail::slow_landing`: below |v|^2 = F_h |g| L (F_h = `detail::hop_froude`, L the
  // signature's length) a body from flight meets level ground with its hull, as a hop's landing;
  // above it the table's response stands. The box's landing axis starts at F = 0.1, the
  // L-shape's at 1: the bound is the runtime's, not the table's first Froude sample.
  for (const SignatureView<3>& sig : {tables::lshape.view(), tables::box.view()}) {
    const std::string name = sig.name;
    CAPTURE(name);
    REQUIRE(sig.landing.present());
    const Scalar g = 9.81f, limit2 = detail::hop_froude * g * sig.length;
    // Slow: from rest, |v|^2 = 0.5 F_h |g| L at the ground, above the table's restitution
    // threshold, so that without the option a landing is a statistical collision (where the
    // collision sphere does not start on the ground: it may stand below or above the hull).
    const Scalar slow_drop = Scalar(0.25) * limit2 / g;
    REQUIRE(std::sqrt(2 * g * slow_drop) > 2 * g / 60);
    // Fast: |v|^2 = 3 F_h |g| L at the start, more at the ground.
    const Scalar fast_speed = std::sqrt(3 * limit2);
    const std::uint64_t slow_hulls = landing_responses(sig, 32, true, slow_drop, 0);
    const std::uint64_t slow_spheres = landing_responses(sig, 32, false, slow_drop, 0);
    const std::uint64_t fast_hulls = landing_responses(sig, 32, true, 0.05f, fast_speed);
    MESSAGE(name << ": statistical responses: slow with ground hulls " << slow_hulls << ", without "
                     << slow_spheres << "; fast with ground hulls " << fast_hulls);
    CHECK(slow_hulls == 0);
    CHECK(slow_spheres >= 24);
    CHECK(fast_hulls >= 32);
  }
}

namespace {
/// Drops `n` bodies of table `sig` onto level ground, each alone, at random orientations and
/// spins, from 0.1 to 0.6 m above their bounding radius, with `WorldDef::ground_hulls`, for 3 s.
/// Counts the impacts from flight faster than a hop's landing (`detail::slow_landing`: steps
/// that begin with a body off the ground at |v|^2 >= F_h |g| L and end with it on it, without a
/// rest pose), those that end with its centre more than a hundredth of its
/// bounding radius from its hull's support toward the ground (`off_hull`); and the steps that
/// begin with a body on the ground, without a rest pose, moving up as fast as a flight that
/// rises more than the table's `hop` L (`flights`), those of them in which it took more than
/// gravity (`braked`: its velocity's change off g dt by more than 0.1 mm/s).
void ground_impacts(const SignatureView<3>& sig, int n, int& impacts, int& off_hull, int& flights, int& braked)
{
  WorldDef3 def;
  def.ground_hulls = true;
  const Scalar dt = Scalar(1) / 60;
  auto w = std::make_unique<World3<32>>(def);
  REQUIRE(w->construction_status() == Status::ok);
  const ShapeId shape = w->add_shape(sig).id;
  REQUIRE(w->add_plane(Vector3::UnitZ(), 0).ok());
  const Scalar bound = w->shape(shape).bounding_radius;
  Pcg32 g(29, 3);
  for (int i = 0; i < n; ++i) {
    BodyDef3 b;
    b.shape = shape;
    b.position = Vector3(Scalar(6) * Scalar(i), 0, bound + g.uniform(0.1f, 0.6f));
    b.orientation = random_orientation(g);
    b.angular_velocity = Vector3(g.uniform(-5.f, 5.f), g.uniform(-5.f, 5.f), g.uniform(-5.f, 5.f));
    REQUIRE(w->add_body(b).ok());
  }
  const Scalar hop_speed2 = 2 * Scalar(9.81) * sig.landing.hop * sig.length;
  const Scalar fast2 = detail::hop_froude * Scalar(9.81) * sig.length;
  impacts = off_hull = flights = braked = 0;
  std::vector<char> ground(std::size_t(n), 0);
  std::vector<Vector3> v(static_cast<std::size_t>(n));
  for (int s = 0; s < 180; ++s) {
    for (int i = 0; i < n; ++i) {
      const Body3& b = w->body(std::uint32_t(i));
      ground[std::size_t(i)] = b.on_ground && b.rest_pose == no_rest_pose && b.state != MotionState::asleep;
      v[std::size_t(i)] = b.linear_velocity;
    }
    REQUIRE(w->step(dt).ok());
    for (int i = 0; i < n; ++i) {
      const Body3& b = w->body(std::uint32_t(i));
      const std::size_t k = std::size_t(i);
      if (!ground[k] && b.on_ground && b.rest_pose == no_rest_pose && b.state != MotionState::asleep &&
          v[k].squaredNorm() >= fast2) {
        ++impacts;
        const Scalar support = detail::support_along(sig.contact, detail::to_body(b.orientation, Vector3(-Vector3::UnitZ())));
        off_hull += std::fabs(b.position.z() - support) > Scalar(0.01) * bound;
      }
      if (ground[k] && v[k].z() > 0 && v[k].z() * v[k].z() > hop_speed2) {
        ++flights;
        braked += (b.linear_velocity - v[k] - Vector3(0, 0, Scalar(-9.81) * dt)).norm() > Scalar(1e-4);
      }
    }
  }
}
}  // namespace

TEST_CASE("ground hulls: a body meets level ground from flight at its hull's support, and the table's response sends it off")
{
  // With `WorldDef::ground_hulls` the impact from flight is taken where the hull touches
  // (`detail::ground_impact_on_hull`), not at the collision radius, from which the hull's contact
  // after it lifted the centre to its support or let it fall there; a body the response sends off
  // as a flight (`detail::leaves_ground`) flies, its hull's contact not taking the flight out.
  for (const SignatureView<3>& sig : {tables::lshape.view(), tables::box.view(), tables::bunny.view()}) {
    const std::string name = sig.name;
    CAPTURE(name);
    REQUIRE(sig.landing.present());
    int impacts = 0, off_hull = 0, flights = 0, braked = 0;
    ground_impacts(sig, 32, impacts, off_hull, flights, braked);
    MESSAGE(name << ": " << impacts << " impacts from flight, " << off_hull << " of them off the hull's support; "
                 << flights << " flights after a step on the ground, " << braked << " of them braked");
    CHECK(impacts >= 32);
    CHECK(off_hull == 0);
    CHECK(flights >= 8);
    CHECK(braked == 0);
  }
}

TEST_CASE("ground hulls: refused without Features::slopes, the world unchanged")
{
  WorldDef3 def;
  def.ground_hulls = true;
  auto w = std::make_unique<World3<4, 8, 24, 8, 0, BroadPhase::automatic, Features::piles>>(def);
  CHECK(w->construction_status() == Status::not_compiled);
  CHECK_FALSE(w->def().ground_hulls);  // it took the defaults
  const std::uint64_t before = w->state_hash();
  CHECK(w->configure(def) == Status::not_compiled);
  CHECK(w->state_hash() == before);
  auto all = std::make_unique<World3<4>>();
  CHECK(all->configure(def) == Status::ok);
  CHECK(all->def().ground_hulls);
}
