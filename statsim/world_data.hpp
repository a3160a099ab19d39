#pragma once
/// @file
/// The data the phases of a step share: `WorldData` (the world's arrays, counts and parameters,
/// capacity-erased), `StepContext` (what one step counts as it goes), the first phase
/// (`integrate`) and the state hash.

#include "statsim/world_def.hpp"
#include "statsim/random.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// A world's storage (owned by `World<>`), counts and parameters: what every phase reads.
template <int D>
struct WorldData {
  Body<D>* bodies;
  SweepEntry* entries;  ///< the sweep-and-prune order of the first `entry_count` bodies
  Pair* pairs;
  Plane<D>* planes;
  Shape<D>* shapes;
  SpatialHash<D> grid;
  std::uint32_t max_bodies, max_pairs, max_planes, max_shapes;
  std::uint32_t body_count = 0, pair_count = 0, plane_count = 0, shape_count = 0;
  /// Bodies that have a sweep entry: sweep-and-prune adds the entries of newer bodies when it
  /// next runs, so the grid never touches them.
  std::uint32_t entry_count = 0;
  std::uint64_t step_count = 0;
  std::uint64_t energy_clamps = 0;  ///< over the world's life
  WorldDef<D> def{};
};

/// What one step counts as its phases run; the passes reset the counter they test.
struct StepContext {
  Scalar dt;
  /// Body-body contacts of the impact pass: the pairs at the front of the pair buffer that the
  /// later passes visit.
  std::uint32_t touching = 0;
  std::uint32_t moves = 0;          ///< position corrections since the counter was reset
  std::uint32_t changes = 0;        ///< impulses and position corrections since it was reset
  std::uint32_t energy_clamps = 0;  ///< sampled responses the energy guard scaled down
};

/// Lever arm of a body in the particle response: its radius for a sphere; 0 for a statistical
/// body, whose sphere is not its shape, so friction on the sphere must not spin it (a spin it
/// does not have would come back as speed).
template <int D>
Scalar contact_radius(const WorldData<D>& w, const Body<D>& b)
{
  return w.shapes[b.shape].statistical ? Scalar(0) : b.radius;
}

/// The body's random stream, where it left off.
template <int D>
Pcg32 rng_of(const WorldData<D>& w, const Body<D>& b)
{
  return Pcg32::resume(b.rng_state, body_stream(w.def.seed, std::uint32_t(&b - w.bodies)));
}

template <int D>
void wake(Body<D>& b)
{
  b.state = MotionState::moving;
  b.slow_time = 0;
  b.step_start = b.position;  // a sleeper is not integrated: this is where it started the step
}

/// Semi-implicit Euler for awake bodies: gravity and damping change the velocity, which then
/// moves the body; orientation without trigonometry (`detail::integrate`).
template <int D>
void integrate(WorldData<D>& w, Scalar dt)
{
  using Vec = typename Space<D>::Vec;
  const Vec dv = w.def.gravity * dt;
  const Scalar lin_damp = Scalar(1) / (1 + dt * w.def.linear_damping);
  const Scalar ang_damp = Scalar(1) / (1 + dt * w.def.angular_damping);
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    Body<D>& b = w.bodies[i];
    if (b.state == MotionState::asleep) continue;
    b.step_start = b.position;
    b.linear_velocity = (b.linear_velocity + dv) * lin_damp;
    b.angular_velocity = b.angular_velocity * ang_damp;
    b.position += b.linear_velocity * dt;
    b.orientation = integrate(b.orientation, b.angular_velocity, dt);
  }
}

/// FNV-1a hash of the world's state (see `WorldCore::state_hash`).
template <int D>
std::uint64_t state_hash(const WorldData<D>& w)
{
  Fnv1a h;
  h.add(w.body_count);
  h.add(w.plane_count);
  h.add(w.shape_count);
  h.add(w.step_count);
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    const Body<D>& b = w.bodies[i];
    h.add_vec(b.position);
    h.add_rot(b.orientation);
    h.add_vec(b.linear_velocity);
    h.add_spin(b.angular_velocity);
    h.add(b.radius);
    h.add(b.bounding_radius);
    h.add(b.inv_mass);
    h.add(b.slow_time);
    h.add(b.rng_state);
    h.add(b.rest_blend);
    h.add(b.shape);
    h.add(std::uint8_t(b.state));
    h.add(std::uint8_t(b.touching));
    h.add(std::uint8_t(b.on_ground));
    h.add(b.rest_pose);
    h.add(std::uint8_t(b.pile_rest));
  }
  for (std::uint32_t i = 0; i < w.plane_count; ++i) {
    h.add_vec(w.planes[i].normal);
    h.add(w.planes[i].offset);
  }
  for (std::uint32_t i = 0; i < w.shape_count; ++i) {
    h.add(w.shapes[i].radius);
    h.add(w.shapes[i].bounding_radius);
    h.add(w.shapes[i].material.restitution);
    h.add(w.shapes[i].material.friction);
  }
  return h.value;
}

}  // namespace detail
}  // namespace statsim
