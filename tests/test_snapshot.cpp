// World snapshots (statsim/snapshot.hpp): a world loaded from a snapshot steps on bit for bit as
// the saved one; save, load, save gives the same bytes; a snapshot that is truncated, damaged,
// of another version, dimension or scalar width, too large or of other shapes, or that holds a
// value no world can have, is refused and the world is left as it was.
#include <doctest/doctest.h>

#include "support/snapshot_scene.hpp"

#include "statsim/queries.hpp"
#include "statsim/snapshot.hpp"

#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

using namespace statsim;
using statsim::testing::add_snapshot_shapes;
using statsim::testing::build_snapshot_scene;

namespace {
using Bytes = std::vector<unsigned char>;
constexpr Scalar dt = Scalar(1) / 60;
using World3s = World3<128, 8, 768, 4, 16>;
using World3l = World3<200, 8, 1200, 4, 16>;  // room for more: a smaller snapshot loads into it
using World2s = World2<128, 8, 512, 4, 16>;

template <int D>
Bytes save_bytes(const WorldCore<D>& w)
{
  Bytes b(snapshot_size(w));
  std::size_t n = 0;
  REQUIRE(save(w, b.data(), b.size(), &n) == Status::ok);
  REQUIRE(n == b.size());
  return b;
}

/// Rewrites the checksum after an edit, so that the edit itself is what `load` meets.
void reseal(Bytes& b)
{
  const std::uint64_t h = detail::fnv1a64(b.data(), b.size() - 8);
  for (int i = 0; i < 8; ++i) b[b.size() - 8 + std::size_t(i)] = static_cast<unsigned char>(h >> (8 * i));
}
void put32(Bytes& b, std::size_t at, std::uint32_t x)
{
  for (int i = 0; i < 4; ++i) b[at + std::size_t(i)] = static_cast<unsigned char>(x >> (8 * i));
}
std::uint32_t get32(const Bytes& b, std::size_t at)
{
  std::uint32_t x = 0;
  for (int i = 0; i < 4; ++i) x |= std::uint32_t(b[at + std::size_t(i)]) << (8 * i);
  return x;
}
/// Offsets in a snapshot of the layout documented in statsim/snapshot.hpp.
constexpr std::size_t def_offset = 32 + 28;
template <int D>
constexpr std::size_t sweep_axis_offset()
{
  return def_offset + 4 * D + 8 + 15 * 4 + 8;
}
template <int D>
std::size_t first_body(std::uint32_t shapes, std::uint32_t planes)
{
  return def_offset + 4 * D + 8 + 15 * 4 + 16 + 9 + 8 * shapes + planes * (D + 1) * 4;
}

/// Saves `a`, loads the bytes into `b` (which has the scene's shapes), and steps both `steps`
/// times: the state hashes agree after the load and after every step.
template <int D, class A, class B>
void check_continuation(A& a, B& b, int steps)
{
  const Bytes bytes = save_bytes<D>(a);
  CHECK(bytes.size() <= snapshot_capacity<D>(A::max_bodies, A::max_planes, A::max_shapes));
  REQUIRE(load<D>(b, bytes.data(), bytes.size()) == Status::ok);
  CHECK(b.state_hash() == a.state_hash());
  CHECK(save_bytes<D>(b) == bytes);  // the round trip gives the same bytes
  int differ = 0;
  for (int s = 0; s < steps; ++s) {
    REQUIRE(a.step(dt).status == Status::ok);
    REQUIRE(b.step(dt).status == Status::ok);
    differ += a.state_hash() != b.state_hash();
  }
  CHECK(differ == 0);
}

int anchors = 0;  // bodies saved with their step start (`detail::keeps_step_start`)

template <int D, class World>
void check_scene(const WorldDef<D>& def, int save_at, bool mixed = true)
{
  INFO("saved at step ", save_at);
  auto a = std::make_unique<World>(def);
  REQUIRE(build_snapshot_scene<D>(*a, 96, save_at));
  // What the snapshot must carry: bodies in every state, contacts, removed and reused slots.
  CHECK(a->count(MotionState::asleep) + a->count(MotionState::settling) > 0);
  CHECK(a->live_body_count() < a->body_count());
  std::uint32_t touching = 0;
  for (std::uint32_t i = 0; i < a->body_count(); ++i) {
    touching += detail::CoreAccess::data(*a).bodies[i].touching;
    anchors += detail::keeps_step_start(detail::CoreAccess::data(*a), detail::CoreAccess::data(*a).bodies[i]);
  }
  if (mixed) {
    CHECK(a->count(MotionState::moving) + a->count(MotionState::settling) > 0);
    CHECK(touching > 0);
  }
  auto b = std::make_unique<World>();
  REQUIRE(add_snapshot_shapes<D>(*b));
  check_continuation<D>(*a, *b, 240);
  // Again later in the pile, into a world of larger capacities.
  auto c = std::make_unique<World3l>();
  if constexpr (D == 3) {
    REQUIRE(add_snapshot_shapes<D>(*c));
    check_continuation<D>(*a, *c, 120);
  }
}
}  // namespace

