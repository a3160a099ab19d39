// Body-body contacts at the shapes' hulls (statsim/detail/hull.hpp, BodyContacts::hulls) with the
// committed tables' body-body data: the support map against the closed form, stacks that hold
// their true height, and piles that end asleep, above the ground and without overlaps.
#include "statsim/snapshot.hpp"
#include "statsim/statsim.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"
#include "tables/lshape2d.hpp"
#include "tables/square2d.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <memory>

using namespace statsim;

namespace {

// The deepest overlap of any touching pair as a fraction of the separation at which it touches
// (the runtime's own hull contact, found afresh), and the lowest point of any hull below the
// plane z = 0 (2D: y = 0), m (negative: below).
template <int D, class World>
void pile_state(const World& w, Scalar& overlap, Scalar& lowest)
{
  using Vec = typename Space<D>::Vec;
  overlap = 0;
  lowest = 1e9f;
  const Vec down = -Vec::Unit(Space<D>::up_axis);
  for (std::uint32_t i = 0; i < w.body_count(); ++i) {
    const Body<D>& a = w.body(i);
    const Shape<D>& sa = w.shape(ShapeId(a.shape));
    const Scalar low = a.position[Space<D>::up_axis] -
                       detail::support_along(sa.signature.contact, detail::to_body(a.orientation, down));
    lowest = low < lowest ? low : lowest;
    for (std::uint32_t j = i + 1; j < w.body_count(); ++j) {
      const Body<D>& b = w.body(j);
      const Shape<D>& sb = w.shape(ShapeId(b.shape));
      const Vec d = b.position - a.position;
      const Scalar dist = d.norm();
      const Vec e = d / dist;
      const Scalar packing = sa.largest_packing > sb.largest_packing ? sa.largest_packing : sb.largest_packing;
      const std::uint32_t k =
          detail::find_hull_witness(sa, a, sb, b, e, dist, packing, detail::pair_packing(sa, sb, a.shape == b.shape, e));
      if (k == detail::no_witness) continue;
      const detail::HullCandidate<D> h = detail::hull_candidate(sa, a, sb, b, e, k);
      const Scalar reach = (k == 0 ? detail::pair_packing(sa, sb, a.shape == b.shape, e) : h.packing) * h.reach;
      const Scalar f = (reach - d.dot(h.normal)) / reach;
      overlap = f > overlap ? f : overlap;
    }
  }
}

// Steps three copies of a pile of two shapes and plain spheres (radius `sphere`, m; they touch
// the others' faces) with hull contacts: with room for every touching
// pair's face contact (`detail::PairHull`, kept by the impact and shock passes for the passes
// after them), with room for `few` (the pairs beyond are found afresh in every pass), and with
// none. The state hashes must agree after every step; `kept` counts the entries the first world
// held after its steps, to show that it used them.
template <int D, class World>
void compare_kept_contacts(const SignatureView<D>& s0, const SignatureView<D>& s1, Scalar sphere, int steps,
                           std::uint32_t few, std::uint64_t& kept)
{
  using Vec = typename Space<D>::Vec;
  WorldDef<D> def;
  def.body_contacts = BodyContacts::hulls;
  std::unique_ptr<World> w[3] = {std::make_unique<World>(def), std::make_unique<World>(def), std::make_unique<World>(def)};
  REQUIRE(detail::SnapshotAccess::data<D>(*w[0]).max_pair_hulls > few);
  detail::SnapshotAccess::data<D>(*w[1]).max_pair_hulls = few;
  detail::SnapshotAccess::data<D>(*w[2]).max_pair_hulls = 0;
  for (auto& world : w) {
    ShapeDef ball;
    ball.radius = sphere;
    const ShapeId shapes[] = {world->add_shape(s0).id, world->add_shape(s1).id, world->add_shape(ball).id};
    REQUIRE(world->add_plane(Vec::Unit(Space<D>::up_axis), 0).status == Status::ok);
    Pcg32 rng(7, 1);
    for (std::uint32_t i = 0; i < World::max_bodies; ++i) {
      BodyDef<D> b;
      b.shape = shapes[i % 3];
      b.mass = 1;
      // As the piles above: 3D layers of 4 x 4 boxes and L-shapes (0.2 m), 2D rows of 8 (1 m).
      if constexpr (D == 3) {
        b.position = Vector3(Scalar(0.25) * Scalar(i % 4), Scalar(0.25) * Scalar((i / 4) % 4), Scalar(0.3) + Scalar(0.3) * Scalar(i / 16));
        b.orientation = Quaternion(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f).normalized();
      } else {
        b.position = Vector2(Scalar(1.6) * Scalar(i % 8) - 6, Scalar(1) + Scalar(1.6) * Scalar(i / 8));
        b.orientation = Rot2::from_angle(Scalar(6.283185) * rng.uniform());
      }
      REQUIRE(world->add_body(b).status == Status::ok);
    }
  }
  kept = 0;
  for (int s = 0; s < steps; ++s) {
    for (auto& world : w) REQUIRE(world->step(Scalar(1) / 60).ok());
    const detail::WorldData<D>& data = detail::SnapshotAccess::data<D>(*w[0]);
    for (std::uint32_t k = 0; k < data.touching_pairs && k < data.max_pair_hulls; ++k) kept += data.pair_hulls[k].reach > 0;
    REQUIRE(w[1]->state_hash() == w[0]->state_hash());
    REQUIRE(w[2]->state_hash() == w[0]->state_hash());
  }
}

}  // namespace

