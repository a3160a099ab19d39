#include <doctest/doctest.h>

#include "statsim/world3.hpp"
#include "statsim/world2.hpp"

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

using namespace statsim;

namespace {

using PairList = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

PairList sorted(PairList p)
{
  for (auto& x : p)
    if (x.first > x.second) std::swap(x.first, x.second);
  std::sort(p.begin(), p.end());
  return p;
}

struct Sphere {
  Vector3 c;
  float r;
};

/// `n` spheres of radius 0.05 to 0.4 centred in |x|, |y| <= 3 and |z| <= 1 (z = 0 when `flat`).
std::vector<Sphere> random_spheres(Pcg32& rng, int n, bool flat)
{
  std::vector<Sphere> spheres(n);
  for (Sphere& s : spheres) {
    s.c = Vector3(rng.uniform(-3, 3), rng.uniform(-3, 3), flat ? 0.0f : rng.uniform(-1, 1));
    s.r = rng.uniform(0.05f, 0.4f);
  }
  return spheres;
}

PairList brute_force(const std::vector<Sphere>& s)
{
  PairList out;
  for (std::uint32_t i = 0; i < s.size(); ++i)
    for (std::uint32_t j = i + 1; j < s.size(); ++j) {
      const float reach = s[i].r + s[j].r;
      if ((s[i].c - s[j].c).squaredNorm() <= reach * reach) out.emplace_back(i, j);
    }
  return out;
}

PairList sweep_and_prune(std::vector<SweepEntry>& entries, const std::vector<Sphere>& s, int axis)
{
  for (auto& e : entries) {
    e.lo = s[e.body].c[axis] - s[e.body].r;
    e.hi = s[e.body].c[axis] + s[e.body].r;
  }
  detail::insertion_sort(entries.data(), std::uint32_t(entries.size()));
  for (std::size_t i = 1; i < entries.size(); ++i) REQUIRE(entries[i - 1].lo <= entries[i].lo);
  // All entries active: sweep_active reports every overlapping interval pair once.
  float widest = 0;
  for (const auto& e : entries) widest = std::max(widest, e.hi - e.lo);
  PairList out;
  detail::sweep_active(entries.data(), std::uint32_t(entries.size()), widest, [&](std::uint32_t a, std::uint32_t b) {
    const float reach = s[a].r + s[b].r;
    if ((s[a].c - s[b].c).squaredNorm() <= reach * reach) out.emplace_back(a, b);
  });
  return sorted(out);
}

}  // namespace

TEST_CASE("sweep-and-prune finds exactly the brute-force pairs - also after many incremental steps")
{
  Pcg32 rng(11, 0);
  for (int scene = 0; scene < 6; ++scene) {
    const int n = 50 + 60 * scene;
    std::vector<Sphere> s = random_spheres(rng, n, false);
    std::vector<Vector3> vel(n);
    for (Vector3& v : vel) v = Vector3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)) * 0.05f;
    std::vector<SweepEntry> entries(n);
    for (int i = 0; i < n; ++i) entries[i] = detail::sweep_entry(std::uint32_t(i), true);
    const int axis = scene % 3;
    std::size_t total = 0;
    for (int step = 0; step < 80; ++step) {
      const PairList got = sweep_and_prune(entries, s, axis);
      const PairList want = brute_force(s);
      REQUIRE(got == want);
      total += want.size();
      for (int i = 0; i < n; ++i) {
        s[i].c += vel[i];
        // Bounce inside the box so the scene keeps mixing.
        for (int k = 0; k < 3; ++k)
          if (std::abs(s[i].c[k]) > (k == 2 ? 1.0f : 3.0f)) vel[i][k] = -vel[i][k];
      }
    }
    CHECK(total > 0);  // the scenes do produce pairs
  }
}

