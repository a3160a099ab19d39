// Regression tests for the failures the stress matrix (`statsim stress`) and the fuzzers
// (tests/fuzz) found in the runtime. Each is small and fast; the matrix itself is a tool run.
#include <doctest/doctest.h>

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/bunny.hpp"
#include "tables/square2d.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

using namespace statsim;

namespace {
constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();

using Small3 = World3<8, 4, 64, 4>;

/// A world with a bunny, a plane and two bodies, stepped once: something for a bad call to change.
std::unique_ptr<Small3> populated()
{
  auto w = std::make_unique<Small3>();
  const auto shape = w->add_shape(tables::bunny.view());
  REQUIRE(shape.ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  for (int i = 0; i < 2; ++i) {
    BodyDef3 b;
    b.shape = shape.id;
    b.position = Vector3(0.5f * float(i), 0, 1);
    b.linear_velocity = Vector3(0.1f, 0, 0);
    REQUIRE(w->add_body(b).ok());
  }
  REQUIRE(w->step(1.0f / 60).ok());
  return w;
}

/// The bunny with float response tables (whatever precision the committed table has).
constexpr auto bunny_f32 = dequantize(tables::bunny);

/// A copy of the bunny's numbers that a test can spoil, and a view of the copy.
struct BunnyCopy {
  std::vector<Scalar> height_axis, height_mean, response_mean, rest_normals, rest_heights;
  SignatureView<3> view = bunny_f32.view();
  BunnyCopy()
  {
    const auto& t = bunny_f32;
    height_axis.assign(t.height_axis.begin(), t.height_axis.end());
    height_mean.assign(t.height_mean.begin(), t.height_mean.end());
    response_mean.assign(t.response_mean.begin(), t.response_mean.end());
    rest_normals.assign(t.rest_normals.begin(), t.rest_normals.end());
    rest_heights.assign(t.rest_heights.begin(), t.rest_heights.end());
    view.height.spin_ratio = height_axis;
    view.height.mean = ValuesView(height_mean);
    view.response.mean = ValuesView(response_mean);
    view.rest.normals = rest_normals;
    view.rest.heights = ValuesView(rest_heights);
  }
};
}  // namespace

// fuzz_loaders found: add_shape accepted a signature whose tables held NaN, and its bodies went
// non-finite on their first impact. Table contents are now checked once, at add_shape.
TEST_CASE("stress regression - a signature with bad table numbers is rejected and adds nothing")
{
  {
    BunnyCopy ok;
    Small3 w;
    CHECK(w.add_shape(ok.view).ok());  // the unspoiled copy is fine
  }
  const auto rejected = [](const BunnyCopy& c) {
    Small3 w;
    const Status s = w.add_shape(c.view).status;
    CHECK(w.shape_count() == 0);
    return s;
  };
  BunnyCopy a;
  a.height_mean[3] = nan_f;
  CHECK(rejected(a) == Status::invalid_shape);
  BunnyCopy b;
  b.height_mean[0] = 0;  // a collision radius of zero
  CHECK(rejected(b) == Status::invalid_shape);
  BunnyCopy c;
  c.height_axis[2] = c.height_axis[1];  // not strictly increasing
  CHECK(rejected(c) == Status::invalid_shape);
  BunnyCopy d;
  d.response_mean[17] = 1e30f;  // finite, but scaled by a speed it overflows
  CHECK(rejected(d) == Status::invalid_shape);
  BunnyCopy e;
  e.rest_normals[0] *= 2;  // not unit
  CHECK(rejected(e) == Status::invalid_shape);
  BunnyCopy f;
  f.rest_heights[1] = -0.05f;
  CHECK(rejected(f) == Status::invalid_shape);
  BunnyCopy g;
  g.view.material.friction = nan_f;
  CHECK(rejected(g) == Status::non_finite);
}

// fuzz_world found: a step with dt = 1e30 s (finite and positive, so accepted) made every body
// infinite, and the grid broad phase then converted NaN to an integer (undefined behaviour).
// Finite values beyond statsim::limits are now rejected, and the grid's cell conversion is
// defined for NaN.
TEST_CASE("stress regression - finite values beyond the limits are rejected and change nothing")
{
  auto w = populated();
  const std::uint64_t before = w->state_hash();
  CHECK(w->step(1e30f).status == Status::invalid_time_step);
  CHECK(w->step(2.0f).status == Status::invalid_time_step);
  BodyDef3 b;
  b.position = Vector3(1e30f, 0, 1);
  CHECK(w->add_body(b).status == Status::out_of_range);
  b.position = Vector3(0, 0, 1);
  b.linear_velocity = Vector3(0, 0, -1e30f);
  CHECK(w->add_body(b).status == Status::out_of_range);
  b.linear_velocity = Vector3::Zero();
  b.angular_velocity = Vector3(1e30f, 0, 0);
  CHECK(w->add_body(b).status == Status::out_of_range);
  b.angular_velocity = Vector3::Zero();
  b.mass = 1e-30f;  // inverse mass 1e30
  CHECK(w->add_body(b).status == Status::out_of_range);
  CHECK(w->set_velocity(0, Vector3(1e30f, 0, 0), Vector3::Zero()) == Status::out_of_range);
  CHECK(w->add_plane(Vector3(0, 0, 1), 1e30f).status == Status::out_of_range);
  ShapeDef tiny;
  tiny.radius = 1e-30f;  // the grid's inverse cell size would overflow
  CHECK(w->add_shape(tiny).status == Status::out_of_range);
  WorldDef3 def;
  def.gravity = Vector3(0, 0, -1e30f);
  CHECK(w->configure(def) == Status::invalid_parameter);
  def = WorldDef3{};
  def.rest_turn_time = 1e-30f;  // the rest turn's spin would be infinite
  CHECK(w->configure(def) == Status::invalid_parameter);
  CHECK(w->state_hash() == before);
  CHECK(w->body_count() == 2);
  CHECK(w->plane_count() == 1);
  CHECK(w->shape_count() == 1);
  // The largest accepted values step without leaving the finite range.
  b.mass = 1;
  b.position = Vector3(limits::coordinate * 0.5f, 0, 1);
  b.linear_velocity = Vector3(-limits::speed, 0, 0);
  b.angular_velocity = Vector3(0, limits::spin, 0);
  REQUIRE(w->add_body(b).ok());
  for (int i = 0; i < 30; ++i) REQUIRE(w->step(limits::time_step).ok());
  for (std::uint32_t i = 0; i < w->body_count(); ++i) {
    CHECK(detail::finite(w->body(i).position));
    CHECK(detail::finite(w->body(i).linear_velocity));
    CHECK(detail::finite(w->body(i).orientation));
  }
}

TEST_CASE("stress regression - grid cells of non-finite coordinates are clamped, not undefined")
{
  using SpatialHash = detail::SpatialHash<3>;
  CHECK(SpatialHash::cell_of(nan_f, 1.0f) == -1000000000);
  CHECK(SpatialHash::cell_of(std::numeric_limits<float>::infinity(), 1.0f) == 1000000000);
  CHECK(SpatialHash::cell_of(-std::numeric_limits<float>::infinity(), 1.0f) == -1000000000);
  CHECK(SpatialHash::cell_of(2.5f, 1.0f) == 2);
}

// The 2D world takes the same checks (one WorldCore implementation per dimension).
TEST_CASE("stress regression - 2D rejects a huge dt and out-of-range states")
{
  World2<4, 2, 16, 2> w;
  const auto shape = w.add_shape(tables::square2d.view());
  REQUIRE(shape.ok());
  REQUIRE(w.add_plane(Vector2(0, 1), 0).ok());
  BodyDef<2> b;
  b.shape = shape.id;
  b.position = Vector2(0, 2);
  REQUIRE(w.add_body(b).ok());
  const std::uint64_t before = w.state_hash();
  CHECK(w.step(1e30f).status == Status::invalid_time_step);
  b.linear_velocity = Vector2(1e30f, 0);
  CHECK(w.add_body(b).status == Status::out_of_range);
  CHECK(w.state_hash() == before);
}
