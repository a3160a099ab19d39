// Compile-time feature sets (statsim/features.hpp): a world refuses, changing nothing, what its
// features leave out, and a scene steps bit for bit the same under every set that covers it.
// (That the code left out is not compiled is tests/api/features_code.cmake's.)
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/queries.hpp"
#include "statsim/snapshot.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/square2d.hpp"

#include <cmath>
#include <memory>
#include <vector>

using namespace statsim;

namespace {
constexpr BroadPhase sweep_only = BroadPhase::sweep_and_prune;
template <Features F>
using Small3 = World3<64, 8, 64 * 24, 4, 0, sweep_only, F>;
template <Features F>
using Small2 = World2<64, 8, 64 * 24, 4, 0, sweep_only, F>;

/// Boxes (or squares) and spheres dropped into a walled box, stepped 300 times: the hash.
template <int D, class World, class Sig>
std::uint64_t drop_scene(World& w, const Sig& table, const WorldDef<D>& def, bool tilted)
{
  using Vec = typename Space<D>::Vec;
  REQUIRE(w.configure(def) == Status::ok);
  const ShapeId box = w.add_shape(table.view()).id;
  ShapeDef ball;
  ball.radius = 0.08f;
  const ShapeId sphere = w.add_shape(ball).id;
  Vec floor = Vec::Unit(Space<D>::up_axis);
  if (tilted) floor[0] = 0.3f;  // 17 degrees
  REQUIRE(w.add_plane(floor, 0).ok());
  REQUIRE(w.add_plane(Vec::Unit(0), -1).ok());
  REQUIRE(w.add_plane(-Vec::Unit(0), -1).ok());
  Pcg32 g(7, 3);
  for (int i = 0; i < 64; ++i) {
    BodyDef<D> b;
    b.shape = i % 4 == 0 ? sphere : box;
    b.mass = 1;
    for (int k = 0; k < D; ++k) b.position[k] = g.uniform(-0.7f, 0.7f);
    b.position[Space<D>::up_axis] = 0.3f + 0.25f * float(i / 4);
    if constexpr (D == 3) {
      b.orientation = Quaternion(g.uniform() - 0.5f, g.uniform() - 0.5f, g.uniform() - 0.5f, g.uniform() - 0.5f).normalized();
      b.angular_velocity = Vector3(g.uniform(-3, 3), g.uniform(-3, 3), g.uniform(-3, 3));
    } else {
      b.orientation = Rot2::from_angle(6.283185f * g.uniform());
      b.angular_velocity = g.uniform(-3, 3);
    }
    REQUIRE(w.add_body(b).ok());
  }
  for (int s = 0; s < 300; ++s) REQUIRE(w.step(1.0f / 60).ok());
  return w.state_hash();
}
}  // namespace

