// Queries: ray casts (closest and all hits) and sphere overlaps against the bodies' collision
// spheres and the planes; their statuses; that they change nothing; and that through the broad
// phase's records they find exactly what a test of every slot finds, reading few records.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/queries.hpp"
#include "statsim/random.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

using namespace statsim;

namespace {
/// Ground at z = 0 and three asleep spheres of radius 0.2 m at (1, 0, 1), (2, 0, 1), (3, 0, 1).
std::unique_ptr<World3<8>> row_of_spheres(BodyId ids[3])
{
  auto w = std::make_unique<World3<8>>();
  ShapeDef ball;
  ball.radius = 0.2f;
  BodyDef3 bd;
  bd.shape = w->add_shape(ball).id;
  bd.asleep = true;
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  for (int i = 0; i < 3; ++i) {
    bd.position = Vector3(float(i + 1), 0, 1);
    ids[i] = w->add_body(bd).id;
  }
  return w;
}
}  // namespace

TEST_CASE("a ray cast finds the nearest sphere or plane, and every one through the callback")
{
  BodyId ids[3];
  auto w = row_of_spheres(ids);
  const std::uint64_t h = w->state_hash();
  QueryHit<3> hit;
  REQUIRE(ray_cast(*w, Vector3(0, 0, 1), Vector3(5, 0, 0), 10, hit) == Status::ok);
  REQUIRE(hit.hit());
  CHECK(hit.body == ids[0]);
  CHECK(hit.plane == no_plane);
  CHECK(std::fabs(hit.distance - 0.8f) < 1e-6f);
  CHECK(hit.point.isApprox(Vector3(0.8f, 0, 1)));
  CHECK(hit.normal.isApprox(Vector3(-1, 0, 0)));

  int bodies = 0, planes = 0;
  REQUIRE(ray_cast_all(*w, Vector3(0, 0, 1), Vector3(1, 0, 0), 10, [&](const QueryHit<3>& q) {
            bodies += q.body != no_body;
            planes += q.plane != no_plane;
            return true;
          }) == Status::ok);
  CHECK(bodies == 3);
  CHECK(planes == 0);
  // Down through the middle sphere onto the ground.
  bodies = planes = 0;
  float ground = -1;
  REQUIRE(ray_cast_all(*w, Vector3(2, 0, 5), Vector3(0, 0, -1), 10, [&](const QueryHit<3>& q) {
            bodies += q.body == ids[1];
            if (q.plane == 0) ground = q.distance;
            planes += q.plane != no_plane;
            return true;
          }) == Status::ok);
  CHECK(bodies == 1);
  CHECK(planes == 1);
  CHECK(std::fabs(ground - 5) < 1e-6f);
  REQUIRE(ray_cast(*w, Vector3(2, 0, 5), Vector3(0, 0, -1), 10, hit) == Status::ok);
  CHECK(hit.body == ids[1]);
  CHECK(std::fabs(hit.distance - 3.8f) < 1e-5f);

  // Too short, stopped early, from inside a sphere, from below the ground, away from all.
  REQUIRE(ray_cast(*w, Vector3(0, 0, 1), Vector3(1, 0, 0), 0.7f, hit) == Status::ok);
  CHECK(!hit.hit());
  int calls = 0;
  REQUIRE(ray_cast_all(*w, Vector3(0, 0, 1), Vector3(1, 0, 0), 10, [&](const QueryHit<3>&) {
            ++calls;
            return false;
          }) == Status::ok);
  CHECK(calls == 1);
  REQUIRE(ray_cast(*w, Vector3(1, 0, 1), Vector3(1, 0, 0), 10, hit) == Status::ok);
  CHECK(hit.body == ids[1]);
  REQUIRE(ray_cast(*w, Vector3(0, 0, -1), Vector3(0, 0, 1), 10, hit) == Status::ok);
  CHECK(!hit.hit());
  REQUIRE(ray_cast(*w, Vector3(0, 0, 1), Vector3(-1, 0, 0), 10, hit) == Status::ok);
  CHECK(!hit.hit());
  CHECK(w->state_hash() == h);
}

