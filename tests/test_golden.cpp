// Golden hashes: the final state of a fixed scene, bit for bit. A change to the runtime that
// changes results (on purpose or not) fails here; update the constant in the same commit and
// say why in its message. The same values hold for Release and for the Debug sanitizer build
// (the runtime's arithmetic does not depend on the optimisation level). Each scene also runs in
// a world of the smallest feature set that covers it (statsim/features.hpp), to the same hash.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"
#include "tables/lshape2d.hpp"
#include "tables/square2d.hpp"

#include <cstdio>
#include <memory>

using namespace statsim;

namespace {
template <int D, class World, class Sig>
std::uint64_t run_scene(World& w, const Sig& sig)
{
  const ShapeId stat = w.add_shape(sig.view()).id;
  ShapeDef ball;
  ball.radius = 0.12f;
  const ShapeId sphere = w.add_shape(ball).id;
  using Vec = typename Space<D>::Vec;
  REQUIRE(w.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok());
  REQUIRE(w.add_plane(Vec::Unit(0), -2).ok());
  REQUIRE(w.add_plane(-Vec::Unit(0), -2).ok());
  Pcg32 g(2026, 11);
  for (int i = 0; i < 150; ++i) {
    BodyDef<D> b;
    b.shape = i % 3 == 0 ? sphere : stat;
    b.mass = 1;  // kg, not the table's (the scene predates shape masses)
    for (int k = 0; k < D; ++k) {
      const float x = g.uniform(-1.5f, 1.5f);
      b.position[k] = x;
    }
    const float h = g.uniform(0.3f, 4);
    b.position[Space<D>::up_axis] = h;
    for (int k = 0; k < D; ++k) {
      const float v = g.uniform(-1, 1);
      b.linear_velocity[k] = v;
    }
    if constexpr (D == 3) {
      const float wx = g.uniform(-6, 6), wy = g.uniform(-6, 6), wz = g.uniform(-6, 6);
      b.angular_velocity = Vector3(wx, wy, wz);
    } else {
      b.angular_velocity = g.uniform(-6, 6);
    }
    REQUIRE(w.add_body(b).ok());
  }
  for (int i = 0; i < 600; ++i) REQUIRE(w.step(1.0f / 60).status == Status::ok);
  return w.state_hash();
}

/// A heap of one shape on the hashed grid: a single bounding radius takes the grid search's
/// branch-free loop, whose pairs (and their order, which the contact passes follow) must be the
/// general loop's. The scenes above have two shapes and sweep-and-prune.
template <int D, class World, class Sig>
std::uint64_t run_grid_heap(World& w, const Sig& sig)
{
  const ShapeId stat = w.add_shape(sig.view()).id;
  using Vec = typename Space<D>::Vec;
  REQUIRE(w.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok());
  Pcg32 g(2026, 18);
  const int side = D == 3 ? 8 : 30;
  for (int i = 0; i < 600; ++i) {
    BodyDef<D> b;
    b.shape = stat;
    b.mass = 1;
    // A lattice of 0.4 m cells, side x side per layer, jittered, with random velocities.
    int q = i;
    for (int k = 0; k < D; ++k) {
      const bool up = k == Space<D>::up_axis;
      const int cell = up ? q : q % side;
      if (!up) q /= side;
      const float jitter = g.uniform(-0.03f, 0.03f);
      b.position[k] = 0.4f * float(cell) + jitter + (up ? 0.3f : 0.0f);
      const float v = g.uniform(-1, 1);
      b.linear_velocity[k] = v;
    }
    REQUIRE(w.add_body(b).ok());
  }
  for (int i = 0; i < 300; ++i) REQUIRE(w.step(1.0f / 60).status == Status::ok);
  return w.state_hash();
}
}  // namespace

TEST_CASE("golden hash of a fixed 3D scene")
{
  auto w = std::make_unique<World3<150>>();
  const std::uint64_t h = run_scene<3>(*w, statsim::testing::cube_synthetic);
  std::printf("golden 3D: 0x%016llx\n", static_cast<unsigned long long>(h));
  CHECK(h == 0x83cc1773c1255bf3ull);
  auto small = std::make_unique<World3<150, 8, 900, 8, 0, BroadPhase::sweep_and_prune, Features::paper>>();
  CHECK(run_scene<3>(*small, statsim::testing::cube_synthetic) == 0x83cc1773c1255bf3ull);
}

TEST_CASE("golden hash of a fixed 2D scene")
{
  auto w = std::make_unique<World2<150>>();
  const std::uint64_t h = run_scene<2>(*w, statsim::testing::square2d_synthetic);
  std::printf("golden 2D: 0x%016llx\n", static_cast<unsigned long long>(h));
  CHECK(h == 0x08cfb291cf3cca20ull);
  auto small = std::make_unique<World2<150, 8, 900, 8, 0, BroadPhase::sweep_and_prune, Features::paper>>();
  CHECK(run_scene<2>(*small, statsim::testing::square2d_synthetic) == 0x08cfb291cf3cca20ull);
}

