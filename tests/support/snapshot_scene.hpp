// Test fixture: a small pile for snapshot tests (tests/test_snapshot.cpp, tests/test_no_heap.cpp,
// tests/fuzz/fuzz_snapshot.cpp): statistical bodies of a committed table with body-body data and
// plain spheres dropped into a bin, some removed and their slots reused part way, so that a
// snapshot taken after `steps` steps holds moving, settling and sleeping bodies, touching pairs,
// removed slots and advanced generations.
#pragma once

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include "tables/box.hpp"
#include "tables/square2d.hpp"

#include <cstdint>

namespace statsim::testing {

/// The shapes of the scene, in order: a world loads a snapshot of it only with these.
template <int D, class World>
bool add_snapshot_shapes(World& w)
{
  ShapeDef ball;
  ball.radius = 0.08f;
  if constexpr (D == 3) {
    if (!w.add_shape(statsim::tables::box.view()).ok()) return false;
  } else {
    if (!w.add_shape(statsim::tables::square2d.view()).ok()) return false;
  }
  return w.add_shape(ball).ok();
}

/// Builds the pile (shapes, a bin, `bodies` bodies) and steps it `steps` times, removing every
/// fifth body after a third of the steps and adding a few in their place. False if a call failed.
template <int D, class World>
bool build_snapshot_scene(World& w, std::uint32_t bodies, int steps)
{
  using Vec = typename Space<D>::Vec;
  if (!add_snapshot_shapes<D>(w)) return false;
  bool ok = w.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok() && w.add_plane(Vec::Unit(0), -0.6f).ok() &&
            w.add_plane(-Vec::Unit(0), -0.6f).ok();
  if constexpr (D == 3) ok = ok && w.add_plane(Vec::Unit(1), -0.6f).ok() && w.add_plane(-Vec::Unit(1), -0.6f).ok();
  Pcg32 g(21, 6);
  BodyId ids[512];
  if (!ok || bodies > 512) return false;
  for (std::uint32_t i = 0; i < bodies; ++i) {
    BodyDef<D> b;
    b.shape = ShapeId(std::uint16_t(i % 4 == 3 ? 1 : 0));
    for (int k = 0; k < D; ++k) b.position[k] = g.uniform(-0.5f, 0.5f);
    b.position[Space<D>::up_axis] = g.uniform(0.2f, 2.5f);
    if constexpr (D == 3) {
      b.angular_velocity = Vector3(g.uniform(-4, 4), g.uniform(-4, 4), g.uniform(-4, 4));
    } else {
      b.angular_velocity = g.uniform(-4, 4);
    }
    const auto added = w.add_body(b);
    if (!added.ok()) return false;
    ids[i] = added.id;
  }
  for (int s = 0; s < steps; ++s) {
    if (s == steps / 3) {
      for (std::uint32_t i = 0; i < bodies; i += 5)
        if (w.remove_body(ids[i]) != Status::ok) return false;
      for (std::uint32_t i = 0; i < bodies / 10; ++i) {
        BodyDef<D> b;
        b.position[Space<D>::up_axis] = 1.5f + 0.2f * float(i);
        if (!w.add_body(b).ok()) return false;
      }
    }
    if (w.step(Scalar(1) / 60).status != Status::ok) return false;
  }
  return true;
}

}  // namespace statsim::testing