TEST_CASE("snapshot: a loaded 3D pile steps on bit for bit (collision spheres, sweep-and-prune)")
{
  WorldDef3 def;
  def.impact_threshold = Scalar(0.5);
  for (int at : {40, 150, 220}) check_scene<3, World3s>(def, at);
}

TEST_CASE("snapshot: a loaded 3D pile steps on bit for bit (hull contacts, pile rest, grid)")
{
  WorldDef3 def;
  def.body_contacts = BodyContacts::hulls;
  def.pile_rest = true;
  def.broad_phase = BroadPhase::grid;
  def.seed = 77;
  anchors = 0;
  for (int at : {150, 180}) check_scene<3, World3s>(def, at);
  CHECK(anchors > 0);
  def.broad_phase = BroadPhase::sweep_and_prune;
  def.sweep_axis = 1;
  check_scene<3, World3s>(def, 200);
}

TEST_CASE("snapshot: a loaded 3D pile with ground hulls steps on bit for bit")
{
  WorldDef3 def;
  def.ground_hulls = true;
  for (int at : {60, 150}) check_scene<3, World3s>(def, at);
  // Snapshots keep the option (in the rest conditions' byte, so that older snapshots load with it
  // off).
  auto a = std::make_unique<World3s>(def);
  REQUIRE(add_snapshot_shapes<3>(*a));
  std::vector<unsigned char> on(snapshot_size(*a));
  REQUIRE(save(*a, on.data(), on.size(), nullptr) == Status::ok);
  auto b = std::make_unique<World3s>();
  REQUIRE(add_snapshot_shapes<3>(*b));
  REQUIRE(load(*b, on.data(), on.size()) == Status::ok);
  CHECK(b->def().ground_hulls);
}

TEST_CASE("snapshot: a loaded 2D pile steps on bit for bit")
{
  WorldDef2 def;
  for (int at : {60, 140}) check_scene<2, World2s>(def, at);
  def.body_contacts = BodyContacts::hulls;
  def.broad_phase = BroadPhase::grid;
  check_scene<2, World2s>(def, 120);
  check_scene<2, World2s>(def, 250, false);  // all asleep
}

TEST_CASE("snapshot: size per body")
{
  // One body slot: 15 bytes of integers, 17 scalars (3D) or 11 (2D), a 4-byte sweep entry.
  auto a = std::make_unique<World3s>();
  REQUIRE(add_snapshot_shapes<3>(*a));
  const std::size_t empty = snapshot_size(*a);
  REQUIRE(a->add_body(BodyDef3{}).ok());
  REQUIRE(a->step(dt).ok());
  const std::size_t per3 = snapshot_size(*a) - empty;
  auto b = std::make_unique<World2s>();
  REQUIRE(add_snapshot_shapes<2>(*b));
  const std::size_t empty2 = snapshot_size(*b);
  REQUIRE(b->add_body(BodyDef2{}).ok());
  REQUIRE(b->step(dt).ok());
  const std::size_t per2 = snapshot_size(*b) - empty2;
  std::printf("snapshot bytes per body: 3D %zu (Body<3> %zu), 2D %zu (Body<2> %zu); empty 3D world %zu\n", per3,
              sizeof(Body<3>), per2, sizeof(Body<2>), empty);
  CHECK(per3 == 15 + 17 * sizeof(Scalar) + 4);
  CHECK(per2 == 15 + 11 * sizeof(Scalar) + 4);
  CHECK(snapshot_capacity<3>(1, 0, 2) == empty + per3 + 12);  // the one body with an anchor
  CHECK(snapshot_capacity<2>(1, 0, 2) == empty2 + per2 + 8);
  CHECK(per3 <= sizeof(Body<3>));
  CHECK(per2 <= sizeof(Body<2>));
}

TEST_CASE("snapshot: save into a buffer too small writes nothing past it")
{
  auto a = std::make_unique<World3s>();
  REQUIRE(build_snapshot_scene<3>(*a, 40, 30));
  const std::size_t need = snapshot_size(*a);
  Bytes buf(need + 16, 0xab);
  std::size_t n = 0;
  CHECK(save(*a, buf.data(), need - 1, &n) == Status::capacity_exceeded);
  CHECK(n == need);
  for (unsigned char c : buf) REQUIRE(c == 0xab);
  CHECK(save(*a, nullptr, 0, &n) == Status::capacity_exceeded);
  CHECK(save(*a, buf.data(), buf.size(), &n) == Status::ok);
  for (std::size_t i = need; i < buf.size(); ++i) REQUIRE(buf[i] == 0xab);
}