TEST_CASE("golden hashes of heaps of one shape on the grid (3D and 2D)")
{
  WorldDef3 d3;
  d3.broad_phase = BroadPhase::grid;
  auto w3 = std::make_unique<World<3, 600, 4, 600 * 16, 1>>(d3);
  const std::uint64_t h3 = run_grid_heap<3>(*w3, statsim::testing::cube_synthetic);
  std::printf("golden grid 3D: 0x%016llx\n", static_cast<unsigned long long>(h3));
  CHECK(h3 == 0x1fd3064a19a22aebull);
  auto small3 = std::make_unique<World<3, 600, 4, 600 * 16, 1, 0, BroadPhase::automatic, Features::paper>>(d3);
  CHECK(run_grid_heap<3>(*small3, statsim::testing::cube_synthetic) == 0x1fd3064a19a22aebull);
  WorldDef2 d2;
  d2.broad_phase = BroadPhase::grid;
  auto w2 = std::make_unique<World<2, 600, 4, 600 * 16, 1>>(d2);
  const std::uint64_t h2 = run_grid_heap<2>(*w2, statsim::testing::square2d_synthetic);
  std::printf("golden grid 2D: 0x%016llx\n", static_cast<unsigned long long>(h2));
  CHECK(h2 == 0xd0f2aad726f70514ull);
  auto small2 = std::make_unique<World<2, 600, 4, 600 * 16, 1, 0, BroadPhase::automatic, Features::paper>>(d2);
  CHECK(run_grid_heap<2>(*small2, statsim::testing::square2d_synthetic) == 0xd0f2aad726f70514ull);
}

namespace {
// A pile of two or three committed shapes meeting at their hulls (`BodyContacts::hulls`): the
// hull candidate search, the kept face contacts and the tipping rule, which the scenes above
// (collision spheres) never run.
template <int D, class World, std::size_t N>
std::uint64_t run_hull_pile(World& w, const SignatureView<D> (&shapes)[N])
{
  using Vec = typename Space<D>::Vec;
  ShapeId ids[N];
  for (std::size_t k = 0; k < N; ++k) ids[k] = w.add_shape(shapes[k]).id;
  REQUIRE(w.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok());
  Pcg32 g(2026, 12);
  for (std::uint32_t i = 0; i < World::max_bodies; ++i) {
    BodyDef<D> b;
    b.shape = ids[i % N];
    b.mass = 1;
    if constexpr (D == 3) {
      b.position = Vector3(0.22f * float(i % 6), 0.22f * float((i / 6) % 6), 0.3f + 0.25f * float(i / 36));
      b.orientation = Quaternion(g.uniform() - 0.5f, g.uniform() - 0.5f, g.uniform() - 0.5f, g.uniform() - 0.5f).normalized();
    } else {
      b.position = Vector2(1.6f * float(i % 8) - 6, 1 + 1.6f * float(i / 8));
      b.orientation = Rot2::from_angle(6.283185f * g.uniform());
    }
    b.linear_velocity[0] = g.uniform(-0.5f, 0.5f);
    REQUIRE(w.add_body(b).ok());
  }
  for (int s = 0; s < 400; ++s) REQUIRE(w.step(1.0f / 60).ok());
  return w.state_hash();
}
}  // namespace

TEST_CASE("golden hashes of piles of committed shapes with hull contacts (3D and 2D)")
{
  WorldDef3 d3;
  d3.body_contacts = BodyContacts::hulls;
  auto w3 = std::make_unique<World<3, 216, 8, 216 * 24>>(d3);
  const SignatureView<3> s3[] = {tables::bunny.view(), tables::box.view(), tables::lshape.view()};
  const std::uint64_t h3 = run_hull_pile<3>(*w3, s3);
  std::printf("golden hulls 3D: 0x%016llx\n", static_cast<unsigned long long>(h3));
  CHECK(h3 == 0xb7ab25a26a89e744ull);
  auto small3 = std::make_unique<World<3, 216, 8, 216 * 24, 8, 0, BroadPhase::sweep_and_prune, Features::piles>>(d3);
  CHECK(run_hull_pile<3>(*small3, s3) == 0xb7ab25a26a89e744ull);
  WorldDef2 d2;
  d2.body_contacts = BodyContacts::hulls;
  auto w2 = std::make_unique<World<2, 96, 8, 96 * 16>>(d2);
  const SignatureView<2> s2[] = {tables::square2d.view(), tables::lshape2d.view()};
  const std::uint64_t h2 = run_hull_pile<2>(*w2, s2);
  std::printf("golden hulls 2D: 0x%016llx\n", static_cast<unsigned long long>(h2));
  CHECK(h2 == 0x9354f00b8551af17ull);
  auto small2 = std::make_unique<World<2, 96, 8, 96 * 16, 8, 0, BroadPhase::sweep_and_prune, Features::piles>>(d2);
  CHECK(run_hull_pile<2>(*small2, s2) == 0x9354f00b8551af17ull);
}