TEST_CASE("hull contacts: the box table's support map is the cube's closed form")
{
  const ContactView<3>& c = tables::box.view().contact;
  REQUIRE(c.present());
  REQUIRE(c.face_count == 6u);
  // s(u) = 0.1 (|u_x| + |u_y| + |u_z|) for a cube of half side 0.1 m; the map is exact on a cube
  // (its creases lie on grid lines) up to the 16-bit storage.
  const Vector3 dirs[] = {Vector3(1, 0, 0), Vector3(0, -1, 0), Vector3(1, 1, 1).normalized(),
                          Vector3(0.3f, -0.8f, 0.52f).normalized(), Vector3(-0.9f, 0.1f, -0.42f).normalized()};
  for (const Vector3& u : dirs) {
    const Scalar expected = Scalar(0.1) * (std::fabs(u.x()) + std::fabs(u.y()) + std::fabs(u.z()));
    CHECK(detail::support_along(c, u) == doctest::Approx(expected).epsilon(1e-3));
  }
  for (std::uint32_t k = 0; k < c.face_count; ++k) {
    CHECK(c.faces[k * face_values(3) + 3] == doctest::Approx(0.1).epsilon(1e-6));
    CHECK(c.faces[k * face_values(3) + 4] == doctest::Approx(1.0).epsilon(0.02));  // convex: no nesting
  }
}

TEST_CASE("hull contacts: a column of 10 cubes placed face to face holds its height and sleeps")
{
  for (const BodyContacts mode : {BodyContacts::hulls, BodyContacts::collision_spheres}) {
    CAPTURE(int(mode));
    WorldDef3 def;
    def.body_contacts = mode;
    auto w = std::make_unique<World3<16>>(def);
    const ShapeId box = w->add_shape(tables::box.view()).id;
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).status == Status::ok);
    for (int i = 0; i < 10; ++i) {
      BodyDef3 b;
      b.shape = box;
      b.mass = 8;
      b.position = Vector3(0, 0, Scalar(0.1) + Scalar(0.2) * Scalar(i));
      REQUIRE(w->add_body(b).status == Status::ok);
    }
    for (int s = 0; s < 180; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
    Scalar top = 0;
    bool asleep = true;
    for (std::uint32_t i = 0; i < w->body_count(); ++i) {
      top = w->body(i).position.z() > top ? w->body(i).position.z() : top;
      asleep = asleep && w->body(i).state == MotionState::asleep;
    }
    if (mode == BodyContacts::hulls) {
      CHECK(std::fabs(top / Scalar(1.9) - 1) < Scalar(0.02));
      CHECK(asleep);
    } else {
      CHECK(top / Scalar(1.9) > Scalar(1.2));  // the paper's spheres: 2 h_coll a cube
    }
  }
}

TEST_CASE("hull contacts: a body pressed deep between two sleepers wakes them, and all three part and sleep")
{
  // Three cubes of 0.2 m in a row on the ground, the outer two asleep 0.28 m apart, the middle one
  // awake between them: it overlaps each by 6 cm, 30% of the separation at which they touch.
  // Asleep, the outer ones could not give way, and the overlap correction would throw the
  // middle one from one into the other in every step (`hull_wake_overlap`).
  WorldDef3 def;
  def.body_contacts = BodyContacts::hulls;
  auto w = std::make_unique<World3<4>>(def);
  const ShapeId box = w->add_shape(tables::box.view()).id;
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).status == Status::ok);
  for (const Scalar x : {Scalar(-0.14), Scalar(0.14), Scalar(0)}) {
    BodyDef3 b;
    b.shape = box;
    b.mass = 8;
    b.position = Vector3(x, 0, Scalar(0.1));
    const BodyId id = w->add_body(b).id;
    if (x != 0) REQUIRE(w->sleep(id) == Status::ok);
  }
  for (int s = 0; s < 240; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
  Scalar overlap, lowest;
  pile_state<3>(*w, overlap, lowest);
  CHECK(overlap < Scalar(0.03));
  CHECK(w->body(0).position.x() < Scalar(-0.18));
  CHECK(w->body(1).position.x() > Scalar(0.18));
  for (std::uint32_t i = 0; i < w->body_count(); ++i) CHECK(w->body(i).state == MotionState::asleep);
}