TEST_CASE("snapshot: refused loads leave the world as it was")
{
  auto a = std::make_unique<World3s>();
  REQUIRE(build_snapshot_scene<3>(*a, 96, 150));
  const Bytes good = save_bytes<3>(*a);
  // The target: another pile, and its twin that no load is tried on.
  WorldDef3 other;
  other.seed = 5;
  auto t = std::make_unique<World3s>(other);
  auto twin = std::make_unique<World3s>(other);
  REQUIRE(build_snapshot_scene<3>(*t, 60, 100));
  REQUIRE(build_snapshot_scene<3>(*twin, 60, 100));
  const std::uint64_t h0 = t->state_hash();
  REQUIRE(h0 == twin->state_hash());
  int accepted = 0, changed = 0;
  const auto refused = [&](const Bytes& b, std::size_t n) {
    const Status s = load(*t, b.data(), n);
    accepted += s == Status::ok;
    changed += t->state_hash() != h0;
    return s;
  };
  SUBCASE("truncated, too long, every byte flipped")
  {
    for (std::size_t n = 0; n < good.size(); ++n) CHECK(refused(good, n) != Status::ok);
    Bytes longer = good;
    longer.push_back(0);
    CHECK(refused(longer, longer.size()) == Status::invalid_snapshot);
    for (std::size_t i = 0; i < good.size(); ++i) {
      Bytes b = good;
      b[i] ^= static_cast<unsigned char>(1u << (i % 8));
      CHECK(refused(b, b.size()) != Status::ok);
    }
  }
  SUBCASE("wrong version, dimension, scalar width, broad-phase storage")
  {
    Bytes b = good;
    b[4] = 1;  // the version before `WorldDef::sleep_islands`
    reseal(b);
    CHECK(refused(b, b.size()) == Status::snapshot_incompatible);
    b = good;
    b[7] = 8;  // a snapshot of a double build
    reseal(b);
    CHECK(refused(b, b.size()) == Status::snapshot_incompatible);
    auto flat = std::make_unique<World2s>();
    REQUIRE(add_snapshot_shapes<2>(*flat));
    const std::uint64_t hf = flat->state_hash();
    CHECK(load(*flat, good.data(), good.size()) == Status::snapshot_incompatible);
    CHECK(flat->state_hash() == hf);
    auto sweep_only = std::make_unique<World3<128, 8, 768, 4, 16, BroadPhase::sweep_and_prune>>();
    REQUIRE(add_snapshot_shapes<3>(*sweep_only));
    CHECK(load(*sweep_only, good.data(), good.size()) == Status::snapshot_incompatible);
  }
  SUBCASE("too large, other shapes")
  {
    auto small = std::make_unique<World3<32, 8, 192, 4>>();
    REQUIRE(add_snapshot_shapes<3>(*small));
    const std::uint64_t hs = small->state_hash();
    CHECK(load(*small, good.data(), good.size()) == Status::capacity_exceeded);
    CHECK(small->state_hash() == hs);
    auto swapped = std::make_unique<World3s>();
    ShapeDef ball;
    ball.radius = 0.08f;
    REQUIRE(swapped->add_shape(ball).ok());
    REQUIRE(swapped->add_shape(statsim::tables::box.view()).ok());
    CHECK(load(*swapped, good.data(), good.size()) == Status::shape_mismatch);
    auto one = std::make_unique<World3s>();
    REQUIRE(one->add_shape(statsim::tables::box.view()).ok());
    CHECK(load(*one, good.data(), good.size()) == Status::shape_mismatch);
    auto scaled = std::make_unique<World3s>();
    REQUIRE(scaled->add_shape(statsim::tables::box.view(), Scalar(1.5)).ok());
    REQUIRE(scaled->add_shape(ball).ok());
    CHECK(load(*scaled, good.data(), good.size()) == Status::shape_mismatch);
  }
  SUBCASE("values no world can hold, under a valid checksum")
  {
    const std::size_t body = first_body<3>(2, 5);
    const std::size_t position = body + 15 + 16;
    const std::uint32_t entries = get32(good, 28);
    const std::size_t order = good.size() - 8 - 4 * std::size_t(entries);
    struct Edit {
      std::size_t at;
      std::uint32_t value;
      Status expected;
    };
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::uint32_t nan_bits, two_bits, far_bits, tiny_bits, wider_bits;
    const float two = 2, far = 2e6f, tiny = 1e-30f, wider = 0.09f;
    std::memcpy(&nan_bits, &nan, 4);
    std::memcpy(&two_bits, &two, 4);
    std::memcpy(&far_bits, &far, 4);
    std::memcpy(&tiny_bits, &tiny, 4);
    std::memcpy(&wider_bits, &wider, 4);
    // The collision radius follows the flags byte, 2 + 2 + 1 + 1 bytes of generation, shape,
    // state and pose, the 8-byte random state, the orientation and three vectors; bodies that
    // keep their step start (flag 16) have it after the four scalars. The first ball (shape 1):
    const auto radius_at = [](std::size_t at) { return at + 15 + 16 + 3 * 12; };
    std::size_t ball = body;
    while (ball + 80 < good.size() && (get32(good, ball + 3) & 0xffffu) != 1)
      ball = radius_at(ball) + 16 + ((good[ball] & 16) ? 12 : 0);
    REQUIRE(ball + 80 < good.size());
    const Edit edits[] = {
        {position, nan_bits, Status::non_finite},
        {position, far_bits, Status::out_of_range},
        {body + 15, two_bits, Status::non_unit_quaternion},
        {body + 3, 0x00ff0000u | get32(good, body + 3), Status::invalid_snapshot},  // motion state 255
        {body + 3, (0xffff0000u & get32(good, body + 3)) | 9u, Status::invalid_shape},  // shape 9
        // Shape 2049, whose low `shape_index_bits` (11) name shape 1: `Body::shape` keeps only those.
        {body + 3, (0xffff0000u & get32(good, body + 3)) | 2049u, Status::invalid_shape},
        {sweep_axis_offset<3>(), 5, Status::invalid_parameter},
        {order, get32(good, order + 4), Status::invalid_snapshot},  // a slot twice in the sweep order
        {order, entries, Status::invalid_snapshot},                 // a slot past the end
        {20, 8, Status::ok},                                        // more planes than written
        {def_offset - 4, 0x7f800000u, Status::invalid_snapshot},    // widest: no shape's diameter
        {radius_at(body), tiny_bits, Status::invalid_radius},       // below limits::min_radius
        {radius_at(ball), wider_bits, Status::invalid_radius},      // a ball of 0.08 m at 0.09 m
    };
    for (const Edit& e : edits) {
      Bytes b = good;
      put32(b, e.at, e.value);
      reseal(b);
      CAPTURE(e.at);
      const Status s = refused(b, b.size());
      // (ok as expected: any refusal)
      CHECK((e.expected == Status::ok ? s != Status::ok : s == e.expected));
    }
  }
  CHECK(accepted == 0);
  CHECK(changed == 0);
  // Nothing a step reads changed either (the sweep order check writes only scratch).
  int differ = 0;
  for (int s = 0; s < 60; ++s) {
    REQUIRE(t->step(dt).ok());
    REQUIRE(twin->step(dt).ok());
    differ += t->state_hash() != twin->state_hash();
  }
  CHECK(differ == 0);
}