TEST_CASE("features: a scene hashes the same under every feature set that covers it")
{
  // Collision spheres on level ground: `paper` covers it, and so do the larger sets.
  WorldDef3 d3;
  WorldDef2 d2;
  d3.body_contacts = BodyContacts::collision_spheres;
  d2.body_contacts = BodyContacts::collision_spheres;
  const auto all3 = std::make_unique<Small3<Features::all>>();
  const std::uint64_t h3 = drop_scene<3>(*all3, tables::box, d3, false);
  CHECK(drop_scene<3>(*std::make_unique<Small3<Features::paper>>(), tables::box, d3, false) == h3);
  CHECK(drop_scene<3>(*std::make_unique<Small3<Features::piles>>(), tables::box, d3, false) == h3);
  CHECK(drop_scene<3>(*std::make_unique<Small3<Features::paper | Features::slopes>>(), tables::box, d3, false) == h3);
  const std::uint64_t h2 = drop_scene<2>(*std::make_unique<Small2<Features::all>>(), tables::square2d, d2, false);
  CHECK(drop_scene<2>(*std::make_unique<Small2<Features::paper>>(), tables::square2d, d2, false) == h2);
  // Hull contacts, asked for or by default (`automatic`): `piles`.
  for (const BodyContacts contacts : {BodyContacts::hulls, BodyContacts::automatic}) {
    CAPTURE(int(contacts));
    d3.body_contacts = contacts;
    d2.body_contacts = contacts;
    const std::uint64_t p3 = drop_scene<3>(*std::make_unique<Small3<Features::all>>(), tables::box, d3, false);
    CHECK(p3 != h3);
    CHECK(drop_scene<3>(*std::make_unique<Small3<Features::piles>>(), tables::box, d3, false) == p3);
    const std::uint64_t p2 = drop_scene<2>(*std::make_unique<Small2<Features::all>>(), tables::square2d, d2, false);
    CHECK(drop_scene<2>(*std::make_unique<Small2<Features::piles>>(), tables::square2d, d2, false) == p2);
  }
  // The default in a world without hull contacts: the bodies step as with collision spheres (the
  // hash differs by the parameter alone).
  {
    d3.body_contacts = BodyContacts::automatic;
    const auto by_default = std::make_unique<Small3<Features::paper>>();
    drop_scene<3>(*by_default, tables::box, d3, false);
    d3.body_contacts = BodyContacts::collision_spheres;
    const auto spheres = std::make_unique<Small3<Features::paper>>();
    drop_scene<3>(*spheres, tables::box, d3, false);
    REQUIRE(by_default->body_count() == spheres->body_count());
    for (std::uint32_t i = 0; i < spheres->body_count(); ++i) {
      CHECK(by_default->body(i).position == spheres->body(i).position);
      CHECK(by_default->body(i).orientation.coeffs() == spheres->body(i).orientation.coeffs());
    }
    d3.body_contacts = BodyContacts::hulls;
  }
  // A tilted floor: `paper | slopes`, with and without hull contacts.
  const std::uint64_t s3 = drop_scene<3>(*std::make_unique<Small3<Features::all>>(), tables::box, d3, true);
  CHECK(drop_scene<3>(*std::make_unique<Small3<Features::piles | Features::slopes>>(), tables::box, d3, true) == s3);
  d3.body_contacts = BodyContacts::collision_spheres;
  const std::uint64_t t3 = drop_scene<3>(*std::make_unique<Small3<Features::all>>(), tables::box, d3, true);
  CHECK(drop_scene<3>(*std::make_unique<Small3<Features::paper | Features::slopes>>(), tables::box, d3, true) == t3);
  const std::uint64_t t2 = drop_scene<2>(*std::make_unique<Small2<Features::all>>(), tables::square2d, d2, true);
  CHECK(drop_scene<2>(*std::make_unique<Small2<Features::piles | Features::slopes>>(), tables::square2d, d2, true) == t2);
}

TEST_CASE("features: plain spheres need no feature at all")
{
  const auto run = [](auto& w) {
    ShapeDef ball;
    ball.radius = 0.1f;
    const ShapeId s = w.add_shape(ball).id;
    REQUIRE(w.add_plane(Vector3(0, 0, 1), 0).ok());
    for (int i = 0; i < 40; ++i) {
      BodyDef3 b;
      b.shape = s;
      b.mass = 1;
      b.position = Vector3(0.05f * float(i % 5), 0.03f * float(i % 3), 0.3f + 0.22f * float(i));
      REQUIRE(w.add_body(b).ok());
    }
    for (int k = 0; k < 200; ++k) REQUIRE(w.step(1.0f / 60).ok());
    return w.state_hash();
  };
  const auto all = std::make_unique<World3<40>>();
  const auto spheres = std::make_unique<World3<40, 8, 240, 8, 0, BroadPhase::automatic, Features::spheres>>();
  CHECK(run(*spheres) == run(*all));
  CHECK(spheres->features() == Features::spheres);
  CHECK(all->features() == Features::all);
}

