// Zero heap allocations in construction and 10,000 steps of full-capacity worlds.
//
// Three nets: global operator new/delete are replaced and count; malloc, calloc, realloc,
// aligned_alloc and posix_memalign are wrapped at link time (-Wl,--wrap=...) for all code in
// this executable, which includes the whole header-only runtime; and Eigen is built with
// EIGEN_RUNTIME_NO_MALLOC, so any Eigen heap allocation asserts while it is disallowed.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "support/snapshot_scene.hpp"

#include "common/task_pool.hpp"
#include "tables/box.hpp"

#include "statsim/queries.hpp"
#include "statsim/snapshot.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};
void note()
{
  if (g_counting.load()) g_allocations.fetch_add(1);
}
}  // namespace

extern "C" {
void* __real_malloc(std::size_t);
void* __real_calloc(std::size_t, std::size_t);
void* __real_realloc(void*, std::size_t);
void* __real_aligned_alloc(std::size_t, std::size_t);
int __real_posix_memalign(void**, std::size_t, std::size_t);
void* __wrap_malloc(std::size_t n)
{
  note();
  return __real_malloc(n);
}
void* __wrap_calloc(std::size_t n, std::size_t s)
{
  note();
  return __real_calloc(n, s);
}
void* __wrap_realloc(void* p, std::size_t n)
{
  note();
  return __real_realloc(p, n);
}
void* __wrap_aligned_alloc(std::size_t a, std::size_t n)
{
  note();
  return __real_aligned_alloc(a, n);
}
int __wrap_posix_memalign(void** p, std::size_t a, std::size_t n)
{
  note();
  return __real_posix_memalign(p, a, n);
}
}

