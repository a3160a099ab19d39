// A step's work grows with the awake bodies only: a world whose bodies are all asleep integrates
// none, puts none into the broad phase and examines no pair (counters of `StepResult`, not time).
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <memory>
#include <vector>

using namespace statsim;

namespace {

/// Drops `n` bodies (every third a plain sphere) in a loose block onto the ground and steps until
/// all are asleep; returns the steps taken. A plain sphere nested between sleepers can keep
/// spinning (friction at several static contacts, solved one after the other, spins it up again
/// in every step: statsim/README.md, "How a step works"): up to two such bodies are put to sleep
/// through the API after 2,000 steps, as the work counters below are the point here.
template <int D, class World, class Sig>
int settle(World& w, const Sig& sig, int n)
{
  std::vector<BodyId> ids;
  const ShapeId stat = w.add_shape(sig.view()).id;
  ShapeDef ball;
  ball.radius = 0.12f;
  const ShapeId sphere = w.add_shape(ball).id;
  using Vec = typename Space<D>::Vec;
  REQUIRE(w.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok());
  Pcg32 g(7, 1);
  for (int i = 0; i < n; ++i) {
    BodyDef<D> b;
    b.shape = i % 3 == 0 ? sphere : stat;
    b.mass = 1;
    for (int k = 0; k < D; ++k) b.position[k] = g.uniform(-1.5f, 1.5f);
    b.position[Space<D>::up_axis] = g.uniform(0.3f, 2);
    const Added<BodyId> added = w.add_body(b);
    REQUIRE(added.ok());
    ids.push_back(added.id);
  }
  for (int s = 0; s < 2000; ++s) {
    const StepResult r = w.step(1.0f / 60);
    REQUIRE(r.ok());
    if (w.count(MotionState::asleep) == w.body_count()) return s + 1;
  }
  REQUIRE(w.body_count() - w.count(MotionState::asleep) <= 2);
  for (std::uint32_t i = 0; i < w.body_count(); ++i) {
    if (w.body(i).state == MotionState::asleep) continue;
    MESSAGE("body " << i << " (shape " << w.body(i).shape << ") still awake after 2,000 steps: put to sleep");
    REQUIRE(w.sleep(ids[i]) == Status::ok);
  }
  REQUIRE(w.count(MotionState::asleep) == w.body_count());
  return 2000;
}

/// Steps a fully asleep world: the first step may still sort the sweep-and-prune entries on the
/// places where the last bodies fell asleep; from then on it does nothing per body.
template <class World>
void check_asleep_steps(World& w)
{
  const std::uint64_t before = w.state_hash();
  (void)w.step(1.0f / 60);
  for (int s = 0; s < 3; ++s) {
    const StepResult r = w.step(1.0f / 60);
    CHECK(r.ok());
    CHECK(r.bodies_integrated == 0);
    CHECK(r.broad_phase_bodies == 0);
    CHECK(r.pairs_examined == 0);
    CHECK(r.pairs_found == 0);
    CHECK(r.contacts == 0);
  }
  CHECK(w.count(MotionState::asleep) == w.body_count());
  // Only the step count changed.
  CHECK(w.state_hash() != before);
}

/// Wakes the pile by dropping a body onto it: the step integrates the awake body, then the woken
/// ones, and the broad phase runs again.
template <int D, class World>
void check_wakes(World& w)
{
  BodyDef<D> drop;
  drop.shape = ShapeId(1);
  drop.mass = 1;
  drop.position = w.body(0).position;
  drop.position[Space<D>::up_axis] += 0.5f;
  drop.linear_velocity[Space<D>::up_axis] = -4;
  REQUIRE(w.add_body(drop).ok());
  bool woke = false;
  for (int s = 0; s < 60 && !woke; ++s) {
    const std::uint32_t awake = w.body_count() - w.count(MotionState::asleep);
    const StepResult r = w.step(1.0f / 60);
    CHECK(r.bodies_integrated == awake);
    CHECK(r.broad_phase_bodies > 0);
    woke = w.body_count() - w.count(MotionState::asleep) > 1;
  }
  CHECK(woke);
}

template <int D, std::uint32_t N, class Sig>
void asleep_world_costs_nothing(const Sig& sig, BroadPhase broad_phase)
{
  WorldDef<D> def;
  def.broad_phase = broad_phase;
  auto w = std::make_unique<World<D, N, 8, 16 * N>>(def);
  REQUIRE(settle<D>(*w, sig, int(N) - 1) > 0);
  check_asleep_steps(*w);
  check_wakes<D>(*w);
}

}  // namespace

TEST_CASE("a fully asleep 3D world does no work per body (grid)")
{
  asleep_world_costs_nothing<3, 121>(testing::cube_synthetic, BroadPhase::grid);
}

TEST_CASE("a fully asleep 3D world does no work per body (sweep-and-prune)")
{
  asleep_world_costs_nothing<3, 121>(testing::cube_synthetic, BroadPhase::sweep_and_prune);
}

TEST_CASE("a fully asleep 2D world does no work per body (grid and sweep-and-prune)")
{
  asleep_world_costs_nothing<2, 61>(testing::square2d_synthetic, BroadPhase::grid);
  asleep_world_costs_nothing<2, 61>(testing::square2d_synthetic, BroadPhase::sweep_and_prune);
}

TEST_CASE("hull contacts: a fully asleep world does no work per body")
{
  WorldDef<3> def;
  def.body_contacts = BodyContacts::hulls;
  auto w = std::make_unique<World<3, 121>>(def);
  REQUIRE(settle<3>(*w, testing::cube_synthetic, 120) > 0);
  check_asleep_steps(*w);
}