TEST_CASE("features: a world refuses what its features leave out, changing nothing")
{
  SUBCASE("statistical shapes")
  {
    const auto w = std::make_unique<World3<4, 8, 24, 4, 0, BroadPhase::automatic, Features::spheres>>();
    const Added<ShapeId> a = w->add_shape(tables::box.view());
    CHECK(a.status == Status::not_compiled);
    CHECK(w->add_shape(tables::box.view(), 2).status == Status::not_compiled);
    CHECK(w->shape_count() == 0);
    ShapeDef ball;
    CHECK(w->add_shape(ball).ok());
  }
  SUBCASE("hull contacts")
  {
    WorldDef3 def;
    def.body_contacts = BodyContacts::hulls;
    const auto refused = std::make_unique<Small3<Features::paper>>(def);
    CHECK(refused->construction_status() == Status::not_compiled);
    CHECK(refused->def().body_contacts == BodyContacts::automatic);  // the default, kept
    CHECK(refused->configure(def) == Status::not_compiled);
    CHECK(refused->def().body_contacts == BodyContacts::automatic);
    const auto accepted = std::make_unique<Small3<Features::piles>>(def);
    CHECK(accepted->construction_status() == Status::ok);
    // The default asks for no feature: without hull contacts it means collision spheres.
    CHECK(std::make_unique<Small3<Features::paper>>()->construction_status() == Status::ok);
  }
  SUBCASE("tilted planes, and a gravity that tilts a plane")
  {
    const auto w = std::make_unique<Small3<Features::piles>>();
    CHECK(w->add_plane(Vector3(0.2f, 0, 1), 0).status == Status::not_compiled);
    CHECK(w->plane_count() == 0);
    // Level ground and walls carry no pull along them.
    CHECK(w->add_plane(Vector3(0, 0, 1), 0).ok());
    CHECK(w->add_plane(Vector3(1, 0, 0), -1).ok());
    CHECK(w->add_plane(Vector3(0, 0, -1), -3).ok());  // a ceiling: it carries no weight
    WorldDef3 def;
    def.gravity = Vector3(1, 0, -9.81f);
    CHECK(w->configure(def) == Status::not_compiled);
    CHECK(w->def().gravity == WorldDef3{}.gravity);
    const auto sloped = std::make_unique<Small3<Features::piles | Features::slopes>>();
    CHECK(sloped->add_plane(Vector3(0.2f, 0, 1), 0).ok());
    const auto w2 = std::make_unique<Small2<Features::paper>>();
    CHECK(w2->add_plane(Vector2(0.3f, 1), 0).status == Status::not_compiled);
    CHECK(w2->plane_count() == 0);
  }
  SUBCASE("queries")
  {
    const auto w = std::make_unique<Small3<Features::paper>>();
    ShapeDef ball;
    const ShapeId s = w->add_shape(ball).id;
    BodyDef3 b;
    b.shape = s;
    b.mass = 1;
    REQUIRE(w->add_body(b).ok());
    QueryHit<3> hit;
    CHECK(ray_cast(*w, Vector3(0, 0, 5), Vector3(0, 0, -1), 10, hit) == Status::not_compiled);
    CHECK(!hit.hit());
    int calls = 0;
    const auto count = [&calls](const QueryHit<3>&) { return ++calls > 0; };
    CHECK(overlap_sphere(*w, Vector3::Zero(), 1, count) == Status::not_compiled);
    CHECK(ray_cast_all(*w, Vector3(0, 0, 5), Vector3(0, 0, -1), 10, count) == Status::not_compiled);
    CHECK(calls == 0);
    const auto q = std::make_unique<Small3<Features::paper | Features::queries>>();
    const ShapeId qs = q->add_shape(ball).id;
    b.shape = qs;
    REQUIRE(q->add_body(b).ok());
    CHECK(ray_cast(*q, Vector3(0, 0, 5), Vector3(0, 0, -1), 10, hit) == Status::ok);
    CHECK(hit.hit());
  }
  SUBCASE("snapshots of a world with hull contacts or tilted planes")
  {
    WorldDef3 def;
    def.body_contacts = BodyContacts::hulls;
    const auto source = std::make_unique<Small3<Features::all>>(def);
    ShapeDef ball;
    REQUIRE(source->add_shape(ball).ok());
    REQUIRE(source->add_plane(Vector3(0, 0, 1), 0).ok());
    std::vector<unsigned char> bytes(snapshot_capacity<3>(64, 8, 4));
    std::size_t n = 0;
    REQUIRE(save(*source, bytes.data(), bytes.size(), &n) == Status::ok);
    const auto target = std::make_unique<Small3<Features::paper>>();
    REQUIRE(target->add_shape(ball).ok());
    const std::uint64_t before = target->state_hash();
    CHECK(load(*target, bytes.data(), n) == Status::not_compiled);
    CHECK(target->state_hash() == before);
    const auto tilted = std::make_unique<Small3<Features::all>>();
    REQUIRE(tilted->add_shape(ball).ok());
    REQUIRE(tilted->add_plane(Vector3(0.2f, 0, 1), 0).ok());
    REQUIRE(save(*tilted, bytes.data(), bytes.size(), &n) == Status::ok);
    const auto piles = std::make_unique<Small3<Features::piles>>();
    REQUIRE(piles->add_shape(ball).ok());
    CHECK(load(*piles, bytes.data(), n) == Status::not_compiled);
    CHECK(piles->plane_count() == 0);
    const auto sloped = std::make_unique<Small3<Features::piles | Features::slopes>>();
    REQUIRE(sloped->add_shape(ball).ok());
    CHECK(load(*sloped, bytes.data(), n) == Status::ok);
    CHECK(sloped->plane_count() == 1);
  }
}