void* operator new(std::size_t n)
{
  note();
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

using namespace statsim;

namespace {
constexpr std::uint32_t N3 = 128, N2 = 128, N_big = 10000;
// Static storage: a full-capacity world is big, and constructing it in place is part of the test.
alignas(World3<N3>) unsigned char storage3[sizeof(World3<N3>)];
alignas(World2<N2>) unsigned char storage2[sizeof(World2<N2>)];
alignas(World3<N_big>) unsigned char storage_big[sizeof(World3<N_big>)];
using EventWorld = World3<64, 8, 384, 8, 32>;
using SnapWorld = World3<64, 8, 384, 4, 8>;
alignas(SnapWorld) unsigned char storage_snap[2][sizeof(SnapWorld)];
unsigned char snapshot_buffer[2][16384];
alignas(EventWorld) unsigned char storage_events[sizeof(EventWorld)];

template <int D, class W>
void populate_and_step(W& w, int steps)
{
  ShapeDef s;
  s.radius = 0.05f;
  s.bounding_radius = 0.07f;
  REQUIRE(w.add_shape(s).ok());
  using Vec = typename Space<D>::Vec;
  REQUIRE(w.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok());
  for (int k = 0; k < D - 1; ++k) {
    REQUIRE(w.add_plane(Vec::Unit(k), -1).ok());
    REQUIRE(w.add_plane(-Vec::Unit(k), -1).ok());
  }
  Pcg32 g(1, 2);
  for (std::uint32_t i = 0; i < W::max_bodies; ++i) {
    BodyDef<D> b;
    for (int k = 0; k < D; ++k) b.position[k] = g.uniform(-0.9f, 0.9f);
    b.position[Space<D>::up_axis] = g.uniform(0.1f, 4);
    REQUIRE(w.add_body(b).ok());
  }
  CHECK(w.add_body(BodyDef<D>{}).status == Status::capacity_exceeded);
  for (int i = 0; i < steps; ++i) REQUIRE(w.step(1.0f / 60).status == Status::ok);
}
}  // namespace

TEST_CASE("no heap allocation in construction and 10000 steps of full-capacity worlds - 2D and 3D")
{
  g_allocations = 0;
  // Self-check: the counters do see allocations (volatile, so the compiler cannot elide them).
  g_counting = true;
  void* volatile probe = std::malloc(16);
  int* volatile probe_new = new int(1);
  g_counting = false;
  std::free(probe);
  delete probe_new;
  REQUIRE(g_allocations.load() >= 2);
  g_allocations = 0;

  Eigen::internal::set_is_malloc_allowed(false);
  g_counting = true;
  auto* w3 = new (storage3) World3<N3>();
  populate_and_step<3>(*w3, 10000);
  auto* w2 = new (storage2) World2<N2>();
  populate_and_step<2>(*w2, 10000);
  g_counting = false;
  Eigen::internal::set_is_malloc_allowed(true);

  CHECK(g_allocations.load() == 0);
  CHECK(w3->step_count() == 10000);
  CHECK(w2->step_count() == 10000);
  std::destroy_at(w3);
  std::destroy_at(w2);
}

TEST_CASE("no heap allocation in construction and stepping of a 10000-body statistical world")
{
  g_allocations = 0;
  Eigen::internal::set_is_malloc_allowed(false);
  g_counting = true;
  auto* w = new (storage_big) World3<N_big>();
  // One shape of each response model.
  REQUIRE(w->add_shape(statsim::testing::cube_synthetic.view()).ok());
  REQUIRE(w->add_shape(statsim::testing::cube_correlated_synthetic.view()).ok());
  REQUIRE(w->add_shape(statsim::testing::cube_empirical_synthetic.view()).ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  Pcg32 g(3, 4);
  for (std::uint32_t i = 0; i < N_big; ++i) {
    BodyDef3 b;
    b.shape = ShapeId(std::uint16_t(i % 3));
    b.position = Vector3(g.uniform(-5, 5), g.uniform(-5, 5), g.uniform(0.2f, 3));
    b.angular_velocity = Vector3(g.uniform(-5, 5), 0, g.uniform(-5, 5));
    REQUIRE(w->add_body(b).ok());
  }
  for (int i = 0; i < 150; ++i) REQUIRE(w->step(1.0f / 60).status == Status::ok);
  g_counting = false;
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(g_allocations.load() == 0);
  CHECK(w->count(MotionState::moving) < N_big);  // bodies did land: contacts were exercised
  std::destroy_at(w);
}

TEST_CASE("no heap allocation with workers: the grid search and the hull candidates on two threads")
{
  tools::TaskPool pool(2);  // its threads start here, before the count
  WorldDef3 def;
  def.workers = pool.workers();
  def.body_contacts = BodyContacts::hulls;
  g_allocations = 0;
  Eigen::internal::set_is_malloc_allowed(false);
  g_counting = true;
  auto* w = new (storage_big) World3<N_big>(def);
  REQUIRE(w->construction_status() == Status::ok);
  REQUIRE(w->add_shape(tables::box.view()).ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  Pcg32 g(5, 6);
  for (std::uint32_t i = 0; i < N_big; ++i) {
    BodyDef3 b;
    b.position = Vector3(g.uniform(-4, 4), g.uniform(-4, 4), g.uniform(0.2f, 3));
    REQUIRE(w->add_body(b).ok());
  }
  for (int i = 0; i < 60; ++i) REQUIRE(w->step(1.0f / 60).status == Status::ok);
  g_counting = false;
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(g_allocations.load() == 0);
  CHECK(w->count(MotionState::moving) < N_big);
  std::destroy_at(w);
}

TEST_CASE("no heap allocation in impulses, sleep and wake, removal, impact events and queries")
{
  g_allocations = 0;
  Eigen::internal::set_is_malloc_allowed(false);
  g_counting = true;
  auto* w = new (storage_events) EventWorld();
  REQUIRE(w->add_shape(statsim::testing::cube_synthetic.view()).ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  Pcg32 g(5, 6);
  BodyId ids[64];
  for (BodyId& id : ids) {
    BodyDef3 b;
    b.position = Vector3(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(0.2f, 3));
    id = w->add_body(b).id;
  }
  std::uint32_t impacts = 0, hits = 0;
  for (int i = 0; i < 600; ++i) {
    BodyId& id = ids[i % 64];
    REQUIRE(w->remove_body(id) == Status::ok);
    BodyDef3 b;
    b.position = Vector3(g.uniform(-1, 1), g.uniform(-1, 1), 2);
    id = w->add_body(b).id;
    REQUIRE(w->apply_impulse(ids[(i + 7) % 64], Vector3(0, 0, 1), Vector3::Zero()) == Status::ok);
    REQUIRE(w->sleep(ids[(i + 13) % 64]) == Status::ok);
    REQUIRE(w->wake(ids[(i + 29) % 64]) == Status::ok);
    REQUIRE(w->step(1.0f / 60).status == Status::ok);
    impacts += w->impact_count();
    QueryHit<3> hit;
    REQUIRE(ray_cast(*w, Vector3(0, 0, 5), Vector3(0, 0, -1), 10, hit) == Status::ok);
    hits += hit.hit();
    REQUIRE(overlap_sphere(*w, Vector3::Zero(), 0.5f, [&hits](const QueryHit<3>&) { return ++hits, true; }) ==
            Status::ok);
  }
  g_counting = false;
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(g_allocations.load() == 0);
  CHECK(impacts > 0);
  CHECK(hits > 0);
  std::destroy_at(w);
}

TEST_CASE("no heap allocation in saving and loading snapshots")
{
  g_allocations = 0;
  Eigen::internal::set_is_malloc_allowed(false);
  g_counting = true;
  auto* a = new (storage_snap[0]) SnapWorld();
  auto* b = new (storage_snap[1]) SnapWorld();
  REQUIRE(statsim::testing::build_snapshot_scene<3>(*a, 60, 120));
  REQUIRE(statsim::testing::add_snapshot_shapes<3>(*b));
  std::size_t n = 0, m = 0;
  REQUIRE(save(*a, snapshot_buffer[0], sizeof snapshot_buffer[0], &n) == Status::ok);
  REQUIRE(load(*b, snapshot_buffer[0], n - 1) == Status::invalid_snapshot);
  REQUIRE(load(*b, snapshot_buffer[0], n) == Status::ok);
  for (int i = 0; i < 60; ++i) REQUIRE(b->step(1.0f / 60).status == Status::ok);
  REQUIRE(save(*b, snapshot_buffer[1], sizeof snapshot_buffer[1], &m) == Status::ok);
  g_counting = false;
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(g_allocations.load() == 0);
  CHECK(b->step_count() == 180);
  std::destroy_at(a);
  std::destroy_at(b);
}
