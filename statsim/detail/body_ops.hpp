#pragma once
/// @file
/// What a user does to one body between steps: add it, set its velocity or pose, kick it with
/// an impulse, wake it or put it to sleep. Each checks everything first and returns a `Status`,
/// so that a rejected call changes nothing; `WorldCore` forwards to these.

#include "statsim/detail/checks.hpp"
#include "statsim/detail/world_data.hpp"

#include <cstdint>
#include <limits>

namespace statsim {
namespace detail {

/// Slot index of the live body `id` names, or `no_slot` when it names none.
template <int D>
std::uint32_t find_slot(const WorldData<D>& w, BodyId id)
{
  return w.slots.find(id, w.body_count);
}

/// Adds a body whose state passed `check_state`, of a shape the world owns.
template <int D>
Added<BodyId> add_body(WorldData<D>& w, const BodyDef<D>& def)
{
  using Vec = typename Space<D>::Vec;
  const Shape<D>& shape = w.shapes[def.shape.index];
  const Scalar mass = def.mass == 0 ? shape.mass : def.mass;
  if (!finite(mass)) return {Status::non_finite, 0};
  if (!(mass > 0)) return {Status::invalid_mass, 0};
  if (mass < limits::min_mass || mass > limits::max_mass) return {Status::out_of_range, 0};
  // A removed slot is reused before a new one, the lowest first.
  BodySlots& slots = w.slots;
  std::uint32_t id = w.body_count;
  if (slots.free_count > 0) {
    std::uint32_t k = 0;
    while (slots.free[k] == 0) ++k;
    id = k * 32 + lowest_bit(slots.free[k]);
  } else if (w.body_count == w.max_bodies) {
    return {Status::capacity_exceeded, 0};
  }
  const std::uint32_t generation = id < w.body_count ? slots.generation[id] : 0u;
  Body<D>& b = w.bodies[id];
  b.position = def.position;
  b.orientation = normalized(def.orientation);
  b.linear_velocity = def.asleep ? Vec::Zero() : def.linear_velocity;
  b.angular_velocity = def.asleep ? Space<D>::zero_spin() : def.angular_velocity;
  b.radius = shape.statistical
                 ? collision_radius<D>(shape.signature, b.linear_velocity, b.angular_velocity)
                 : shape.radius;
  w.widest = 2 * shape.bounding_radius > w.widest ? 2 * shape.bounding_radius : w.widest;
  b.inv_mass = Scalar(1) / mass;
  b.slow_time = 0;
  b.step_start = b.position;
  // The slot's stream from another start in each generation (the first's is the seed's).
  const std::uint64_t start = w.def.seed + generation * std::uint64_t(0x9e3779b97f4a7c15ull);
  b.rng_state = Pcg32(start, body_stream(w.def.seed, id)).state();
  b.shape = std::uint16_t(def.shape.index & ((1u << shape_index_bits) - 1u));  // checked below shape_count
  b.state = def.asleep ? MotionState::asleep : MotionState::moving;
  b.touching = false;
  b.on_ground = false;
  b.rest_pose = no_rest_pose;
  b.pile_rest = false;
  b.rest_blend = 0;
  if (!def.asleep) {
    set_bit(w.awake, id);
    ++w.awake_count;
  }
  if (id < w.body_count) {
    clear_bit(slots.free, id);
    --slots.free_count;
    --slots.removed;
    w.sweep_current = false;  // the slot's sweep entry is where the removed body was
    note_moved(w, id);
  } else {
    slots.generation[id] = 0;
    ++w.body_count;
  }
  return {Status::ok, make_body_id(id, generation)};
}

/// Removes a body: it leaves the awake set and the broad phase (at infinity, where no interval
/// or cell reaches it), sleepers whose bounding spheres reach it wake (what rested on it), and
/// its slot's generation advances so that its id is refused from now on.
template <int D>
Status remove_body(WorldData<D>& w, BodyId id)
{
  using Vec = typename Space<D>::Vec;
  const std::uint32_t slot = find_slot(w, id);
  if (slot == no_slot) return Status::invalid_body;
  Body<D>& b = w.bodies[slot];
  const Scalar bound = w.shapes[b.shape].bounding_radius;
  // Bodies resting on it touch it at their reach, give or take rounding: reaches grown by 1%.
  for (std::uint32_t j = 0; j < w.body_count; ++j) {
    Body<D>& o = w.bodies[j];
    const Scalar reach = (bound + w.shapes[o.shape].bounding_radius) * Scalar(1.01);
    if (j != slot && o.state == MotionState::asleep && w.slots.live(j) &&
        (o.position - b.position).squaredNorm() <= reach * reach)
      wake(w, o);
  }
  if (b.state != MotionState::asleep) {
    clear_bit(w.awake, slot);
    --w.awake_count;
  }
  clear_bit(w.flagged, slot);
  b.position = Vec::Constant(std::numeric_limits<Scalar>::infinity());
  b.step_start = b.position;
  b.linear_velocity = Vec::Zero();
  b.angular_velocity = Space<D>::zero_spin();
  b.state = MotionState::asleep;
  b.touching = false;
  b.on_ground = false;
  b.rest_pose = no_rest_pose;
  b.pile_rest = false;
  b.rest_blend = 0;
  b.slow_time = 0;
  w.sweep_current = false;
  const std::uint16_t generation = std::uint16_t(w.slots.generation[slot] + 1);
  w.slots.generation[slot] = generation;
  ++w.slots.removed;
  if (generation != retired_generation) {
    set_bit(w.slots.free, slot);
    ++w.slots.free_count;
  }
  return Status::ok;
}

/// Moves a body and wakes it.
template <int D>
Status set_transform(WorldData<D>& w, BodyId id, const typename Space<D>::Vec& position,
                     const typename Space<D>::Rot& orientation)
{
  const std::uint32_t slot = find_slot(w, id);
  if (slot == no_slot) return Status::invalid_body;
  const Status s = check_state<D>(position, orientation, Space<D>::Vec::Zero(), Space<D>::zero_spin());
  if (s != Status::ok) return s;
  Body<D>& b = w.bodies[slot];
  b.position = position;
  b.orientation = normalized(orientation);
  wake(w, b);
  note_moved(w, slot);
  return Status::ok;
}

/// v rotated by the unit quaternion q: v + 2 w (u x v) + 2 u x (u x v), u the vector part,
/// written out so that no vectorised product rounds it differently on another build.
inline Vector3 rotate(const Quaternion& q, const Vector3& v)
{
  const Scalar tx = 2 * (q.y() * v.z() - q.z() * v.y());
  const Scalar ty = 2 * (q.z() * v.x() - q.x() * v.z());
  const Scalar tz = 2 * (q.x() * v.y() - q.y() * v.x());
  return Vector3(v.x() + q.w() * tx + (q.y() * tz - q.z() * ty), v.y() + q.w() * ty + (q.z() * tx - q.x() * tz),
                 v.z() + q.w() * tz + (q.x() * ty - q.y() * tx));
}

/// Moment of inertia over mass about the body's principal axis k, m^2: the table's
/// `unit_inertia` for a statistical body (a table that records 0 counts as a solid sphere of its
/// bounding radius), k r^2 for a plain sphere of radius r (k = 2/5 in 3D, 1/2 for a 2D disc).
template <int D>
Scalar unit_inertia(const WorldData<D>& w, const Body<D>& b, int k)
{
  const Shape<D>& s = w.shapes[b.shape];
  const Scalar sphere_r = s.statistical ? s.signature.bounding_radius : s.radius;
  const Scalar sphere = Space<D>::inertia_factor * sphere_r * sphere_r;
  if (!s.statistical) return sphere;
  const Scalar u = s.signature.unit_inertia[std::size_t(k)];
  return u > 0 ? u : sphere;
}

/// The change of angular velocity from an angular impulse `l` (N m s, world frame):
/// I^-1 l = R diag(1 / (m u_k)) R^T l, R the body's orientation.
inline Vector3 spin_change(const WorldData<3>& w, const Body<3>& b, const Vector3& l)
{
  const Vector3 lb = rotate(b.orientation.conjugate(), l);
  const Vector3 wb(lb.x() * b.inv_mass / unit_inertia(w, b, 0), lb.y() * b.inv_mass / unit_inertia(w, b, 1),
                   lb.z() * b.inv_mass / unit_inertia(w, b, 2));
  return rotate(b.orientation, wb);
}
inline Scalar spin_change(const WorldData<2>& w, const Body<2>& b, Scalar l)
{
  return l * b.inv_mass / unit_inertia(w, b, 0);
}

/// Sets the velocities of the body in `slot` if they are finite and within the limits, and
/// wakes it.
template <int D>
Status set_velocities(WorldData<D>& w, std::uint32_t slot, const typename Space<D>::Vec& v,
                      const typename Space<D>::Spin& spin)
{
  if (!finite(v) || !finite(spin)) return Status::non_finite;
  if (!within(v, limits::speed) || !within(spin, limits::spin)) return Status::out_of_range;
  Body<D>& b = w.bodies[slot];
  b.linear_velocity = v;
  b.angular_velocity = spin;
  wake(w, b);
  return Status::ok;
}

/// dv = J / m, dw = I^-1 (r x J), r from the centre of mass to `point`.
template <int D>
Status apply_impulse(WorldData<D>& w, BodyId id, const typename Space<D>::Vec& impulse,
                     const typename Space<D>::Vec& point)
{
  const std::uint32_t slot = find_slot(w, id);
  if (slot == no_slot) return Status::invalid_body;
  if (!finite(impulse) || !finite(point)) return Status::non_finite;
  if (!within(point, limits::coordinate)) return Status::out_of_range;
  const Body<D>& b = w.bodies[slot];
  const auto l = moment(typename Space<D>::Vec(point - b.position), impulse);
  return set_velocities(w, slot, typename Space<D>::Vec(b.linear_velocity + impulse * b.inv_mass),
                        typename Space<D>::Spin(b.angular_velocity + spin_change(w, b, l)));
}

template <int D>
Status apply_angular_impulse(WorldData<D>& w, BodyId id, const typename Space<D>::Spin& l)
{
  const std::uint32_t slot = find_slot(w, id);
  if (slot == no_slot) return Status::invalid_body;
  if (!finite(l)) return Status::non_finite;
  const Body<D>& b = w.bodies[slot];
  return set_velocities(w, slot, b.linear_velocity, typename Space<D>::Spin(b.angular_velocity + spin_change(w, b, l)));
}

template <int D>
Status wake_body(WorldData<D>& w, BodyId id)
{
  const std::uint32_t slot = find_slot(w, id);
  if (slot == no_slot) return Status::invalid_body;
  wake(w, w.bodies[slot]);
  return Status::ok;
}

/// As a body falls asleep at the end of a step (`update_motion_states`): still, off the awake
/// set, its contact flags left for the next step to clear.
template <int D>
Status sleep_body(WorldData<D>& w, BodyId id)
{
  const std::uint32_t slot = find_slot(w, id);
  if (slot == no_slot) return Status::invalid_body;
  Body<D>& b = w.bodies[slot];
  if (b.state == MotionState::asleep) return Status::ok;
  b.state = MotionState::asleep;
  clear_bit(w.awake, slot);
  --w.awake_count;
  set_bit(w.flagged, slot);
  b.linear_velocity = Space<D>::Vec::Zero();
  b.angular_velocity = Space<D>::zero_spin();
  b.slow_time = 0;
  return Status::ok;
}

}  // namespace detail
}  // namespace statsim
