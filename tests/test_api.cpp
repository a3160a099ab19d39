// The public surface's guards against mistakes: the shape's mass by default, shape ids tied to
// their world, a checked body lookup, the step's time-step status, the random-orientation
// helper and the floating-point contraction probe.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/mesh_pose.hpp"
#include "statsim/random.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <cmath>
#include <memory>

using namespace statsim;

TEST_CASE("a body takes its shape's mass unless it gives one")
{
  auto w = std::make_unique<World3<8>>();
  Signature<3, 2, 2, 2, 2, 1, 6> nut = testing::cube_synthetic;
  nut.mass = 0.468f;
  const Added<ShapeId> stat = w->add_shape(nut.view());
  ShapeDef ball;
  ball.mass = 2.5f;
  const Added<ShapeId> sphere = w->add_shape(ball);
  REQUIRE(stat.ok());
  REQUIRE(sphere.ok());

  BodyDef3 b;
  b.shape = stat.id;
  const Added<BodyId> a = w->add_body(b);
  REQUIRE(a.ok());
  CHECK(w->body(a.id).inv_mass == 1 / 0.468f);
  b.shape = sphere.id;
  const Added<BodyId> s = w->add_body(b);
  REQUIRE(s.ok());
  CHECK(w->body(s.id).inv_mass == 1 / 2.5f);
  b.mass = 4;
  const Added<BodyId> given = w->add_body(b);
  REQUIRE(given.ok());
  CHECK(w->body(given.id).inv_mass == 0.25f);

  // A table without a mass: its bodies must give one.
  nut.mass = 0;
  const Added<ShapeId> massless = w->add_shape(nut.view());
  REQUIRE(massless.ok());
  b.shape = massless.id;
  b.mass = 0;
  CHECK(w->add_body(b).status == Status::invalid_mass);
  CHECK(w->body_count() == 3);

  // A table whose mass add_body would refuse is refused at add_shape, named for what is wrong.
  nut.mass = 4.7e10f;
  CHECK(w->add_shape(nut.view()).status == Status::out_of_range);
  nut.mass = -1;
  CHECK(w->add_shape(nut.view()).status == Status::invalid_mass);
  ball.mass = 0;
  CHECK(w->add_shape(ball).status == Status::invalid_mass);
  ball.mass = 1e12f;
  CHECK(w->add_shape(ball).status == Status::out_of_range);
  CHECK(w->shape_count() == 3);
}

TEST_CASE("a shape id of another world is refused; a bare index is not")
{
  auto a = std::make_unique<World3<8>>();
  auto b = std::make_unique<World3<8>>();
  CHECK(a->tag() != b->tag());
  CHECK(a->tag() != 0);
  ShapeDef small, big;
  big.radius = 0.5f;
  const Added<ShapeId> a0 = a->add_shape(small);
  const Added<ShapeId> a1 = a->add_shape(big);
  const Added<ShapeId> b0 = b->add_shape(small);
  const Added<ShapeId> b1 = b->add_shape(small);
  REQUIRE((a0.ok() && a1.ok() && b0.ok() && b1.ok()));
  CHECK(a1.id.index == b1.id.index);
  CHECK(a1.id != b1.id);
  CHECK(a->owns(a1.id));
  CHECK(!a->owns(b1.id));

  const std::uint64_t before = a->state_hash();
  BodyDef3 body;
  body.position = Vector3(0, 0, 1);
  body.shape = b1.id;  // world b's shape 1: means nothing in a
  CHECK(a->add_body(body).status == Status::invalid_shape);
  CHECK(a->state_hash() == before);
  body.shape = a1.id;
  CHECK(a->add_body(body).ok());
  body.shape = ShapeId(1);  // a bare index, as before ids had tags
  CHECK(a->add_body(body).ok());
  CHECK(&a->shape(a1.id) == &a->shape_of(a->body(0)));
  body.shape = ShapeId(2);
  CHECK(a->add_body(body).status == Status::invalid_shape);
}

namespace {
int g_asserts = 0;
void count_assert(const char*, const char*, int) { ++g_asserts; }
}  // namespace

TEST_CASE("a 2D body is 64 bytes: its shape index and four flags share two bytes, each keeps its own value")
{
  // The firmware's RAM per body counts one body (examples/firmware/README.md).
  CHECK(sizeof(Body<2>) == 64);
  CHECK(sizeof(Body<3>) == 96);
  Body<2> b{};
  const Body<2>& r = b;  // doctest binds its operands by reference: a const one copies a bit-field
  b.shape = (1u << shape_index_bits) - 1;
  CHECK(r.shape == 2047);
  CHECK(r.state == MotionState::moving);
  CHECK(!r.touching);
  b.state = MotionState::asleep;
  b.touching = true;
  b.pile_rest = true;
  CHECK(r.shape == 2047);
  CHECK(r.state == MotionState::asleep);
  CHECK(r.touching);
  CHECK(!r.on_ground);
  CHECK(r.pile_rest);
  b.shape = 0;
  b.on_ground = true;
  CHECK(r.state == MotionState::asleep);
  CHECK(r.touching);
  CHECK(r.on_ground);
  CHECK(r.shape == 0);
  CHECK(r.rest_pose == 0);
  CHECK(r.supports == 0);
}