TEST_CASE("sweep over active entries finds exactly the pairs with an active member")
{
  Pcg32 rng(12, 0);
  for (int scene = 0; scene < 6; ++scene) {
    const int n = 100 + 80 * scene;
    const std::vector<Sphere> s = random_spheres(rng, n, true);
    std::vector<SweepEntry> entries(n);
    std::vector<bool> active(n);
    float widest = 0;
    for (int i = 0; i < n; ++i) {
      widest = std::max(widest, 2 * s[i].r);
      active[i] = rng.uniform() < 0.2f * float(scene);
      entries[i] = detail::sweep_entry(std::uint32_t(i), active[i]);
      entries[i].lo = s[i].c.x() - s[i].r;
      entries[i].hi = s[i].c.x() + s[i].r;
    }
    detail::insertion_sort(entries.data(), std::uint32_t(n));
    PairList got;
    detail::sweep_active(entries.data(), std::uint32_t(n), widest, [&](std::uint32_t a, std::uint32_t b) {
      const float reach = s[a].r + s[b].r;
      if ((s[a].c - s[b].c).squaredNorm() <= reach * reach) got.emplace_back(a, b);
    });
    PairList want;
    for (const auto& p : brute_force(s))
      if (active[p.first] || active[p.second]) want.push_back(p);
    const PairList sorted_got = sorted(got);
    REQUIRE(sorted_got == want);
    REQUIRE(std::adjacent_find(sorted_got.begin(), sorted_got.end()) == sorted_got.end());  // no pair twice
  }
}

TEST_CASE("world broad phase: pairs equal brute force on bounding spheres - skipping sleeping pairs")
{
  // Collision spheres are tiny, so no contact moves a body and the end-of-step positions are the
  // positions the broad phase saw. With hull contacts both broad phases look as far as the
  // bounding spheres (`detail::pair_radius`).
  for (BroadPhase bp : {BroadPhase::grid, BroadPhase::sweep_and_prune, BroadPhase::automatic}) {
  CAPTURE(int(bp));
  WorldDef3 def;
  def.gravity = Vector3::Zero();
  def.broad_phase = bp;
  def.body_contacts = BodyContacts::hulls;
  auto world = std::make_unique<World3<400, 8, 4000>>(def);
  ShapeDef small;
  small.radius = 1e-4f;
  small.bounding_radius = 0.3f;
  const ShapeId shape = world->add_shape(small).id;
  Pcg32 rng(21, 0);
  for (int i = 0; i < 400; ++i) {
    BodyDef3 b;
    b.shape = shape;
    b.position = Vector3(rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-2, 2));
    b.linear_velocity = Vector3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    b.asleep = i % 5 == 0;
    REQUIRE(world->add_body(b).ok());
  }
  for (int step = 0; step < 120; ++step) {
    const StepResult r = world->step(1.0f / 60);
    REQUIRE(r.ok());
    REQUIRE(r.contacts == 0);
    PairList want;
    for (std::uint32_t i = 0; i < world->body_count(); ++i)
      for (std::uint32_t j = i + 1; j < world->body_count(); ++j) {
        const Body3& a = world->body(i);
        const Body3& b = world->body(j);
        if (a.state == MotionState::asleep && b.state == MotionState::asleep) continue;
        const float reach = world->shape_of(a).bounding_radius + world->shape_of(b).bounding_radius;
        if ((a.position - b.position).squaredNorm() <= reach * reach) want.emplace_back(i, j);
      }
    PairList got;
    for (std::uint32_t k = 0; k < world->pair_count(); ++k) got.emplace_back(world->pairs()[k].a, world->pairs()[k].b);
    REQUIRE(sorted(got) == want);
    REQUIRE(r.pairs_found == want.size());
  }
  }
}

namespace {

// A pile in which contacts move bodies: the order pairs are found in shapes the result, so equal
// bits mean the same broad phase ran. Hashes the bodies only: `state_hash` also covers the
// parameters, which differ between the worlds compared.
template <class WorldT = World2<200>>
std::uint64_t pile_hash(BroadPhase bp, std::uint32_t grid_above, std::uint32_t bodies)
{
  WorldDef2 def;
  def.broad_phase = bp;
  def.grid_above_bodies = grid_above;
  auto world = std::make_unique<WorldT>(def);
  ShapeDef disc;
  disc.radius = 0.3f;
  disc.bounding_radius = 0.3f;
  const ShapeId shape = world->add_shape(disc).id;
  REQUIRE(world->add_plane(Vector2(0, 1), 0).ok());
  Pcg32 rng(5, 0);
  for (std::uint32_t i = 0; i < bodies; ++i) {
    BodyDef2 b;
    b.shape = shape;
    b.position = Vector2(rng.uniform(-2, 2), rng.uniform(0.3f, 8));
    REQUIRE(world->add_body(b).ok());
  }
  for (int step = 0; step < 200; ++step) REQUIRE(world->step(1.0f / 60).ok());
  detail::Fnv1a h;
  for (std::uint32_t i = 0; i < world->body_count(); ++i) {
    h.add_vec(world->body(i).position);
    h.add_vec(world->body(i).linear_velocity);
    h.add_spin(world->body(i).angular_velocity);
  }
  return h.value;
}

}  // namespace