TEST_CASE("a sphere overlap reports the bodies and planes it reaches")
{
  BodyId ids[3];
  auto w = row_of_spheres(ids);
  const std::uint64_t h = w->state_hash();
  BodyId seen[4];
  int n = 0, planes = 0;
  const auto collect = [&](const QueryHit<3>& q) {
    if (q.body != no_body) seen[n++] = q.body;
    planes += q.plane != no_plane;
    return n < 4;
  };
  REQUIRE(overlap_sphere(*w, Vector3(1.5f, 0, 1), 0.31f, collect) == Status::ok);
  CHECK(n == 2);
  CHECK(seen[0] == ids[0]);
  CHECK(seen[1] == ids[1]);
  CHECK(planes == 0);
  n = 0;
  REQUIRE(overlap_sphere(*w, Vector3(1.5f, 0, 1), 0.29f, collect) == Status::ok);
  CHECK(n == 0);
  REQUIRE(overlap_sphere(*w, Vector3(3, 0, 0.5f), 0.6f, [&](const QueryHit<3>& q) {
            if (q.body == ids[2]) {
              CHECK(std::fabs(q.distance + 0.3f) < 1e-5f);
              CHECK(q.point.isApprox(Vector3(3, 0, 0.8f)));
            } else {
              CHECK(q.plane == 0);
              CHECK(std::fabs(q.distance + 0.1f) < 1e-5f);
              CHECK(q.point.isApprox(Vector3(3, 0, 0)));
            }
            ++n;
            return true;
          }) == Status::ok);
  CHECK(n == 2);
  CHECK(w->state_hash() == h);
}

TEST_CASE("queries use a statistical body's collision sphere, and a 2D world's discs")
{
  WorldDef2 def;
  def.gravity = Vector2::Zero();
  auto w = std::make_unique<World2<4>>(def);
  BodyDef2 bd;
  bd.shape = w->add_shape(testing::square2d_synthetic.view()).id;
  bd.position = Vector2(3, 0);
  const BodyId id = w->add_body(bd).id;
  const float r = w->body(id).radius;
  QueryHit<2> hit;
  REQUIRE(ray_cast(*w, Vector2(0, 0), Vector2(1, 0), 10, hit) == Status::ok);
  CHECK(hit.body == id);
  CHECK(std::fabs(hit.distance - (3 - r)) < 1e-5f);
  int n = 0;
  REQUIRE(overlap_sphere(*w, Vector2(0, 0), 3 - r - 1e-3f, [&](const QueryHit<2>&) { return ++n, true; }) ==
          Status::ok);
  CHECK(n == 0);
  REQUIRE(overlap_sphere(*w, Vector2(0, 0), 3 - r + 1e-3f, [&](const QueryHit<2>&) { return ++n, true; }) ==
          Status::ok);
  CHECK(n == 1);
}

TEST_CASE("queries refuse bad input")
{
  BodyId ids[3];
  auto w = row_of_spheres(ids);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  QueryHit<3> hit;
  hit.distance = 42;
  const auto any = [](const QueryHit<3>&) { return true; };
  CHECK(ray_cast(*w, Vector3(nan, 0, 0), Vector3(1, 0, 0), 1, hit) == Status::non_finite);
  CHECK(ray_cast(*w, Vector3::Zero(), Vector3(1, 0, 0), nan, hit) == Status::non_finite);
  CHECK(ray_cast(*w, Vector3::Zero(), Vector3::Zero(), 1, hit) == Status::invalid_parameter);
  CHECK(ray_cast(*w, Vector3::Zero(), Vector3(1, 0, 0), -1, hit) == Status::out_of_range);
  CHECK(ray_cast(*w, Vector3(1e7f, 0, 0), Vector3(1, 0, 0), 1, hit) == Status::out_of_range);
  CHECK(hit.distance == 42);  // left as it was
  CHECK(ray_cast_all(*w, Vector3::Zero(), Vector3(0, nan, 0), 1, any) == Status::non_finite);
  CHECK(overlap_sphere(*w, Vector3::Zero(), -1, any) == Status::out_of_range);
  CHECK(overlap_sphere(*w, Vector3(0, 0, nan), 1, any) == Status::non_finite);
}

