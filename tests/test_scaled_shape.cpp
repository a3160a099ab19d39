// One table at any size (statsim/signature_scale.hpp): a shape made from a signature and a size
// factor s has the table's lengths times s, its mass times s^3, its normalised responses as they
// are; s = 1 is the table itself bit for bit; a factor out of range is refused and changes nothing.
#include "statsim/statsim.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

using namespace statsim;

namespace {

// |a - b| within a relative tolerance: an i16 table scaled reads (s offset) + (s scale) q,
// the table's value times s up to rounding.
bool near(Scalar a, Scalar b, Scalar rel = Scalar(1e-6)) { return std::fabs(a - b) <= rel * std::fabs(b); }

// A world of one statistical shape at scale `s` (or the table's own with s < 0), a ground plane
// and one body dropped from `height` at a tilted orientation; returns the state hash after
// `steps` steps of 1/60 s and the body's final height.
std::uint64_t drop(const SignatureView<3>& sig, Scalar s, Scalar height, int steps, Scalar* z = nullptr)
{
  auto w = std::make_unique<World3<4>>(WorldDef3{});
  const Added<ShapeId> shape = s < 0 ? w->add_shape(sig) : w->add_shape(sig, s);
  REQUIRE(shape.ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  BodyDef3 b;
  b.shape = shape.id;
  b.position = Vector3(0, 0, height);
  b.orientation = Quaternion(Scalar(0.9), Scalar(0.3), Scalar(0.2), Scalar(0.1)).normalized();
  b.angular_velocity = Vector3(1, 2, 0);
  REQUIRE(w->add_body(b).ok());
  for (int i = 0; i < steps; ++i) REQUIRE(w->step(Scalar(1) / 60).ok());
  if (z) *z = w->body(0).position.z();
  return w->state_hash();
}

}  // namespace

TEST_CASE("scaled shape: heights, rest heights, mass and bounding radius are the table's times s, s, s^3, s")
{
  const SignatureView<3> sig = tables::bunny.view();
  auto w = std::make_unique<World3<4>>(WorldDef3{});
  const Added<ShapeId> own = w->add_shape(sig);
  REQUIRE(own.ok());
  for (const Scalar s : {Scalar(0.1), Scalar(0.5), Scalar(3), Scalar(10)}) {
    CAPTURE(s);
    const Added<ShapeId> added = w->add_shape(sig, s);
    REQUIRE(added.ok());
    const Shape<3>& a = w->shape(own.id);
    const Shape<3>& b = w->shape(added.id);
    const SignatureView<3>& v = b.signature;
    CHECK(near(v.scale, s));
    CHECK(near(v.length, s * sig.length));
    for (std::uint32_t i = 0; i < sig.height.spin_ratio.size; ++i) {
      CHECK(near(v.height.mean[i], s * sig.height.mean[i]));
      CHECK(near(v.height.stddev[i], s * sig.height.stddev[i]));
      CHECK(near(v.contact.pair_mean[i], s * sig.contact.pair_mean[i]));
    }
    for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
      CHECK(near(v.rest.heights[i], s * sig.rest.heights[i]));
      CHECK(v.rest.frequencies[i] == sig.rest.frequencies[i]);
    }
    CHECK(near(b.mass, s * s * s * sig.mass));
    CHECK(near(v.unit_inertia[2], s * s * sig.unit_inertia[2]));
    CHECK(near(b.bounding_radius, s * a.bounding_radius));
    CHECK(near(b.mean_rest_height, s * a.mean_rest_height));
    CHECK(near(b.support_floor, s * a.support_floor));
    CHECK(near(v.contact.face_offset(0), s * sig.contact.face_offset(0)));
    // The support map and the normalised responses: scaled and scale-free.
    CHECK(near(v.contact.support[7], s * sig.contact.support[7]));
    for (std::uint32_t i = 0; i < 60; ++i) CHECK(v.response.mean[i] == sig.response.mean[i]);
    // A body of the shape takes the scaled mass by default.
    BodyDef3 def;
    def.shape = added.id;
    def.position = Vector3(0, 0, 100 * s);
    const Added<BodyId> body = w->add_body(def);
    REQUIRE(body.ok());
    CHECK(near(Scalar(1) / w->body(body.id).inv_mass, s * s * s * sig.mass, Scalar(1e-5)));
  }
}