TEST_CASE("snapshot: queries after a load find what testing every body finds")
{
  // World b has stepped a scene of its own, so its broad phase's records are those of other
  // bodies in other places; after the load the queries must not search them.
  WorldDef3 def;
  def.broad_phase = BroadPhase::grid;
  auto a = std::make_unique<World3s>(def);
  REQUIRE(build_snapshot_scene<3>(*a, 96, 90));
  auto b = std::make_unique<World3s>(def);
  REQUIRE(build_snapshot_scene<3>(*b, 64, 200));
  const Bytes bytes = save_bytes<3>(*a);
  REQUIRE(load<3>(*b, bytes.data(), bytes.size()) == Status::ok);
  int compared = 0, differ = 0;
  for (int i = -5; i <= 5; ++i)
    for (int j = -5; j <= 5; ++j)
      for (int k = 0; k < 8; ++k) {
        const Vector3 c(Scalar(i) * 0.1f, Scalar(j) * 0.1f, Scalar(k) * 0.1f);
        std::vector<BodyId> searched, scanned;
        QueryStats st;
        const Status s = overlap_sphere<3>(*b, c, 0.15f, [&](const QueryHit<3>& h) {
          if (h.body != no_body) searched.push_back(h.body);
          return true;
        });
        REQUIRE(s == Status::ok);
        detail::overlap_sphere_scan(detail::CoreAccess::data(*b), c, Scalar(0.15f), [&](const QueryHit<3>& h) {
          if (h.body != no_body) scanned.push_back(h.body);
          return true;
        }, st);
        compared += !scanned.empty();
        differ += searched != scanned;
      }
  CHECK(compared > 20);
  CHECK(differ == 0);
}