TEST_CASE("automatic broad phase: sweep-and-prune up to the threshold and the grid above it")
{
  const std::uint64_t sap = pile_hash(BroadPhase::sweep_and_prune, 2048, 120);
  const std::uint64_t grid = pile_hash(BroadPhase::grid, 2048, 120);
  REQUIRE(sap != grid);  // else this scene could not tell them apart
  CHECK(pile_hash(BroadPhase::automatic, 120, 120) == sap);   // 120 bodies, not above 120
  CHECK(pile_hash(BroadPhase::automatic, 119, 120) == grid);  // above 119: the grid
  CHECK(WorldDef3{}.broad_phase == BroadPhase::automatic);
}

TEST_CASE("world broad phase with shapes of different bounding radii: pairs equal brute force")
{
  for (BroadPhase bp : {BroadPhase::grid, BroadPhase::sweep_and_prune}) {
    CAPTURE(int(bp));
    WorldDef3 def;
    def.gravity = Vector3::Zero();
    def.broad_phase = bp;
    def.body_contacts = BodyContacts::hulls;  // both broad phases look as far as the bounding spheres
    auto world = std::make_unique<World3<300, 8, 3000>>(def);
    ShapeDef large, small;
    large.radius = small.radius = 1e-4f;  // no contact moves a body
    large.bounding_radius = 0.35f;
    small.bounding_radius = 0.12f;
    const ShapeId shapes[2] = {world->add_shape(large).id, world->add_shape(small).id};
    Pcg32 rng(23, 0);
    for (int i = 0; i < 300; ++i) {
      BodyDef3 b;
      b.shape = shapes[i % 3 == 0 ? 0 : 1];
      b.position = Vector3(rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-1, 1));
      b.linear_velocity = Vector3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
      REQUIRE(world->add_body(b).ok());
    }
    std::size_t total = 0;
    for (int step = 0; step < 30; ++step) {
      REQUIRE(world->step(1.0f / 60).ok());
      PairList want;
      for (std::uint32_t i = 0; i < world->body_count(); ++i)
        for (std::uint32_t j = i + 1; j < world->body_count(); ++j) {
          const Body3& a = world->body(i);
          const Body3& b = world->body(j);
          const float reach = world->shape_of(a).bounding_radius + world->shape_of(b).bounding_radius;
          if ((a.position - b.position).squaredNorm() <= reach * reach) want.emplace_back(i, j);
        }
      PairList got;
      for (std::uint32_t k = 0; k < world->pair_count(); ++k) got.emplace_back(world->pairs()[k].a, world->pairs()[k].b);
      REQUIRE(sorted(got) == want);
      total += want.size();
    }
    CHECK(total > 0);
  }
}

TEST_CASE("at collision spheres both broad phases look as far as the spheres and a margin, not the bounding spheres")
{
  // Bodies at rest without gravity: the broad phase of the first step sees them where they were
  // placed. Two shapes whose collision spheres are well inside their bounding spheres.
  for (BroadPhase bp : {BroadPhase::grid, BroadPhase::sweep_and_prune}) {
    CAPTURE(int(bp));
    std::size_t total = 0, beyond_spheres = 0;
    for (std::uint32_t seed = 1; seed <= 10; ++seed) {
      WorldDef3 def;
      def.gravity = Vector3::Zero();
      def.broad_phase = bp;
      def.body_contacts = BodyContacts::collision_spheres;
      auto world = std::make_unique<World3<300, 8, 3000>>(def);
      ShapeDef large, small;
      large.radius = 0.15f;
      large.bounding_radius = 0.4f;
      small.radius = 0.1f;
      small.bounding_radius = 0.105f;  // its sphere and margin reach beyond: the bound holds
      const ShapeId shapes[2] = {world->add_shape(large).id, world->add_shape(small).id};
      Pcg32 rng(seed, 0);
      std::vector<Vector3> at;
      for (int i = 0; i < 300; ++i) {
        BodyDef3 b;
        b.shape = shapes[i % 3 == 0 ? 0 : 1];
        b.position = Vector3(rng.uniform(-2.5f, 2.5f), rng.uniform(-2.5f, 2.5f), rng.uniform(-1, 1));
        b.asleep = i % 7 == 0;
        at.push_back(b.position);
        REQUIRE(world->add_body(b).ok());
      }
      REQUIRE(world->step(1.0f / 60).ok());
      const auto reach_of = [&](std::uint32_t i) {
        const ShapeDef& s = i % 3 == 0 ? large : small;
        return std::min(s.bounding_radius, s.radius * (1 + detail::pair_margin));
      };
      PairList want;
      for (std::uint32_t i = 0; i < 300; ++i)
        for (std::uint32_t j = i + 1; j < 300; ++j) {
          if (i % 7 == 0 && j % 7 == 0) continue;  // two sleepers
          const float reach = reach_of(i) + reach_of(j);
          const float d2 = (at[i] - at[j]).squaredNorm();
          if (d2 > reach * reach) continue;
          want.emplace_back(i, j);
          const float spheres = (i % 3 == 0 ? large : small).radius + (j % 3 == 0 ? large : small).radius;
          if (d2 > spheres * spheres) ++beyond_spheres;
        }
      PairList got;
      for (std::uint32_t k = 0; k < world->pair_count(); ++k) got.emplace_back(world->pairs()[k].a, world->pairs()[k].b);
      REQUIRE(sorted(got) == want);
      total += want.size();
    }
    MESSAGE(total << " candidate pairs, " << beyond_spheres << " of them not touching");
    CHECK(total > 400);
    CHECK(beyond_spheres * 5 < total);
  }
}

