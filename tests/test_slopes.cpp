// Statistical bodies on tilted planes meet them with their hulls (statsim/detail/slope_contact.hpp): with
// friction above the slope's tangent they come to rest and fall asleep in a rest pose against the
// plane; below it they keep going; a body rolled over an edge tumbles onto the next face as a
// rigid one does.
#include <doctest/doctest.h>

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/square2d.hpp"

#include <cmath>
#include <memory>

using namespace statsim;

namespace {
constexpr float kPi = 3.14159265f;
constexpr float kDt = 1.0f / 60;
constexpr int kBodies = 8;

/// A world of bodies dropped from rest, 0.4 m above a plane through the origin that falls along
/// +y at `degrees` (3D) or along +x (2D), spaced along the other horizontal axis (3D) or along the
/// slope (2D) so that they never touch each other.
template <int D>
struct Slope {
  using Vec = typename Space<D>::Vec;
  std::unique_ptr<World<D, kBodies>> w = std::make_unique<World<D, kBodies>>();
  Vec normal, downhill;

  Slope(const SignatureView<D>& sig, float degrees)
  {
    const float a = degrees * kPi / 180;
    const ShapeId shape = w->add_shape(sig).id;
    Pcg32 g(7, 1);
    if constexpr (D == 3) {
      normal = Vector3(0, std::sin(a), std::cos(a));
      downhill = Vector3(0, std::cos(a), -std::sin(a));
    } else {
      normal = Vector2(std::sin(a), std::cos(a));
      downhill = Vector2(std::cos(a), -std::sin(a));
    }
    REQUIRE(w->add_plane(normal, 0).ok());
    for (int i = 0; i < kBodies; ++i) {
      BodyDef<D> b;
      b.shape = shape;
      b.mass = sig.mass;
      if constexpr (D == 3) {
        b.position = Vector3(float(i), 0, 0.4f + sig.bounding_radius);
        const Vector3 axis = Vector3(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1)).normalized();
        b.orientation = Quaternion(Eigen::AngleAxisf(g.uniform(-kPi, kPi), axis));
      } else {
        // Along the slope, 3 m apart, each 0.4 m above it (vertically).
        const Vector2 on = downhill * (3.0f * float(i));
        b.position = Vector2(on.x(), on.y() + 0.4f + sig.bounding_radius / std::cos(a));
        b.orientation = Rot2::from_angle(g.uniform(-kPi, kPi));
      }
      REQUIRE(w->add_body(b).ok());
    }
  }
  void run(float seconds)
  {
    const int steps = int(std::lround(seconds / kDt));
    for (int k = 0; k < steps; ++k) REQUIRE(w->step(kDt).ok());
  }
  float along(std::uint32_t i) const { return w->body(i).position.dot(downhill); }
};

template <int D>
void rests_on_gentle_slope(const SignatureView<D>& sig)
{
  Slope<D> s(sig, 10);
  // Falling 0.4 m takes 0.29 s. A body that lands on a curved part of its hull may roll on for
  // seconds, as the reference's bunnies do (tools/stress/README.md, "Slopes"); within 10 s every
  // body sleeps.
  s.run(10);
  CHECK(s.w->count(MotionState::asleep) == kBodies);
  float at_rest[kBodies];
  for (std::uint32_t i = 0; i < kBodies; ++i) {
    CAPTURE(i);
    at_rest[i] = s.along(i);
    const auto& b = s.w->body(i);
    REQUIRE(b.rest_pose < sig.rest.count);
    // In its rest pose against the plane, not against world up, at the pose's height.
    CHECK((b.orientation * sig.rest.normal(b.rest_pose)).dot(s.normal) > std::cos(1.0f * kPi / 180));
    CHECK(b.position.dot(s.normal) == doctest::Approx(sig.rest.heights[b.rest_pose]).epsilon(1e-4));
  }
  s.run(10);
  CHECK(s.w->count(MotionState::asleep) == kBodies);
  for (std::uint32_t i = 0; i < kBodies; ++i) CHECK(s.along(i) == at_rest[i]);
}

