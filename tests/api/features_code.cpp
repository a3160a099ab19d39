// A program whose worlds are compiled with one feature set (statsim/features.hpp), FEATURES_ALL
// 1: `Features::all` with the grid and impact events; 0: `Features::paper`, sweep-and-prune
// only, no events. tests/api/features_code.cmake reads its symbols: the code of what the set
// leaves out must not be in it. Built without inlining, so that every function that is compiled
// keeps its own symbol.
#include "statsim/queries.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/square2d.hpp"

#include <cstdio>

#if FEATURES_ALL
constexpr statsim::Features features = statsim::Features::all;
constexpr statsim::BroadPhase phases = statsim::BroadPhase::automatic;
constexpr std::uint32_t impacts = 16;
#else
constexpr statsim::Features features = statsim::Features::paper;
constexpr statsim::BroadPhase phases = statsim::BroadPhase::sweep_and_prune;
constexpr std::uint32_t impacts = 0;
#endif

namespace {
statsim::World3<32, 4, 256, 2, impacts, phases, features> world3;
statsim::World2<32, 4, 256, 2, impacts, phases, features> world2;

template <int D, class World, class Table>
bool run(World& w, const Table& table)
{
  using Vec = typename statsim::Space<D>::Vec;
  const statsim::ShapeId s = w.add_shape(table.view()).id;
  if (!w.add_plane(Vec::Unit(statsim::Space<D>::up_axis), 0).ok()) return false;
  for (int i = 0; i < 32; ++i) {
    statsim::BodyDef<D> b;
    b.shape = s;
    b.position[statsim::Space<D>::up_axis] = 0.3f + 0.3f * float(i);
    if (!w.add_body(b).ok()) return false;
  }
  for (int k = 0; k < 60; ++k)
    if (!w.step(1.0f / 60).ok()) return false;
  statsim::QueryHit<D> hit;
  const statsim::Status q = ray_cast(w, Vec::Unit(statsim::Space<D>::up_axis), -Vec::Unit(1), 2, hit);
  std::printf("hash 0x%016llx query %s\n", static_cast<unsigned long long>(w.state_hash()), statsim::to_string(q));
  return true;
}
}  // namespace

int main() { return run<3>(world3, statsim::tables::box) && run<2>(world2, statsim::tables::square2d) ? 0 : 1; }
