// A table of format 2.0 (tests/support/format_2_0_box.hpp: tables/box.hpp as committed before
// body-body data, namespace renamed) still compiles, loads, and steps as the paper's spheres do:
// hull contacts need the data it does not have. Its own executable, so that its `box` and the
// current one never meet in one program.
#include "statsim/statsim.hpp"
#include "support/format_2_0_box.hpp"

#include <doctest/doctest.h>

#include <memory>

using namespace statsim;

TEST_CASE("format 2.0: an older table loads without body-body data and steps as with the paper's spheres")
{
  const SignatureView<3> v = tables_2_0::box.view();
  CHECK(!v.contact.present());
  CHECK(v.mesh_frame != nullptr);  // the default: the identity
  std::uint64_t hashes[2];
  int k = 0;
  for (const BodyContacts mode : {BodyContacts::hulls, BodyContacts::collision_spheres}) {
    WorldDef3 def;
    def.body_contacts = mode;
    auto w = std::make_unique<World3<20>>(def);
    const auto shape = w->add_shape(v);
    REQUIRE(shape.status == Status::ok);
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).status == Status::ok);
    for (int i = 0; i < 20; ++i) {
      BodyDef3 b;
      b.shape = shape.id;
      b.mass = 8;
      b.position = Vector3(Scalar(0.05) * Scalar(i % 3), Scalar(0.04) * Scalar(i % 5), Scalar(0.3) + Scalar(0.35) * Scalar(i));
      REQUIRE(w->add_body(b).status == Status::ok);
    }
    for (int s = 0; s < 240; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
    // The option is hashed only when not the default; the bodies must match bit for bit.
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint32_t i = 0; i < w->body_count(); ++i) {
      const Body3& b = w->body(i);
      for (int d = 0; d < 3; ++d) h = (h ^ std::uint64_t(std::int64_t(b.position[d] * 1e6f))) * 1099511628211ull;
    }
    hashes[k++] = h;
  }
  CHECK(hashes[0] == hashes[1]);
}
