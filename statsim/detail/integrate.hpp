#pragma once
/// @file
/// The first phase of a step: semi-implicit Euler for the awake bodies.

#include "statsim/detail/bits.hpp"
#include "statsim/detail/world_data.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// Semi-implicit Euler for awake bodies: gravity and damping change the velocity, which then
/// moves the body; orientation without trigonometry (`detail::integrate`). `own(i)` may move
/// body i through the step itself (`roll_on_slopes`) and return true. Returns the number of
/// bodies integrated.
template <class FS, int D, class Own>
std::uint32_t integrate(WorldData<D>& w, Scalar dt, Own&& own)
{
  using Vec = typename Space<D>::Vec;
  const Vec dv = w.def.gravity * dt;
  const Scalar lin_damp = Scalar(1) / (1 + dt * w.def.linear_damping);
  const Scalar ang_damp = Scalar(1) / (1 + dt * w.def.angular_damping);
  const bool hulls = FS::hull_contacts && hull_contacts_on(w);
  std::uint32_t count = 0;
  for_each_set(w.awake, w.body_count, [&](std::uint32_t i) {
    Body<D>& b = w.bodies[i];
    // The sleep test may measure from where the body's slow time began (`sleeps_from_anchor`):
    // the centre is kept there while the clock runs.
    if (b.slow_time <= 0 || !hulls || !sleeps_from_anchor<FS>(w, b)) b.step_start = b.position;
    ++count;
    if (own(i)) return;
    b.linear_velocity = (b.linear_velocity + dv) * lin_damp;
    b.angular_velocity = b.angular_velocity * ang_damp;
    b.position += b.linear_velocity * dt;
    b.orientation = integrate(b.orientation, b.angular_velocity, dt);
  });
  return count;
}

}  // namespace detail
}  // namespace statsim