TEST_CASE("hull contacts: 3D piles of boxes and L-shapes end asleep, above the ground, without deep overlaps")
{
  // Twelve piles: bodies held by several neighbours that slide down one into another and are
  // lifted back by the overlap correction, over and over, must still fall asleep (the sleep test
  // measures from where the slow time began). Overlaps: the aim is under 5% of the reach, which
  // some piles miss (pairs that fall asleep overlapping: tools/fidelity/README.md, "With hull
  // contacts"); the bounds keep it from getting worse.
  Scalar overlap_sum = 0, overlap_max = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    WorldDef3 def;
    def.body_contacts = BodyContacts::hulls;
    auto w = std::make_unique<World3<60>>(def);
    const ShapeId shapes[] = {w->add_shape(tables::box.view()).id, w->add_shape(tables::lshape.view()).id};
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).status == Status::ok);
    Pcg32 rng(seed, 1);
    for (int i = 0; i < 60; ++i) {
      BodyDef3 b;
      b.shape = shapes[i % 2];
      b.mass = 1;
      b.position = Vector3(Scalar(0.25) * Scalar(i % 4), Scalar(0.25) * Scalar((i / 4) % 4), Scalar(0.3) + Scalar(0.3) * Scalar(i / 16));
      b.orientation = Quaternion(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f).normalized();
      REQUIRE(w->add_body(b).status == Status::ok);
    }
    for (int s = 0; s < 900; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
    std::uint32_t asleep = 0;
    for (std::uint32_t i = 0; i < w->body_count(); ++i) asleep += w->body(i).state == MotionState::asleep ? 1u : 0u;
    CHECK(asleep == w->body_count());
    Scalar overlap, lowest;
    pile_state<3>(*w, overlap, lowest);
    CHECK(lowest > Scalar(-0.002));
    overlap_sum += overlap;
    overlap_max = overlap > overlap_max ? overlap : overlap_max;
  }
  CHECK(overlap_sum / 12 < Scalar(0.08));
  CHECK(overlap_max < Scalar(0.2));
}

TEST_CASE("hull contacts: a 2D pile of squares and L-shapes ends asleep, above the ground, without overlaps")
{
  WorldDef2 def;
  def.body_contacts = BodyContacts::hulls;
  auto w = std::make_unique<World2<100>>(def);
  const ShapeId shapes[] = {w->add_shape(tables::square2d.view()).id, w->add_shape(tables::lshape2d.view()).id};
  REQUIRE(w->add_plane(Vector2(0, 1), 0).status == Status::ok);
  Pcg32 rng(3, 1);
  for (int i = 0; i < 100; ++i) {
    BodyDef2 b;
    b.shape = shapes[i % 2];
    b.mass = 1;
    b.position = Vector2(Scalar(1.6) * Scalar(i % 10) - 8, Scalar(1) + Scalar(1.6) * Scalar(i / 10));
    b.orientation = Rot2::from_angle(Scalar(6.283185) * rng.uniform());
    REQUIRE(w->add_body(b).status == Status::ok);
  }
  for (int s = 0; s < 900; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
  std::uint32_t asleep = 0;
  for (std::uint32_t i = 0; i < w->body_count(); ++i) asleep += w->body(i).state == MotionState::asleep ? 1u : 0u;
  Scalar overlap, lowest;
  pile_state<2>(*w, overlap, lowest);
  CHECK(lowest > Scalar(-0.01));
  // The aim is every body asleep and overlaps under 5%, as in 3D; mixed 2D piles do not reach it
  // yet (pairs of sleepers keep deeper overlaps: tools/ref2d/README.md, "Hull contacts"), so
  // these bounds only keep it from getting worse.
  CHECK(asleep + 3 >= w->body_count());
  CHECK(overlap < Scalar(0.2));
}

TEST_CASE("hull contacts: 2D piles of squares end asleep and above the ground")
{
  // Twelve piles of 100 squares: a square wedged between neighbours that slides along one and is
  // pushed back by another, every few steps, must still fall asleep, within 25 s (sleeping by
  // islands, the default, a square tipping slowly off an edge keeps its island awake until it
  // rests: seed 7's last one at 16 s).
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    WorldDef2 def;
    def.body_contacts = BodyContacts::hulls;
    auto w = std::make_unique<World2<100>>(def);
    const ShapeId square = w->add_shape(tables::square2d.view()).id;
    REQUIRE(w->add_plane(Vector2(0, 1), 0).status == Status::ok);
    Pcg32 rng(seed, 1);
    for (int i = 0; i < 100; ++i) {
      BodyDef2 b;
      b.shape = square;
      b.mass = 1;
      b.position = Vector2(Scalar(1.6) * Scalar(i % 10) - 8, Scalar(1) + Scalar(1.6) * Scalar(i / 10));
      b.orientation = Rot2::from_angle(Scalar(6.283185) * rng.uniform());
      REQUIRE(w->add_body(b).status == Status::ok);
    }
    for (int s = 0; s < 1500 && w->count(MotionState::asleep) < w->body_count(); ++s)
      REQUIRE(w->step(Scalar(1) / 60).ok());
    CHECK(w->count(MotionState::asleep) == w->body_count());
    Scalar overlap, lowest;
    pile_state<2>(*w, overlap, lowest);
    CHECK(lowest > Scalar(-0.01));
  }
}

