#pragma once
/// @file
/// The first phase of a step: gravity, damping and motion of the awake bodies.

#include "statsim/detail/bits.hpp"
#include "statsim/detail/world_data.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// Gravity and damping change the velocity of each awake body, and the mean of its velocities
/// before and after moves it; orientation without trigonometry (`detail::integrate`). `own(i)`
/// may move body i through the step itself (`roll_on_slopes`) and return true. Returns the
/// number of bodies integrated.
///
/// Why the mean: under constant gravity x + (v + v') dt / 2 = x + v dt + g dt^2 / 2 is the exact
/// flight at any step, where semi-implicit Euler's x + v' dt takes g dt^2 / 2 too much a step.
/// A statistical body flies between contacts, and that error shows there: a flight launched at
/// v_n peaks v_n dt / 2 lower (4 mm of a 1 cm hop at 60 Hz), lands early, and travels less; a
/// fall of t seconds leads by g t dt / 2. Velocities, and so every impulse, are unchanged.
///
/// A body that ended the last step touching something (`Body::touching`) and does not rise from
/// it faster than gravity takes back in a step, -v.g <= |g|^2 dt, is supported, not flying: it
/// keeps x + v' dt. Such a body sinks g dt^2 into its support each step and the contact passes
/// lift it out; the mean would halve that sink, and heaps whose bodies hold each other stood
/// looser and higher than the rigid-body reference (tools/fidelity/LOG.md, "Exact flights for
/// flying bodies only"). A body leaving its support faster, a hop's launch, flies the parabola.
template <class FS, int D, class Own>
std::uint32_t integrate(WorldData<D>& w, Scalar dt, Own&& own)
{
  using Vec = typename Space<D>::Vec;
  const Vec dv = w.def.gravity * dt;
  const Scalar g2 = w.def.gravity.squaredNorm();
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
    const Vec before = b.linear_velocity;
    b.linear_velocity = (before + dv) * lin_damp;
    b.angular_velocity = b.angular_velocity * ang_damp;
    if (b.touching && !(-before.dot(w.def.gravity) > g2 * dt))
      b.position += b.linear_velocity * dt;  // supported: semi-implicit Euler, as the passes expect
    else
      b.position += (before + b.linear_velocity) * (dt / 2);
    b.orientation = integrate(b.orientation, b.angular_velocity, dt);
  });
  return count;
}

}  // namespace detail
}  // namespace statsim