TEST_CASE("find_body checks the id; body() past the end stays inside the world")
{
  auto w = std::make_unique<World3<4>>();
  const Added<ShapeId> s = w->add_shape(ShapeDef{});
  REQUIRE(s.ok());
  BodyDef3 b;
  b.shape = s.id;
  b.position = Vector3(1, 2, 3);
  REQUIRE(w->add_body(b).ok());
  REQUIRE(w->find_body(0) != nullptr);
  CHECK(w->find_body(0)->position == Vector3(1, 2, 3));
  CHECK(w->find_body(1) == nullptr);
  CHECK(w->find_body(1000) == nullptr);

  g_asserts = 0;
  const AssertHandler previous = set_assert_handler(&count_assert);
  const Body3& past = w->body(1000);
  set_assert_handler(previous);
  CHECK(g_asserts == STATSIM_ENABLE_ASSERT);
  CHECK(&past == &w->body(0));
}

TEST_CASE("a time step over a second is invalid_time_step, as documented")
{
  World3<2> w;
  CHECK(w.step(2.0f).status == Status::invalid_time_step);
  CHECK(w.step(1.0f).status == Status::ok);
  CHECK(std::string(to_string(Status::float_contraction)) == "float_contraction");
}

TEST_CASE("random orientations are unit, uniform over rotations and reproducible")
{
  Pcg32 g(11, 3), h(11, 3);
  const int n = 200000;
  double q2[4] = {0, 0, 0, 0}, z[3] = {0, 0, 0}, zz = 0;
  for (int i = 0; i < n; ++i) {
    const Quaternion q = random_orientation<3>(g);
    const Quaternion r = random_orientation<3>(h);
    REQUIRE(q.coeffs() == r.coeffs());
    REQUIRE(std::fabs(q.squaredNorm() - 1) < 1e-5f);
    for (int k = 0; k < 4; ++k) q2[k] += double(q.coeffs()[k]) * q.coeffs()[k];
    const Vector3 up = q * Vector3(0, 0, 1);
    for (int k = 0; k < 3; ++k) z[k] += up[k];
    zz += double(up.z()) * up.z();
  }
  // Uniform rotations: each quaternion component has E[q_k^2] = 1/4; a rotated axis is uniform
  // on the sphere (mean 0, E[z^2] = 1/3). Tolerances are about 5 standard errors.
  for (int k = 0; k < 4; ++k) CHECK(std::fabs(q2[k] / n - 0.25) < 0.002);
  for (int k = 0; k < 3; ++k) CHECK(std::fabs(z[k] / n) < 0.007);
  CHECK(std::fabs(zz / n - 1.0 / 3) < 0.003);

  double c = 0, s = 0, cc = 0;
  for (int i = 0; i < n; ++i) {
    const Rot2 r = random_orientation<2>(g);
    REQUIRE(std::fabs(r.squared_norm() - 1) < 1e-5f);
    c += r.c;
    s += r.s;
    cc += double(r.c) * r.c;
  }
  CHECK(std::fabs(c / n) < 0.008);
  CHECK(std::fabs(s / n) < 0.008);
  CHECK(std::fabs(cc / n - 0.5) < 0.004);
}

TEST_CASE("a build without contraction constructs worlds with status ok")
{
  // The CMake targets compile with -ffp-contract=off; tests/api/contraction.cpp is built
  // without it and sees float_contraction.
  CHECK(!detail::float_contraction());
  World3<2> w;
  CHECK(w.construction_status() == Status::ok);
  WorldDef3 bad;
  bad.sleep_time = -1;
  World3<2> v(bad);
  CHECK(v.construction_status() == Status::invalid_parameter);
}

namespace {
/// A view with a mesh frame, as tables that record one have.
struct FramedView {
  const Scalar* mesh_frame;
};
}  // namespace

TEST_CASE("a mesh is placed at a body's pose through the table's mesh frame")
{
  // Mesh frame: the body's x axis is the mesh's y axis (R rows: (0 1 0), (-1 0 0), (0 0 1)),
  // the centre of mass at c = (1, 2, 3) in mesh coordinates.
  const Scalar frame[12] = {0, 1, 0, -1, 0, 0, 0, 0, 1, 1, 2, 3};
  const FramedView framed{frame};
  const Vector3 x(5, -1, 2);
  const Quaternion q(Eigen::AngleAxisf(0.7f, Vector3(1, 2, 2).normalized()));
  const auto t = mesh_to_world(framed, x, q);
  const Vector3 m(1.5f, 2.25f, 2.5f);
  const Eigen::Matrix3f r = (Eigen::Matrix3f() << 0, 1, 0, -1, 0, 0, 0, 0, 1).finished();
  const Vector3 expected = x + q * (r * (m - Vector3(1, 2, 3)));
  CHECK((t * m - expected).norm() < 1e-5f);
  CHECK((t * Vector3(1, 2, 3) - x).norm() < 1e-5f);  // the centre of mass is at the body's position

  // A table without a mesh frame: body frame = mesh frame.
  const auto plain = mesh_to_world(testing::cube_synthetic.view(), x, q);
  CHECK((plain * m - (x + q * m)).norm() < 1e-5f);

  // 2D, from a body.
  const Scalar frame2[6] = {0, -1, 1, 0, 0.5f, 0};
  const FramedView framed2{frame2};
  Body2 b{};
  b.position = Vector2(1, 1);
  b.orientation = Rot2{0, 1};  // a quarter turn
  const auto t2 = mesh_to_world(framed2, b);
  // m = (0.5, 1): body point R (m - c) = (0 -1; 1 0) (0, 1) = (-1, 0); turned: (0, -1); + (1, 1).
  CHECK((t2 * Vector2(0.5f, 1) - Vector2(1, 0)).norm() < 1e-6f);
}