namespace {
/// One hit as the queries report it, compared bit for bit.
template <int D>
bool same_hit(const QueryHit<D>& a, const QueryHit<D>& b)
{
  return a.body == b.body && a.plane == b.plane && a.point == b.point && a.normal == b.normal &&
         a.distance == b.distance;
}

/// Up to 64 hits of a query, in the order it reported them.
template <int D>
struct Hits {
  QueryHit<D> h[64];
  int n = 0;
  bool add(const QueryHit<D>& q)
  {
    h[n++] = q;
    return n < 64;
  }
  bool operator==(const Hits& o) const
  {
    if (n != o.n) return false;
    for (int i = 0; i < n; ++i)
      if (!same_hit(h[i], o.h[i])) return false;
    return true;
  }
};

/// Random rays and spheres in and about the world: each query through the broad phase against the
/// same query testing every slot (`detail::*_scan`). Returns how many were answered from the
/// records rather than by a scan.
template <int D, class W>
int compare_queries(const W& w, Pcg32& g, float half)
{
  using Vec = typename Space<D>::Vec;
  const auto point = [&]() {
    Vec p;
    for (int k = 0; k < D; ++k) p[k] = g.uniform(-half, half);
    p[Space<D>::up_axis] = g.uniform(-0.5f, 3.0f);
    return p;
  };
  int searched = 0;
  for (int q = 0; q < 60; ++q) {
    const Vec o = point();
    Vec dir = point() - o;
    if (q % 4 == 0) dir = Vec::Unit(q % D);  // along an axis, the sweep axis among them
    const float len = q % 3 == 0 ? g.uniform(0.0f, 1.0f) : g.uniform(0.0f, 2 * half);
    const float r = q % 5 == 0 ? 0.0f : g.uniform(0.0f, q % 2 ? 0.5f : 2.0f);
    if (!(dir.norm() > 1e-3f)) continue;
    Hits<D> fast, slow;
    QueryStats st;
    REQUIRE(ray_cast_all(w, o, dir, len, [&](const QueryHit<D>& h) { return fast.add(h); }, &st) == Status::ok);
    QueryStats scan;
    const Vec d = dir / dir.norm();
    detail::ray_cast_all_scan(detail::CoreAccess::data(w), o, d, len, [&](const QueryHit<D>& h) { return slow.add(h); }, scan);
    CHECK(fast == slow);
    searched += !st.scanned;
    // The nearest hit: the first strictly nearer one in the scan's order.
    QueryHit<D> nearest, expected;
    REQUIRE(ray_cast(w, o, dir, len, nearest) == Status::ok);
    for (int i = 0; i < slow.n; ++i)
      if (!expected.hit() || slow.h[i].distance < expected.distance) expected = slow.h[i];
    CHECK(same_hit(nearest, expected));
    // Stopped after the first hit.
    Hits<D> first;
    REQUIRE(ray_cast_all(w, o, dir, len, [&](const QueryHit<D>& h) { return first.add(h), false; }) == Status::ok);
    CHECK(first.n == (slow.n > 0 ? 1 : 0));
    if (first.n > 0) CHECK(same_hit(first.h[0], slow.h[0]));

    Hits<D> over, over_slow;
    QueryStats so;
    REQUIRE(overlap_sphere(w, o, r, [&](const QueryHit<D>& h) { return over.add(h); }, &so) == Status::ok);
    detail::overlap_sphere_scan(detail::CoreAccess::data(w), o, r, [&](const QueryHit<D>& h) { return over_slow.add(h); }, scan);
    CHECK(over == over_slow);
    searched += !so.scanned;
  }
  return searched;
}

/// A world of `n` bodies of three sizes (spheres and a statistical shape) dropped on the ground,
/// stepped while bodies are removed, added (into free slots), moved and put to sleep, with queries
/// compared after steps and between the changes.
template <int D, class W>
void random_world_queries(BroadPhase phase, std::uint64_t seed)
{
  using Vec = typename Space<D>::Vec;
  WorldDef<D> def;
  def.broad_phase = phase;
  def.seed = seed;
  auto w = std::make_unique<W>(def);
  REQUIRE(w->construction_status() == Status::ok);
  REQUIRE(w->add_plane(Vec::Unit(Space<D>::up_axis), 0).ok());
  ShapeId shapes[3];
  ShapeDef ball;
  ball.radius = 0.1f;
  shapes[0] = w->add_shape(ball).id;
  ball.radius = 0.25f;
  shapes[1] = w->add_shape(ball).id;
  if constexpr (D == 3) shapes[2] = w->add_shape(testing::cube_synthetic.view()).id;
  else shapes[2] = w->add_shape(testing::square2d_synthetic.view()).id;
  Pcg32 g(seed, 7);
  const float half = D == 3 ? 4.0f : 12.0f;
  std::vector<BodyId> live;
  const auto spawn = [&](bool asleep) {
    BodyDef<D> bd;
    bd.shape = shapes[g.next_u32() % 3];
    for (int k = 0; k < D; ++k) bd.position[k] = g.uniform(-half, half);
    bd.position[Space<D>::up_axis] = g.uniform(0.3f, 2.5f);
    for (int k = 0; k < D; ++k) bd.linear_velocity[k] = g.uniform(-2.0f, 2.0f);
    bd.asleep = asleep;
    const Added<BodyId> a = w->add_body(bd);
    if (a.ok()) live.push_back(a.id);
  };
  for (std::uint32_t i = 0; i < W::max_bodies * 3 / 4; ++i) spawn(i % 7 == 0);
  int searched = 0;
  searched += compare_queries<D>(*w, g, half);  // before any step: every query scans
  for (int round = 0; round < 12; ++round) {
    for (int s = 0; s < 5 + round * 3; ++s) REQUIRE(w->step(1.0f / 60).ok());
    searched += compare_queries<D>(*w, g, half);
    // Between steps: removals, additions into the freed slots and new ones, moves, sleepers.
    for (int k = 0; k < 6 && !live.empty(); ++k) {
      const std::size_t at = g.next_u32() % live.size();
      REQUIRE(w->remove_body(live[at]) == Status::ok);
      live.erase(live.begin() + std::ptrdiff_t(at));
    }
    searched += compare_queries<D>(*w, g, half);
    for (int k = 0; k < 5; ++k) spawn(k == 0);
    for (int k = 0; k < 3 + round % 4 * 6 && !live.empty(); ++k) {
      Vec p;
      for (int j = 0; j < D; ++j) p[j] = g.uniform(-half, half);
      p[Space<D>::up_axis] = g.uniform(0.3f, 2.5f);
      REQUIRE(w->set_transform(live[g.next_u32() % live.size()], p, Space<D>::identity()) == Status::ok);
    }
    if (!live.empty()) REQUIRE(w->sleep(live[g.next_u32() % live.size()]) == Status::ok);
    searched += compare_queries<D>(*w, g, half);
  }
  CHECK(searched > 500);  // most were answered from the records
}
}  // namespace

