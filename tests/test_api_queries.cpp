// Queries: ray casts (closest and all hits) and sphere overlaps against the bodies' collision
// spheres and the planes; their statuses; and that they change nothing.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/queries.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <cmath>
#include <limits>
#include <memory>

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