TEST_CASE("hull contacts: a body whose centre lies beyond the edge of the one below tips off and rests on the ground")
{
  // The lower body sleeps (a fixed support); the upper one is placed touching it, at rest, its
  // centre a quarter of a side in from the edge (it stays) or half a side beyond it (it falls).
  for (const Scalar overhang : {Scalar(-0.25), Scalar(0.25)}) {
    CAPTURE(overhang);
    WorldDef3 def;
    def.body_contacts = BodyContacts::hulls;
    auto w = std::make_unique<World3<4>>(def);
    const ShapeId box = w->add_shape(tables::box.view()).id;  // a cube of side 0.2 m
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).status == Status::ok);
    BodyDef3 b;
    b.shape = box;
    b.mass = 8;
    b.position = Vector3(0, 0, Scalar(0.1));
    b.asleep = true;
    REQUIRE(w->add_body(b).status == Status::ok);
    b.asleep = false;
    b.position = Vector3(Scalar(0.1) + Scalar(0.2) * overhang, Scalar(0.03), Scalar(0.3));
    REQUIRE(w->add_body(b).status == Status::ok);
    for (int s = 0; s < 300; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
    const auto& top = w->body(1);
    CHECK(top.state == MotionState::asleep);
    if (overhang < 0) {
      CHECK(top.position.z() > Scalar(0.29));
      CHECK(std::fabs(top.position.x() - Scalar(0.05)) < Scalar(1e-3));
    } else {
      CHECK(top.position.z() < Scalar(0.11));  // on the ground, on a face
      CHECK(top.position.x() > Scalar(0.2));   // beside the lower cube
    }
  }
}