TEST_CASE("queries through the broad phase find what testing every body finds, in the same order")
{
  for (const BroadPhase phase : {BroadPhase::grid, BroadPhase::sweep_and_prune}) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      CAPTURE(int(phase));
      CAPTURE(seed);
      random_world_queries<3, World3<400, 8, 4000>>(phase, seed);
      random_world_queries<2, World2<400, 8, 4000>>(phase, seed);
    }
  }
}

TEST_CASE("a query in a sparse region visits few of the world's bodies")
{
  for (const BroadPhase phase : {BroadPhase::grid, BroadPhase::sweep_and_prune}) {
    CAPTURE(int(phase));
    WorldDef3 def;
    def.broad_phase = phase;
    auto w = std::make_unique<World3<2000, 8, 12000>>(def);
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
    ShapeDef ball;
    ball.radius = 0.1f;
    BodyDef3 bd;
    bd.shape = w->add_shape(ball).id;
    // A 100 x 20 carpet of bodies along the sweep axis x, x in [0, 20], y in [0, 4], one layer on
    // the ground.
    for (int i = 0; i < 2000; ++i) {
      bd.position = Vector3(0.2f * float(i / 20) + 0.1f, 0.2f * float(i % 20) + 0.1f, 0.1f);
      REQUIRE(w->add_body(bd).ok());
    }
    for (int s = 0; s < 3; ++s) REQUIRE(w->step(1.0f / 60).ok());
    // Down onto one corner of the carpet, across its end (perpendicular to the sweep axis x), and
    // a small sphere there: each meets a few bodies; sweep-and-prune reads the slab of the first
    // column or two (20 bodies each).
    QueryStats ray, across, sphere;
    int hits = 0;
    const auto count = [&](const QueryHit<3>& h) { return hits += h.body != no_body, true; };
    REQUIRE(ray_cast_all(*w, Vector3(0.1f, 0.1f, 2), Vector3(0, 0, -1), 3, count, &ray) == Status::ok);
    REQUIRE(ray_cast_all(*w, Vector3(0.1f, -1, 0.1f), Vector3(0, 1, 0), 2, count, &across) == Status::ok);
    REQUIRE(overlap_sphere(*w, Vector3(0.1f, 0.1f, 0.1f), 0.15f, count, &sphere) == Status::ok);
    CHECK(hits >= 3);
    for (const QueryStats* st : {&ray, &across, &sphere}) {
      CHECK(!st->scanned);
      CHECK(st->bodies_examined < 2000 / 20);
    }
    // A scan reads every slot.
    QueryStats scan;
    detail::overlap_sphere_scan(detail::CoreAccess::data(*w), Vector3(0.1f, 0.1f, 0.1f), 0.15f, count, scan);
    CHECK(scan.bodies_examined == 2000);
  }
}