TEST_CASE("a world with storage for sweep-and-prune only: smaller, sweeps at any size, refuses the grid")
{
  using SweepOnly = World2<200, 8, 6 * 200, 8, 0, BroadPhase::sweep_and_prune>;
  CHECK(sizeof(SweepOnly) < sizeof(World2<200>));
  const std::uint64_t sap = pile_hash(BroadPhase::sweep_and_prune, 2048, 120);
  CHECK(pile_hash<SweepOnly>(BroadPhase::sweep_and_prune, 2048, 120) == sap);
  CHECK(pile_hash<SweepOnly>(BroadPhase::automatic, 119, 120) == sap);  // with the grid's storage: the grid
  WorldDef2 grid;
  grid.broad_phase = BroadPhase::grid;
  auto world = std::make_unique<SweepOnly>();
  CHECK(world->configure(grid) == Status::invalid_parameter);
  CHECK(world->def().broad_phase == BroadPhase::automatic);
  auto refused = std::make_unique<SweepOnly>(grid);
  CHECK(refused->construction_status() == Status::invalid_parameter);
  CHECK(refused->def().broad_phase == BroadPhase::automatic);
}

TEST_CASE("pair buffer overflow is reported with the number dropped")
{
  World2<20, 2, 10> world;
  ShapeDef shape;
  shape.radius = 0.5f;
  REQUIRE(world.add_shape(shape).ok());
  for (int i = 0; i < 20; ++i) {
    BodyDef2 b;
    b.position = Vector2(0.04f * float(i), 5);  // all within reach of each other: 190 pairs
    REQUIRE(world.add_body(b).ok());
  }
  const StepResult r = world.step(1.0f / 60);
  CHECK(r.status == Status::ok);
  CHECK((r.overflow & overflow_pairs) != 0);
  CHECK(!r.ok());
  CHECK(r.pairs_found == 190);
  CHECK(r.pairs_dropped == 180);
  CHECK(world.pair_count() == 10);
}

TEST_CASE("a pair record is 8 bytes and a sweep entry 12: indices, witness and awake bit survive their bit-fields")
{
  // The firmware's RAM per body counts several pair records and one entry (examples/firmware/README.md).
  CHECK(sizeof(Pair) == 8);
  CHECK(sizeof(SweepEntry) == 2 * sizeof(Scalar) + 4);
  const std::uint32_t last = (1u << body_index_bits) - 1;
  Pair p = detail::make_pair(last - 1, last);
  const Pair& q = p;  // doctest binds its operands by reference: a const one copies a bit-field
  CHECK(q.a == last - 1);
  CHECK(q.b == last);
  CHECK(q.witness == 0);
  p.witness = detail::no_witness;
  CHECK(q.witness == detail::no_witness);
  CHECK(q.b == last);
  p.witness = 2 * max_contact_faces;  // the highest candidate of two shapes
  CHECK(q.witness == 2 * max_contact_faces);
  const SweepEntry e = detail::sweep_entry(last, true);
  CHECK(e.body == last);
  CHECK(e.active == 1);
  CHECK(detail::sweep_entry(last, false).active == 0);
}