template <int D>
void slides_on_steep_slope(const SignatureView<D>& sig)
{
  // tan 35 deg = 0.70 > friction 0.5: sliding accelerates at g (sin a - mu cos a) = 1.6 m/s^2.
  Slope<D> s(sig, 35);
  s.run(3);
  float at3[kBodies], v3[kBodies];
  for (std::uint32_t i = 0; i < kBodies; ++i) {
    at3[i] = s.along(i);
    v3[i] = s.w->body(i).linear_velocity.dot(s.downhill);
  }
  s.run(1);
  CHECK(s.w->count(MotionState::asleep) == 0);
  const float a = 35 * kPi / 180, slide = 9.81f * (std::sin(a) - 0.5f * std::cos(a));
  float gained = 0;
  for (std::uint32_t i = 0; i < kBodies; ++i) {
    CAPTURE(i);
    // A second later, still going downhill at well over a metre per second. A body sliding on a
    // face speeds up at g (sin a - mu cos a); one that tumbles (its friction at the lower edge
    // turns it over) loses less than that to friction and more at the strikes of its faces, and
    // its speed swings within a turn: the mean over the bodies keeps at least the slide's, and
    // nothing (rolling resistance, a resting contact without lever arm) brakes it below.
    CHECK(s.along(i) - at3[i] > 1.0f);
    const float v4 = s.w->body(i).linear_velocity.dot(s.downhill);
    CHECK(v4 > 1.0f);
    gained += (v4 - v3[i]) / float(kBodies);
  }
  CHECK(gained > 0.8f * slide);
}
}  // namespace

namespace {
/// The tipping angle, degrees, of rest pose `pose` of a statistical shape on a plane of unit
/// normal `normal` falling along `downhill`, the body in the pose turned about the normal by
/// `yaw` (rad), written to `orientation`: atan(e / h) from the support map, h the support toward
/// the plane and e the support set's extent downhill.
float tipping_degrees(const Shape<3>& shape, std::uint32_t pose, const Vector3& normal, const Vector3& downhill,
                      float yaw, Quaternion& orientation)
{
  const SignatureView<3>& sig = shape.signature;
  orientation = Quaternion(Eigen::AngleAxisf(yaw, normal)) *
                snap_to_rest(Quaternion::Identity(), sig.rest.normal(pose), normal);
  const Vector3 down = detail::to_body(orientation, Vector3(-normal));
  const float h = detail::support_along(sig.contact, down);
  const float e = detail::support_extent(shape, down, detail::to_body(orientation, downhill), h);
  return std::atan2(e, h) * 180 / kPi;
}
}  // namespace

TEST_CASE("slopes - a bunny at rest in a pose steeper than its tipping angle tumbles on; within it, it sleeps there")
{
  // 20 degrees, below friction 0.5's 26.6: a held block would not slide. For each rest pose, the
  // yaws at which the slope falls across the pose's support set where it is narrowest and where
  // it is widest (from the support map); a pose narrow enough downhill is no rest pose there, a
  // wide one is.
  const float a = 20 * kPi / 180;
  const Vector3 normal(0, std::sin(a), std::cos(a)), downhill(0, std::cos(a), -std::sin(a));
  const SignatureView<3> sig = tables::bunny.view();
  int tested = 0;
  for (std::uint32_t pose = 0; pose < sig.rest.count; ++pose) {
    CAPTURE(pose);
    auto w = std::make_unique<World<3, 8>>();
    const ShapeId id = w->add_shape(sig).id;
    REQUIRE(w->add_plane(normal, 0).ok());
    const Shape<3>& shape = w->shape(id);
    float narrow = 90, wide = -90, narrow_yaw = 0, wide_yaw = 0;
    Quaternion q;
    for (int k = 0; k < 72; ++k) {
      const float yaw = float(k) * 2 * kPi / 72, t = tipping_degrees(shape, pose, normal, downhill, yaw, q);
      if (t < narrow) narrow = t, narrow_yaw = yaw;
      if (t > wide) wide = t, wide_yaw = yaw;
    }
    Quaternion tips, holds;
    tipping_degrees(shape, pose, normal, downhill, narrow_yaw, tips);
    tipping_degrees(shape, pose, normal, downhill, wide_yaw, holds);
    // Margins beyond the support map's resolution (one cell: 7 degrees at its 17 nodes), and
    // poses that a body exactly in them takes (the basin biases may give it another one).
    const auto takes = [&](const Quaternion& o) {
      return nearest_rest_pose<3>(sig, o, normal, shape.rest_bias.data()) == pose;
    };
    if (!(narrow < 20 - 8 && wide > 20 + 8 && takes(tips) && takes(holds))) continue;
    ++tested;
    // At rest in the pose, at its height above the plane, 1 m apart across the slope.
    for (int i = 0; i < 2; ++i) {
      BodyDef<3> b;
      b.shape = id;
      b.mass = sig.mass;
      b.orientation = i == 0 ? tips : holds;
      b.position = Vector3(float(i), 0, 0) + normal * sig.rest.heights[pose];
      REQUIRE(w->add_body(b).ok());
    }
    const Vector3 start0 = w->body(0).position, start1 = w->body(1).position;
    for (int k = 0; k < 300; ++k) REQUIRE(w->step(kDt).ok());
    const auto in_pose = [&](std::uint32_t i) {
      return (w->body(i).orientation * sig.rest.normal(pose)).dot(normal) > std::cos(5 * kPi / 180);
    };
    // Held: asleep in its pose where it was put.
    CHECK(w->body(1).state == MotionState::asleep);
    CHECK(in_pose(1));
    // (The table's rest normals lie up to a cell of the support map, 7 degrees, off the faces of
    // the map's hull, which the body stands on: it settles onto that face before it sleeps in its
    // pose, its centre moving by up to h sin(7 deg).)
    CHECK((w->body(1).position - start1).norm() < 0.025f);
    // Not held: it has tipped out of the pose, downhill.
    CHECK_FALSE(in_pose(0));
    CHECK((w->body(0).position - start0).dot(downhill) > 0.01f);
  }
  CHECK(tested >= 2);
}