TEST_CASE("scaled shape: scale 1 is the table itself, bit for bit")
{
  for (const SignatureView<3>& sig : {tables::bunny.view(), tables::box.view()}) {
    const std::uint64_t own = drop(sig, -1, Scalar(0.5), 120);
    CHECK(drop(sig, 1, Scalar(0.5), 120) == own);
    CHECK(drop(sig, 2, Scalar(0.5), 120) != own);
  }
}

TEST_CASE("scaled shape: a dropped body comes to rest at its rest heights times s")
{
  const SignatureView<3> sig = tables::bunny.view();
  Scalar lo = sig.rest.heights[0], hi = lo;
  for (std::uint32_t i = 1; i < sig.rest.count; ++i) {
    lo = sig.rest.heights[i] < lo ? sig.rest.heights[i] : lo;
    hi = sig.rest.heights[i] > hi ? sig.rest.heights[i] : hi;
  }
  for (const Scalar s : {Scalar(0.2), Scalar(5)}) {
    CAPTURE(s);
    Scalar z = 0;
    drop(sig, s, Scalar(3) * s * sig.bounding_radius, 600, &z);
    CHECK(z >= Scalar(0.98) * s * lo);
    CHECK(z <= Scalar(1.02) * s * hi);
  }
}

TEST_CASE("scaled shape: a column of 10 scaled cubes in hull contact holds 10 times their scaled side")
{
  for (const Scalar s : {Scalar(0.5), Scalar(5)}) {
    CAPTURE(s);
    WorldDef3 def;
    def.body_contacts = BodyContacts::hulls;
    auto w = std::make_unique<World3<16>>(def);
    const ShapeId box = w->add_shape(tables::box.view(), s).id;
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
    for (int i = 0; i < 10; ++i) {
      BodyDef3 b;
      b.shape = box;
      b.position = Vector3(0, 0, s * (Scalar(0.1) + Scalar(0.2) * Scalar(i)));
      REQUIRE(w->add_body(b).ok());
    }
    for (int i = 0; i < 180; ++i) REQUIRE(w->step(Scalar(1) / 60).ok());
    Scalar top = 0;
    for (std::uint32_t i = 0; i < w->body_count(); ++i)
      top = w->body(i).position.z() > top ? w->body(i).position.z() : top;
    CHECK(std::fabs(top / (Scalar(1.9) * s) - 1) < Scalar(0.02));
  }
}

TEST_CASE("scaled shape: a scale out of range is refused and adds nothing")
{
  auto w = std::make_unique<World3<4>>(WorldDef3{});
  const SignatureView<3> sig = tables::bunny.view();
  CHECK(w->add_shape(sig, std::numeric_limits<Scalar>::quiet_NaN()).status == Status::non_finite);
  CHECK(w->add_shape(sig, std::numeric_limits<Scalar>::infinity()).status == Status::non_finite);
  CHECK(w->add_shape(sig, 0).status == Status::out_of_range);
  CHECK(w->add_shape(sig, -1).status == Status::out_of_range);
  CHECK(w->add_shape(sig, min_shape_scale / 2).status == Status::out_of_range);
  CHECK(w->add_shape(sig, max_shape_scale * 2).status == Status::out_of_range);
  // The bunny's 1.6 kg times 1000^3 is beyond limits::max_mass: refused by the signature's checks.
  CHECK(w->add_shape(sig, max_shape_scale).status == Status::out_of_range);
  CHECK(w->shape_count() == 0u);
  CHECK(w->add_shape(sig, min_shape_scale).ok());
  CHECK(w->add_shape(sig, Scalar(500)).ok());
}
