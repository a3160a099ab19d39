// The worlds of the snapshot fuzz target (fuzz_snapshot.cpp) and of its seed generator
// (snapshot_seeds.cpp): small, so that capacity limits are met.
#pragma once

#include "../support/snapshot_scene.hpp"

#include "statsim/snapshot.hpp"

namespace statsim::fuzz {

using SnapWorld3 = World3<40, 8, 240, 4, 8>;
using SnapWorld2 = World2<40, 8, 160, 4, 8>;

/// The scene a seed snapshot is taken from: a pile of `bodies` after `steps` steps, with the
/// given parameters (`testing::build_snapshot_scene`).
template <int D, class World>
bool build_seed_world(World& w, const WorldDef<D>& def, std::uint32_t bodies, int steps)
{
  return w.configure(def) == Status::ok && testing::build_snapshot_scene<D>(w, bodies, steps);
}

}  // namespace statsim::fuzz