TEST_CASE("slopes - bunnies on 10 degrees with friction 0.5 fall asleep in a pose against the plane and stay put")
{
  rests_on_gentle_slope<3>(tables::bunny.view());
}

TEST_CASE("slopes - bunnies on 35 degrees with friction 0.5 keep sliding")
{
  slides_on_steep_slope<3>(tables::bunny.view());
}

TEST_CASE("slopes - squares (2D) on 10 degrees fall asleep against the plane and stay put")
{
  rests_on_gentle_slope<2>(tables::square2d.view());
}

TEST_CASE("slopes - squares (2D) on 35 degrees keep sliding")
{
  slides_on_steep_slope<2>(tables::square2d.view());
}

namespace {
/// A body resting on a face of a plane tilted by `degrees` (friction 0.5, the tables' material),
/// set rolling downhill about that face's downhill edge at `spin` rad/s, then left for 5 s.
/// Returns the distance its centre moved downhill, m; `turned` gets the angle between the face's
/// outward normal at the start and at the end, degrees, and `toward` that normal's component
/// downhill at the end.
template <int D>
float roll_over_edge(const SignatureView<D>& sig, float degrees, float spin, float& turned, float& toward, bool& asleep)
{
  using Vec = typename Space<D>::Vec;
  const float a = degrees * kPi / 180;
  auto w = std::make_unique<World<D, 4>>();
  const ShapeId id = w->add_shape(sig).id;
  BodyDef<D> b;
  b.shape = id;
  Vec normal, downhill, face;
  const float half = sig.rest.heights[0];
  if constexpr (D == 3) {
    normal = Vector3(0, std::sin(a), std::cos(a));
    downhill = Vector3(0, std::cos(a), -std::sin(a));
    b.orientation = snap_to_rest(Quaternion::Identity(), sig.rest.normal(0), normal);
    // About the edge: w along n x downhill, and the centre moving as w x (centre - edge).
    const Vector3 axis = normal.cross(downhill);
    b.angular_velocity = axis * spin;
    b.linear_velocity = b.angular_velocity.cross(Vector3(normal * half - downhill * half));
  } else {
    normal = Vector2(std::sin(a), std::cos(a));
    downhill = Vector2(std::cos(a), -std::sin(a));
    b.orientation = snap_to_rest(Rot2{}, sig.rest.normal(0), normal);
    b.angular_velocity = -spin;  // clockwise: downhill along +x
    b.linear_velocity = detail::cross(b.angular_velocity, Vector2(normal * half - downhill * half));
  }
  REQUIRE(w->add_plane(normal, 0).ok());
  b.position = normal * half;
  face = b.orientation * sig.rest.normal(0);
  REQUIRE(w->add_body(b).ok());
  for (int k = 0; k < 300; ++k) REQUIRE(w->step(kDt).ok());
  const Vec now = w->body(0).orientation * sig.rest.normal(0);
  turned = std::acos(std::fmax(-1.0f, std::fmin(1.0f, now.dot(face)))) * 180 / kPi;
  toward = now.dot(downhill);
  asleep = w->body(0).state == MotionState::asleep;
  return (w->body(0).position - b.position).dot(downhill);
}

/// A cube or square of side L on 20 degrees, rolled about its downhill edge: over the edge its
/// centre must rise by L (sqrt(2) - cos a - sin a) / 2, which takes a spin of
/// sqrt(3 g (sqrt(2) - cos a - sin a) / (2 L)) (moment of inertia about the edge 2 m L^2 / 3):
/// 1.39 rad/s for the unit square, 3.11 for the 0.2 m cube. Above it the body tumbles onto the
/// next face, whose strike leaves a quarter of the spin (angular momentum about the new edge,
/// I / (I + m L^2 / 2) = 1/4), and it slides on with the downhill speed the strike leaves and stops
/// on that face, more than one and a half sides down; below it, it rocks back. (A body that only
/// spins where it stands moves no further than its start's downhill speed slides it, half a side.)
template <int D>
void tumbles_once(const SignatureView<D>& sig, float side, float needed)
{
  float turned = 0, toward = 0;
  bool asleep = false;
  const float over = roll_over_edge<D>(sig, 20, 2 * needed, turned, toward, asleep);
  CHECK(asleep);
  // Turned about the edge: the face it stood on now faces downhill.
  CHECK(turned == doctest::Approx(90).epsilon(0.05));
  CHECK(toward > std::cos(15 * kPi / 180));
  CHECK(over > 1.5f * side);
  CHECK(over < 4 * side);
  const float back = roll_over_edge<D>(sig, 20, 0.6f * needed, turned, toward, asleep);
  CHECK(asleep);
  CHECK(turned < 5);
  CHECK(back < 0.8f * side);
}
}  // namespace

