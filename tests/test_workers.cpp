// Worker threads (`WorldDef::workers`): a world steps to the same bits with any number of workers
// and any order in which they run the parts, the pair buffer's overflow is reported as on one
// thread, and bad worker settings are refused.
#include <doctest/doctest.h>

#include "common/task_pool.hpp"
#include "scenes/synthetic_signatures.hpp"

#include "statsim/snapshot.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/square2d.hpp"

#include <memory>
#include <vector>

using namespace statsim;

namespace {

/// Runs a task's items on the calling thread in reverse order, before `enqueue` returns.
void* reverse_enqueue(TaskCallback* task, std::uint32_t count, std::uint32_t, void* task_context, void*)
{
  for (std::uint32_t i = count; i-- > 0;) task(i, i + 1, task_context);
  return nullptr;
}
/// Keeps the task and runs its items, from the last, when the world finishes it.
struct Deferred {
  TaskCallback* task = nullptr;
  std::uint32_t count = 0;
  void* context = nullptr;
  int tasks = 0;  ///< tasks handed out so far
};
void* deferred_enqueue(TaskCallback* task, std::uint32_t count, std::uint32_t, void* task_context, void* user)
{
  Deferred& d = *static_cast<Deferred*>(user);
  d = Deferred{task, count, task_context, d.tasks + 1};
  return &d;
}
void deferred_finish(void* handle, void*)
{
  Deferred& d = *static_cast<Deferred*>(handle);
  for (std::uint32_t i = d.count; i-- > 0;) d.task(i, i + 1, d.context);
}
void never_called(void*, void*) { FAIL("finish called for a task that ran in enqueue"); }

/// Adds the ground and `n` bodies of `sig` dropped in a dense column over a small square, so that
/// many bodies touch and the contact passes depend on the pairs' order.
template <int D, class World, class Sig>
void drop_heap(World& w, const Sig& sig, int n)
{
  const ShapeId shape = w.add_shape(sig.view()).id;
  using Vec = typename Space<D>::Vec;
  REQUIRE(w.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok());
  Pcg32 g(2026, 12);
  const int side = D == 3 ? 10 : 40;
  for (int i = 0; i < n; ++i) {
    BodyDef<D> b;
    b.shape = shape;
    b.mass = 1;
    int q = i;
    for (int k = 0; k < D; ++k) {
      const bool up = k == Space<D>::up_axis;
      const int cell = up ? q : q % side;
      if (!up) q /= side;
      b.position[k] = 0.35f * float(cell) + g.uniform(-0.03f, 0.03f) + (up ? 0.3f : 0.0f);
      b.linear_velocity[k] = g.uniform(-1, 1);
    }
    REQUIRE(w.add_body(b).ok());
  }
}

/// Steps a world with each set of workers beside one on the calling thread, comparing the state
/// hash and the step's pair counts after every step.
template <int D, std::uint32_t N, std::uint32_t Pairs, class Sig>
void compare_workers(const Sig& sig, int bodies, int steps, BodyContacts contacts)
{
  using W = World<D, N, 4, Pairs, 1>;
  WorldDef<D> def;
  def.broad_phase = BroadPhase::grid;
  def.body_contacts = contacts;
  tools::TaskPool two(2), four(4);
  Deferred deferred;
  std::vector<Workers> sets;
  sets.push_back(two.workers());
  sets.push_back(four.workers());
  sets.push_back(Workers{3, &reverse_enqueue, &never_called, nullptr});
  sets.push_back(Workers{5, &deferred_enqueue, &deferred_finish, &deferred});
  auto serial = std::make_unique<W>(def);
  drop_heap<D>(*serial, sig, bodies);
  std::vector<std::unique_ptr<W>> worlds;
  for (const Workers& s : sets) {
    WorldDef<D> d = def;
    d.workers = s;
    worlds.push_back(std::make_unique<W>(d));
    REQUIRE(worlds.back()->construction_status() == Status::ok);
    drop_heap<D>(*worlds.back(), sig, bodies);
  }
  std::uint32_t most_pairs = 0;
  for (int i = 0; i < steps; ++i) {
    const StepResult r = serial->step(1.0f / 60);
    REQUIRE(r.status == Status::ok);
    most_pairs = r.pairs_found > most_pairs ? r.pairs_found : most_pairs;
    for (std::size_t k = 0; k < worlds.size(); ++k) {
      const StepResult rk = worlds[k]->step(1.0f / 60);
      REQUIRE(rk.status == Status::ok);
      CHECK(rk.pairs_found == r.pairs_found);
      CHECK(rk.pairs_dropped == r.pairs_dropped);
      CHECK(rk.overflow == r.overflow);
      CHECK(rk.pairs_examined == r.pairs_examined);
      REQUIRE(worlds[k]->state_hash() == serial->state_hash());
    }
  }
  // The worlds were split: the deferred scheduler saw a task in nearly every step.
  CHECK(deferred.tasks > steps / 2);
  CHECK(most_pairs > std::uint32_t(bodies));
}

}  // namespace

