#pragma once
/// @file
/// FNV-1a hashes of what a step reads: a world's state (`WorldCore::state_hash`) and a
/// signature (`Shape::signature_hash`, computed by `add_shape`).

#include "statsim/detail/world_data.hpp"
#include "statsim/math.hpp"
#include "statsim/signature.hpp"

#include <cstddef>
#include <cstdint>

namespace statsim {
namespace detail {

/// Adds every parameter of a world to a hash. A new `WorldDef` field belongs here too, but for
/// `WorldDef::workers`, which does not change results.
template <int D>
void hash_def(Fnv1a& h, const WorldDef<D>& d)
{
  h.add_vec(d.gravity);
  h.add_all(d.seed, d.restitution_threshold, d.settle_speed, d.sleep_speed, d.sleep_time, d.wake_speed,
            d.linear_damping, d.angular_damping, std::int32_t(d.support_iterations),
            std::uint8_t(d.shock_propagation), std::int32_t(d.position_iterations), d.allowed_overlap,
            d.overlap_correction, d.spin_ratio_speed_floor, std::uint8_t(d.nearest_radius),
            std::uint8_t(d.pair_response), std::uint8_t(d.rest_conditions), std::uint8_t(d.pile_rest),
            d.rest_blend_time, d.rest_turn_time, d.rest_snap_cosine, d.ground_cosine, std::uint8_t(d.broad_phase),
            d.grid_above_bodies, std::int32_t(d.sweep_axis), std::uint8_t(d.table_restitution_threshold));
  // Added only when not the value of before the option (collision spheres, islands off), so
  // that worlds from before it keep their hashes.
  if (d.body_contacts != BodyContacts::collision_spheres) h.add(std::uint8_t(d.body_contacts));
  if (d.impact_threshold != WorldDef<D>{}.impact_threshold) h.add(d.impact_threshold);
  if (d.sleep_islands) h.add(std::uint8_t(0x51));
  if (d.ground_hulls) h.add(std::uint8_t(0x47));
}

/// Adds a table's numbers as the runtime reads them (16-bit ones as their values).
inline void hash_values(Fnv1a& h, const ValuesView& v, std::uint32_t n)
{
  for (std::uint32_t i = 0; i < n; ++i) h.add(v[i]);
}
inline void hash_axis(Fnv1a& h, const AxisView& a)
{
  h.add(a.size);
  for (std::uint32_t i = 0; i < a.size; ++i) h.add(a.values[i]);
}

/// FNV-1a hash of everything of a signature that a step reads: its scalars, axes, tables and
/// rest poses. Computed once, by `add_shape`; the signature must have passed `check_signature`.
template <int D>
std::uint64_t signature_hash(const SignatureView<D>& sig)
{
  Fnv1a h;
  h.add_all(sig.length, sig.bounding_radius, sig.mass, sig.unit_inertia[0], sig.unit_inertia[1],
            sig.unit_inertia[2], sig.material.restitution, sig.material.friction, sig.material.rolling_resistance,
            sig.restitution_threshold, std::uint8_t(sig.layout));
  hash_axis(h, sig.height.spin_ratio);
  hash_values(h, sig.height.mean, sig.height.spin_ratio.size);
  hash_values(h, sig.height.stddev, sig.height.spin_ratio.size);
  const ResponseTableView& r = sig.response;
  h.add_all(r.axis_count, r.components, std::uint8_t(r.model), r.spread_per_cell);
  std::uint32_t cells = 1;
  for (std::uint32_t a = 0; a < r.axis_count; ++a) {
    hash_axis(h, r.axes[a]);
    cells *= r.axes[a].size;
  }
  hash_values(h, r.mean, cells * r.components);
  hash_values(h, r.spread, cells * r.spread_per_cell);
  h.add(sig.rest.count);
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    h.add_vec(sig.rest.normal(i));
    h.add(sig.rest.heights[i]);
    h.add(sig.rest.frequencies[i]);
  }
  // Body-body data, landing data, settling data and the spin measure, each when the table has
  // it (a table without them hashes as before).
  const ContactView<D>& c = sig.contact;
  if (c.present()) {
    h.add_all(c.support_size, c.face_count);
    hash_values(h, c.support, c.support_count());
    for (std::uint32_t i = 0; i < c.face_count * face_values(D); ++i) h.add(c.faces[i]);
    if (c.offset_scale != 1) h.add(c.offset_scale);  // a shape of another size (a table's own hashes as before)
    for (std::size_t k = 0; k < 3; ++k) h.add_all(c.packing_mean[k], c.packing_stddev[k]);
    if (c.pair_mean != nullptr)
      for (std::uint32_t i = 0; i < sig.height.spin_ratio.size; ++i) h.add_all(c.pair_mean[i], c.pair_stddev[i]);
  }
  const LandingView& l = sig.landing;
  if (l.present()) {
    h.add(l.hop);
    for (const AxisView& a : l.axes) hash_axis(h, a);
    for (std::uint32_t i = 0; i < l.probability.size; ++i) h.add(l.probability[i]);
  }
  const SettleView& t = sig.settle;
  if (t.present()) {
    h.add(t.quantiles);
    for (std::uint32_t i = 0; i < t.time.size; ++i) h.add(t.time.values[i]);
    if (sig.scale != 1) h.add(sig.scale);  // settling times scale with the shape (`update_rest_pose`)
  }
  if (sig.spin != ResponseSpin::length) h.add(std::uint8_t(sig.spin));  // a `length` table hashes as before
  return h.value;
}

/// FNV-1a hash of the world's state (see `WorldCore::state_hash`).
template <int D>
std::uint64_t state_hash(const WorldData<D>& w)
{
  Fnv1a h;
  h.add_all(w.body_count, w.plane_count, w.shape_count, w.step_count);
  hash_def(h, w.def);
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    const Body<D>& b = w.bodies[i];
    h.add_vec(b.position);
    h.add_rot(b.orientation);
    h.add_vec(b.linear_velocity);
    h.add_spin(b.angular_velocity);
    h.add_all(b.radius, w.shapes[b.shape].bounding_radius, b.inv_mass, b.slow_time, std::uint64_t(b.rng_state),
              b.rest_blend, b.shape,
              std::uint8_t(b.state), std::uint8_t(b.touching), std::uint8_t(b.on_ground), b.rest_pose,
              std::uint8_t(b.pile_rest));
  }
  for (std::uint32_t i = 0; i < w.plane_count; ++i) {
    h.add_vec(w.planes[i].normal);
    h.add(w.planes[i].offset);
  }
  for (std::uint32_t i = 0; i < w.shape_count; ++i) {
    const Shape<D>& s = w.shapes[i];
    h.add_all(s.radius, s.bounding_radius, s.material.restitution, s.material.friction,
              s.material.rolling_resistance, std::uint8_t(s.statistical));
    if (!s.statistical) continue;
    h.add(s.signature_hash);
    h.add(s.mean_rest_height);
    for (std::uint32_t k = 0; k < s.signature.rest.count; ++k) h.add(s.rest_bias[k]);
  }
  // Slot generations decide the ids and random streams of reused slots; a world that never
  // removed a body has none and hashes as before removal existed.
  std::uint32_t removals = 0;
  for (std::uint32_t i = 0; i < w.body_count; ++i) removals += w.slots.generation[i];
  if (removals > 0)
    for (std::uint32_t i = 0; i < w.body_count; ++i) h.add(w.slots.generation[i]);
  // The sweep-and-prune order breaks ties between equal interval starts, so it decides the order
  // of pairs, and with it of contacts.
  h.add(w.entry_count);
  for (std::uint32_t i = 0; i < w.entry_count; ++i) h.add(w.grid_layout ? w.order[i] : w.entries[i].body);
  return h.value;
}

}  // namespace detail
}  // namespace statsim
