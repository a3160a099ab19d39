// A table of format 2.1 (tests/support/format_2_1_box.hpp: tables/box.hpp as committed before the
// landing data, namespace renamed) still compiles, loads without landing data, and steps bit for
// bit as the current table does with its landing data left out: the data it lacks is the only
// difference, and a table without it takes the path of before.
#include "statsim/statsim.hpp"
#include "support/format_2_1_box.hpp"
#include "tables/box.hpp"

#include <doctest/doctest.h>

#include <memory>

using namespace statsim;

namespace {

std::uint64_t drop_boxes(const SignatureView<3>& v)
{
  auto w = std::make_unique<World3<40>>();
  const auto shape = w->add_shape(v);
  REQUIRE(shape.ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  Pcg32 rng(21, 4);
  for (int i = 0; i < 40; ++i) {
    BodyDef3 b;
    b.shape = shape.id;
    b.position = Vector3(Scalar(0.5) * Scalar(i % 8), Scalar(0.5) * Scalar(i / 8), rng.uniform(0.4f, 1.2f));
    b.orientation = random_orientation<3>(rng);
    b.linear_velocity = Vector3(rng.uniform(-0.5f, 0.5f), rng.uniform(-0.5f, 0.5f), 0);
    b.angular_velocity = Vector3(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
    REQUIRE(w->add_body(b).ok());
  }
  for (int s = 0; s < 240; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
  return w->state_hash();
}

}  // namespace

TEST_CASE("format 2.1: an older table loads without landing data and steps as the current one without it")
{
  const SignatureView<3> old = tables_2_1::box.view();
  CHECK(!old.landing.present());
  CHECK(old.contact.present());
  SignatureView<3> current = tables::box.view();
  REQUIRE(current.landing.present());
  const std::uint64_t with_landing = drop_boxes(current);
  current.landing = LandingView{};
  CHECK(drop_boxes(old) == drop_boxes(current));
  CHECK(drop_boxes(old) != with_landing);
}