TEST_CASE("workers: the same bits with 1, 2, 3, 4 and 5 parts, in any order (3D and 2D)")
{
  // Enough bodies for parts of `detail::awake_per_part` awake bodies each.
  compare_workers<3, 4096, 4096 * 16>(statsim::testing::cube_synthetic, 4000, 90, BodyContacts::collision_spheres);
  compare_workers<2, 4096, 4096 * 16>(statsim::testing::square2d_synthetic, 4000, 90,
                                      BodyContacts::collision_spheres);
}

TEST_CASE("workers: the same bits with hull contacts, whose candidates are searched on the workers (3D and 2D)")
{
  compare_workers<3, 1024, 1024 * 16>(tables::box, 1000, 120, BodyContacts::hulls);
  compare_workers<2, 1024, 1024 * 16>(tables::square2d, 1000, 120, BodyContacts::hulls);
}

TEST_CASE("workers: a part whose share of the pair buffer is too small; a buffer too small for all")
{
  // Bodies 0..1199 in a dense heap, 1200..2399 apart from each other: split in two by awake
  // bodies, the first part finds nearly all pairs and its half of the buffer cannot hold them.
  const auto run = [](std::uint32_t count, auto pairs_constant) {
    constexpr std::uint32_t pairs = decltype(pairs_constant)::value;
    WorldDef3 def;
    def.broad_phase = BroadPhase::grid;
    def.workers = Workers{count, &reverse_enqueue, &never_called, nullptr};
    auto w = std::make_unique<World<3, 2400, 4, pairs, 1>>(def);
    drop_heap<3>(*w, statsim::testing::cube_synthetic, 1200);
    for (int i = 0; i < 1200; ++i) {
      BodyDef3 b;
      b.shape = ShapeId(0);
      b.mass = 1;
      b.position = Vector3(100.0f + 2.0f * float(i % 30), 100.0f + 2.0f * float(i / 30), 5.0f);
      REQUIRE(w->add_body(b).ok());
    }
    std::vector<StepResult> results;
    for (int i = 0; i < 30; ++i) results.push_back(w->step(1.0f / 60));
    return std::make_pair(w->state_hash(), results);
  };
  using Roomy = std::integral_constant<std::uint32_t, 3000>;
  const auto serial = run(1, Roomy{});
  const auto split = run(2, Roomy{});
  CHECK(split.first == serial.first);
  bool short_share = false;
  for (std::size_t i = 0; i < serial.second.size(); ++i) {
    CHECK(split.second[i].pairs_found == serial.second[i].pairs_found);
    CHECK(split.second[i].overflow == 0);
    short_share = short_share || (serial.second[i].pairs_found > 1500 && serial.second[i].pairs_found <= 3000);
  }
  CHECK(short_share);  // the case happened: more pairs than half the buffer, fewer than all of it
  // A buffer too small for the step's pairs: the overflow and the dropped pairs as on one thread.
  using Tight = std::integral_constant<std::uint32_t, 800>;
  const auto serial_tight = run(1, Tight{});
  const auto split_tight = run(2, Tight{});
  CHECK(split_tight.first == serial_tight.first);
  bool overflowed = false;
  for (std::size_t i = 0; i < serial_tight.second.size(); ++i) {
    CHECK(split_tight.second[i].overflow == serial_tight.second[i].overflow);
    CHECK(split_tight.second[i].pairs_dropped == serial_tight.second[i].pairs_dropped);
    overflowed = overflowed || (serial_tight.second[i].overflow & overflow_pairs) != 0;
  }
  CHECK(overflowed);
}

TEST_CASE("workers: settings refused, and not carried by snapshots")
{
  WorldDef3 def;
  def.workers.count = 2;  // no callbacks
  CHECK(World3<16>(def).construction_status() == Status::invalid_parameter);
  def.workers = Workers{limits::max_workers + 1, &reverse_enqueue, &never_called, nullptr};
  CHECK(World3<16>(def).construction_status() == Status::invalid_parameter);
  def.workers.count = 0;
  CHECK(World3<16>(def).construction_status() == Status::invalid_parameter);
  def.workers.count = limits::max_workers;
  CHECK(World3<16>(def).construction_status() == Status::ok);

  // A world without workers loads the snapshot of one with them, and keeps its own setting;
  // the hash does not see workers.
  WorldDef3 with;
  with.workers = Workers{4, &reverse_enqueue, &never_called, nullptr};
  World3<16> a(with), b;
  REQUIRE(a.add_shape(statsim::testing::cube_synthetic.view()).ok());
  REQUIRE(b.add_shape(statsim::testing::cube_synthetic.view()).ok());
  CHECK(a.state_hash() == b.state_hash());
  std::vector<unsigned char> buf(snapshot_size(a));
  std::size_t written = 0;
  REQUIRE(save(a, buf.data(), buf.size(), &written) == Status::ok);
  REQUIRE(load(b, buf.data(), written) == Status::ok);
  CHECK(b.def().workers.count == 1);
  REQUIRE(load(a, buf.data(), written) == Status::ok);
  CHECK(a.def().workers.count == 4);
}