TEST_CASE("hull contacts: 2D, a square whose centre lies beyond the edge of the one below tips off and rests on the ground")
{
  for (const Scalar overhang : {Scalar(-0.25), Scalar(0.25)}) {
    CAPTURE(overhang);
    WorldDef2 def;
    def.body_contacts = BodyContacts::hulls;
    auto w = std::make_unique<World2<4>>(def);
    const ShapeId square = w->add_shape(tables::square2d.view()).id;  // side 1 m
    REQUIRE(w->add_plane(Vector2(0, 1), 0).status == Status::ok);
    BodyDef2 b;
    b.shape = square;
    b.mass = 1;
    b.position = Vector2(0, Scalar(0.5));
    b.asleep = true;
    REQUIRE(w->add_body(b).status == Status::ok);
    b.asleep = false;
    b.position = Vector2(Scalar(0.5) + overhang, Scalar(1.5));
    REQUIRE(w->add_body(b).status == Status::ok);
    for (int s = 0; s < 300; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
    const auto& top = w->body(1);
    CHECK(top.state == MotionState::asleep);
    if (overhang < 0) {
      CHECK(top.position.y() > Scalar(1.45));
      CHECK(std::fabs(top.position.x() - Scalar(0.25)) < Scalar(5e-3));
    } else {
      CHECK(top.position.y() < Scalar(0.55));
      CHECK(top.position.x() > Scalar(1));
    }
  }
}

TEST_CASE("hull contacts: the distance at which two L-shapes touch changes continuously as one turns")
{
  // The runtime's own contact test (detail::body_contact, as the impact pass calls it) on two
  // L-shapes, the second turned in steps of 0.2 degrees: the largest separation along a fixed
  // line of centres at which they touch, found by bisection, may change by no more than a turn
  // of 0.2 degrees moves the body (its bounding radius times the angle, with margin). A packing
  // ratio taken from whichever candidate the hulls alone pick jumps where the pick changes
  // between a face that spans the L's hollow and one that does not.
  WorldDef2 def;
  def.body_contacts = BodyContacts::hulls;
  auto world = std::make_unique<World2<2>>(def);
  const ShapeId l = world->add_shape(tables::lshape2d.view()).id;
  BodyDef2 bd;
  bd.shape = l;
  bd.mass = 1;
  REQUIRE(world->add_body(bd).status == Status::ok);
  detail::WorldData<2> w{};
  w.def = def;
  Shape<2> shapes[1] = {world->shape(l)};
  w.shapes = shapes;
  Body<2> a = world->body(0), b = world->body(0);
  const Scalar bound = 2 * shapes[0].bounding_radius;
  const Scalar turn = Scalar(0.2) * Scalar(3.14159265) / 180;
  for (const Scalar phi : {Scalar(0), Scalar(0.7), Scalar(2.1)}) {
    CAPTURE(phi);
    const Vector2 e(std::cos(phi), std::sin(phi));
    Scalar last = -1, jump = 0;
    for (int k = 0; k < 1800; ++k) {
      b.orientation = Rot2::from_angle(turn * Scalar(k));
      Scalar lo = 0, hi = bound;
      for (int it = 0; it < 40; ++it) {
        const Scalar mid = Scalar(0.5) * (lo + hi);
        b.position = a.position + e * mid;
        Pair pair = detail::make_pair(0, 1);
        Contact<2> c;
        Scalar reach, slop;
        (detail::body_contact(w, a, b, pair, true, Scalar(0), c, reach, slop) ? lo : hi) = mid;
      }
      if (last >= 0) jump = std::fabs(lo - last) > jump ? std::fabs(lo - last) : jump;
      last = lo;
    }
    CHECK(jump < Scalar(3) * shapes[0].bounding_radius * turn);
  }
}

TEST_CASE("hull contacts: the face contacts kept between a step's passes give the bits of contacts found afresh (3D and 2D)")
{
  std::uint64_t kept = 0;
  compare_kept_contacts<3, World3<64>>(tables::box.view(), tables::lshape.view(), Scalar(0.1), 400, 5, kept);
  CHECK(kept > 1000);
  compare_kept_contacts<2, World2<64>>(tables::square2d.view(), tables::lshape2d.view(), Scalar(0.5), 400, 5, kept);
  CHECK(kept > 1000);
}

TEST_CASE("hull contacts: the broad phase lists no pair beyond the reach at which the impact pass's search could find a contact")
{
  // Two bunnies at rest, without gravity, at distances around the largest packing ratio P times the
  // sum of their bounding radii R: below it they are a candidate pair (their search decides), above
  // it never. With a plain sphere shape in the world the reach is the bounding radii's again.
  const auto pairs_at = [](Scalar fraction, bool with_sphere) {
    WorldDef3 def;
    def.gravity = Vector3::Zero();
    auto w = std::make_unique<World3<4>>(def);
    const auto bunny = w->add_shape(tables::bunny.view());
    REQUIRE(bunny.ok());
    if (with_sphere) {
      ShapeDef ball;
      ball.radius = Scalar(0.05);
      REQUIRE(w->add_shape(ball).ok());
    }
    const Shape<3>& s = w->shape(bunny.id);
    REQUIRE(s.largest_packing < Scalar(0.99));
    const Scalar d = fraction * s.largest_packing * 2 * s.bounding_radius;
    for (int i = 0; i < 2; ++i) {
      BodyDef3 b;
      b.shape = bunny.id;
      b.position = Vector3(Scalar(i) * d, 0, 1);
      REQUIRE(w->add_body(b).ok());
    }
    REQUIRE(w->step(Scalar(1) / 60).ok());
    return w->pair_count();
  };
  CHECK(pairs_at(Scalar(0.99), false) == 1);
  CHECK(pairs_at(Scalar(1.01), false) == 0);
  CHECK(pairs_at(Scalar(1.01), true) == 1);
}