TEST_CASE("slopes - a square (2D) rolled over its downhill edge tumbles onto the next face and stops there")
{
  tumbles_once<2>(tables::square2d.view(), 1.0f, 1.39f);
}

TEST_CASE("slopes - a cube rolled over its downhill edge tumbles onto the next face and stops there")
{
  tumbles_once<3>(tables::box.view(), 0.2f, 3.11f);
}

TEST_CASE("slopes - bunnies rolling down 20 degrees go as far at 1/60 s as at the tables' 1 ms step")
{
  // 64 bunnies released at rest in random orientations 0.4 m above the plane, 1 m apart across
  // the slope: at 1/60 s (substeps on the slope, `detail::slope_contact_step`) and at 1 ms (no
  // substeps) they roll on their hulls and stop, or roll on, about as far. Each roll is chaotic,
  // so the two runs are compared in the mean over the bodies.
  constexpr std::uint32_t n = 64;
  const SignatureView<3> sig = tables::bunny.view();
  const float a = 20 * kPi / 180;
  const Vector3 normal(0, std::sin(a), std::cos(a)), downhill(0, std::cos(a), -std::sin(a));
  const auto mean_slid = [&](float dt) {
    auto w = std::make_unique<World<3, n>>();
    const ShapeId shape = w->add_shape(sig).id;
    REQUIRE(w->add_plane(normal, 0).ok());
    Pcg32 g(11, 1);
    for (std::uint32_t i = 0; i < n; ++i) {
      BodyDef<3> b;
      b.shape = shape;
      b.mass = sig.mass;
      b.position = Vector3(float(i), 0, 0.4f + sig.bounding_radius);
      const Vector3 axis = Vector3(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1)).normalized();
      b.orientation = Quaternion(Eigen::AngleAxisf(g.uniform(-kPi, kPi), axis));
      REQUIRE(w->add_body(b).ok());
    }
    const int steps = int(std::lround(8 / dt));
    for (int k = 0; k < steps; ++k) REQUIRE(w->step(dt).ok());
    float sum = 0;
    for (std::uint32_t i = 0; i < n; ++i) sum += w->body(i).position.dot(downhill);
    return sum / float(n);
  };
  const float fine = mean_slid(detail::slope_contact_step);
  const float coarse = mean_slid(kDt);
  CAPTURE(fine);
  CAPTURE(coarse);
  CHECK(fine > 1.0f);
  CHECK(coarse == doctest::Approx(fine).epsilon(0.3));
}
