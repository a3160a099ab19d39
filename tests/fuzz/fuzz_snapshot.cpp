// libFuzzer target: `load` (statsim/snapshot.hpp) fed arbitrary bytes, in 2D and 3D.
//
// The first byte picks the dimension (bit 0: 2D), how many steps follow an accepted load
// (bits 1-2) and whether the snapshot's size field and checksum are rewritten to match the bytes
// (bit 3), so that mutations reach the checks behind the checksum; the rest is the snapshot. The world loaded into holds a small pile of its own
// (with the scene's shapes, so that a snapshot of the scene can load). Checked:
//  - a refused load changes nothing: state_hash, counts, and the next steps (against a twin);
//  - an accepted load saves back the same bytes (one encoding per state), and the world then
//    steps with every live body finite.
// Seeds: tests/fuzz/corpus/fuzz_snapshot/, written by snapshot_seeds.cpp.
#include "fuzz_input.hpp"
#include "snapshot_worlds.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace statsim::fuzz {
namespace {

template <int D>
bool body_finite(const Body<D>& b)
{
  return detail::finite(b.position) && detail::finite(b.orientation) && detail::finite(b.linear_velocity) &&
         detail::finite(b.angular_velocity);
}

/// The world's own state, restored before every input from its own snapshot.
template <class World>
struct Target {
  World world, twin;
  unsigned char own[16384];
  std::size_t own_size = 0;
  unsigned char again[16384];
};

template <int D, class World>
Target<World>& target()
{
  static Target<World>* t = [] {
    static Target<World> made;
    WorldDef<D> def;
    def.seed = 3;
    if (!build_seed_world<D>(made.world, def, 24, 40) || !testing::add_snapshot_shapes<D>(made.twin)) fail("set-up");
    if (save(made.world, made.own, sizeof made.own, &made.own_size) != Status::ok) fail("set-up save");
    return &made;
  }();
  return *t;
}

template <int D, class World>
void run(const std::uint8_t* data, std::size_t size, int steps)
{
  Target<World>& t = target<D, World>();
  if (load(t.world, t.own, t.own_size) != Status::ok || load(t.twin, t.own, t.own_size) != Status::ok)
    fail("the world's own snapshot did not load");
  const std::uint64_t before = t.world.state_hash();
  const std::uint32_t bodies = t.world.body_count(), planes = t.world.plane_count();
  const Status s = load(t.world, data, size);
  if (s != Status::ok) {
    if (t.world.state_hash() != before || t.world.body_count() != bodies || t.world.plane_count() != planes)
      fail("a refused load changed the world");
    for (int i = 0; i < 2; ++i) {
      if (!t.world.step(Scalar(1) / 60).ok() || !t.twin.step(Scalar(1) / 60).ok()) fail("step");
      if (t.world.state_hash() != t.twin.state_hash()) fail("a refused load changed the continuation");
    }
    return;
  }
  std::size_t n = 0;
  if (save(t.world, t.again, sizeof t.again, &n) != Status::ok || n != size) fail("an accepted load saves another size");
  for (std::size_t i = 0; i < n; ++i)
    if (t.again[i] != data[i]) fail("an accepted load saves other bytes");
  for (int i = 0; i < steps; ++i) {
    if (t.world.step(Scalar(1) / 60).status != Status::ok) fail("step");
    for (std::uint32_t k = 0; k < t.world.body_count(); ++k)
      if (t.world.alive(t.world.id_of(k)) && !body_finite(t.world.body(t.world.id_of(k))))
        fail("a body became non-finite after an accepted load");
  }
}

}  // namespace
}  // namespace statsim::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace statsim::fuzz;
  if (size < 1) return 0;
  const int steps = 1 + ((data[0] >> 1) & 3);
  const std::uint8_t mode = data[0];
  ++data;
  --size;
  static std::uint8_t sealed[16384];
  if ((mode & 8) && size >= 40 && size <= sizeof sealed) {
    for (std::size_t i = 0; i < size; ++i) sealed[i] = data[i];
    for (int i = 0; i < 4; ++i) sealed[8 + i] = static_cast<std::uint8_t>(size >> (8 * i));
    const std::uint64_t h = statsim::detail::fnv1a64(sealed, size - 8);
    for (int i = 0; i < 8; ++i) sealed[size - 8 + std::size_t(i)] = static_cast<std::uint8_t>(h >> (8 * i));
    data = sealed;
  }
  if (mode & 1)
    run<2, SnapWorld2>(data, size, steps);
  else
    run<3, SnapWorld3>(data, size, steps);
  return 0;
}
