#pragma once
/// @file
/// Checks of everything a user hands to a world: world parameters, shapes, body states and
/// signatures. Each returns the first problem it finds as a `Status`, so that a rejected call
/// can return before it changes anything.

#include "statsim/world_def.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// The parameters of a world: `non_finite` for a NaN or infinity, `invalid_parameter` for a
/// value outside its documented range.
template <int D>
Status check_world_def(const WorldDef<D>& d)
{
  if (!finite(d.gravity) || !finite(d.restitution_threshold) || !finite(d.settle_speed) || !finite(d.sleep_speed) ||
      !finite(d.sleep_time) || !finite(d.wake_speed) || !finite(d.linear_damping) || !finite(d.angular_damping) ||
      !finite(d.allowed_overlap) || !finite(d.overlap_correction) || !finite(d.rest_blend_time) ||
      !finite(d.rest_turn_time) || !finite(d.ground_cosine) || !finite(d.rest_snap_cosine) ||
      !finite(d.spin_ratio_speed_floor) || !finite(d.impact_threshold))
    return Status::non_finite;
  if (d.restitution_threshold < 0 || d.settle_speed < 0 || d.sleep_speed < 0 || d.sleep_time < 0 ||
      d.wake_speed < 0 || d.linear_damping < 0 || d.angular_damping < 0 || d.support_iterations < 1 ||
      d.support_iterations > 64 || d.position_iterations < 0 || d.position_iterations > 64 ||
      (d.broad_phase != BroadPhase::grid && d.broad_phase != BroadPhase::sweep_and_prune &&
       d.broad_phase != BroadPhase::automatic) ||
      (d.body_contacts != BodyContacts::collision_spheres && d.body_contacts != BodyContacts::hulls &&
       d.body_contacts != BodyContacts::automatic) ||
      (d.pair_response != PairResponse::independent && d.pair_response != PairResponse::momentum) ||
      d.allowed_overlap < 0 || d.allowed_overlap >= Scalar(0.5) ||
      !(d.overlap_correction > 0) || d.overlap_correction > 1 || !(d.rest_blend_time > 0) ||
      !(d.rest_turn_time > 0) || d.ground_cosine < 0 || d.ground_cosine > 1 || d.rest_snap_cosine < 0 ||
      d.rest_snap_cosine > 1 || d.spin_ratio_speed_floor < 0 || d.sweep_axis < 0 || d.sweep_axis >= D ||
      !within(d.gravity, limits::gravity) || d.rest_turn_time < Scalar(1e-4) || d.impact_threshold < 0 ||
      d.workers.count < 1 || d.workers.count > limits::max_workers ||
      (d.workers.count > 1 && (!STATSIM_WORKERS || d.workers.enqueue == nullptr || d.workers.finish == nullptr)))
    return Status::invalid_parameter;
  return Status::ok;
}

/// A plain sphere shape, whose bounding radius (0 meaning "the radius") is `bound`.
inline Status check_shape_def(const ShapeDef& def, Scalar bound)
{
  if (!finite(def.radius) || !finite(bound) || !finite(def.material.restitution) ||
      !finite(def.material.friction))
    return Status::non_finite;
  if (!(def.radius > 0) || bound < def.radius) return Status::invalid_radius;
  if (def.radius < limits::min_radius || bound > limits::max_radius) return Status::out_of_range;
  if (!finite(def.mass) || !finite(def.material.rolling_resistance)) return Status::non_finite;
  if (!(def.mass > 0)) return Status::invalid_mass;
  if (def.mass < limits::min_mass || def.mass > limits::max_mass) return Status::out_of_range;
  if (def.material.restitution < 0 || def.material.restitution > 1 || def.material.friction < 0 ||
      def.material.rolling_resistance < 0)
    return Status::invalid_material;
  return Status::ok;
}

/// A body's position, orientation and velocities.
template <int D>
Status check_state(const typename Space<D>::Vec& x, const typename Space<D>::Rot& q, const typename Space<D>::Vec& v,
                   const typename Space<D>::Spin& w)
{
  if (!finite(x) || !finite(q) || !finite(v) || !finite(w)) return Status::non_finite;
  const Scalar n2 = squared_norm(q);
  if (!(n2 > Scalar(1e-12))) return Status::zero_quaternion;
  // |q|^2 - 1 ~ 2 (|q| - 1): a tolerance of 1e-3 on the length.
  if (!(n2 > Scalar(1 - 2e-3) && n2 < Scalar(1 + 2e-3))) return Status::non_unit_quaternion;
  if (!within(x, limits::coordinate) || !within(v, limits::speed) || !within(w, limits::spin))
    return Status::out_of_range;
  return Status::ok;
}

/// True when a table's numbers can be read: float or 16-bit storage is present.
inline bool readable(const ValuesView& v) { return v.f32 != nullptr || v.i16 != nullptr; }
/// True when an axis has a sample and its values can be read.
inline bool readable(const AxisView& a) { return a.values != nullptr && a.size >= 1; }

/// The layout of a signature: every array the world will read is present, for every count
/// above 0, the counts fit the runtime, and each count fits the length of the arrays it counts,
/// so that no check and no step reads past an array of a view built by hand. The values are
/// checked by `check_signature_values`, which reads only what this one has measured.
template <int D>
Status check_signature_layout(const SignatureView<D>& sig)
{
  const HeightTableView& h = sig.height;
  if (!readable(h.spin_ratio) || !readable(h.mean) || !readable(h.stddev)) return Status::invalid_shape;
  const std::uint32_t heights = h.spin_ratio.size;
  if (h.mean.count() < heights || h.stddev.count() < heights) return Status::invalid_shape;
  const ResponseTableView& r = sig.response;
  const std::uint32_t expected_axes = (D == 3 ? 3u : 2u) + (sig.layout == ResponseLayout::with_speed ? 1u : 0u);
  if (r.axis_count != expected_axes || r.components != (D == 3 ? 6u : 3u)) return Status::invalid_shape;
  // A 2D spin is a scalar: its energy never depends on the orientation, so only `length` exists.
  if (sig.spin != ResponseSpin::length &&
      !(D == 3 && (sig.spin == ResponseSpin::gyration || sig.spin == ResponseSpin::energy)))
    return Status::invalid_shape;
  // The spread's size is its model's; an empirical table stores 1 to max_empirical_outcomes
  // outcomes a cell.
  const std::uint32_t s = r.spread_per_cell;
  switch (r.model) {
    case ResponseModel::independent_gaussian:
    case ResponseModel::correlated_gaussian:
      if (s != response_spread_size(r.model, r.components)) return Status::invalid_shape;
      break;
    case ResponseModel::empirical:
      if (s == 0 || s % r.components != 0 || s / r.components > max_empirical_outcomes) return Status::invalid_shape;
      break;
    default: return Status::invalid_shape;
  }
  // Cells times values per cell must fit the 32-bit offsets of `ResponseTableView::lookup`.
  std::uint64_t values = r.components > s ? r.components : s, cells = 1;
  for (std::uint32_t a = 0; a < r.axis_count; ++a) {
    if (!readable(r.axes[a])) return Status::invalid_shape;
    values *= r.axes[a].size;
    cells *= r.axes[a].size;
    if (values > 0x7fffffffu) return Status::invalid_shape;
  }
  if (!readable(r.mean) || !readable(r.spread)) return Status::invalid_shape;
  if (r.mean.count() < cells * r.components || r.spread.count() < cells * s) return Status::invalid_shape;
  const RestPosesView<D>& rest = sig.rest;
  if (rest.count > max_rest_poses) return Status::invalid_shape;
  if (rest.count > 0 && (rest.normals == nullptr || rest.heights == nullptr || rest.frequencies == nullptr))
    return Status::invalid_shape;
  if (rest.normals.size / D < rest.count || rest.heights.count() < rest.count || rest.frequencies.size < rest.count)
    return Status::invalid_shape;
  // Read by `mesh_to_world` only, but it is a count too (D (D + 1) numbers).
  if (sig.mesh_frame != nullptr && sig.mesh_frame.size < std::uint32_t(D * (D + 1))) return Status::invalid_shape;
  // Landing data: one probability per cell of its three axes, exactly.
  const LandingView& l = sig.landing;
  if (l.present()) {
    std::uint64_t landing_cells = 1;
    for (const AxisView& a : l.axes) {
      if (!readable(a)) return Status::invalid_shape;
      landing_cells *= a.size;
      if (landing_cells > 0x7fffffffu) return Status::invalid_shape;
    }
    if (l.probability.values == nullptr || l.probability.size != landing_cells) return Status::invalid_shape;
  }
  // Settling data: the same number of quantiles for every rest pose, and no more than a table
  // holds (`max_settle_quantiles`).
  const SettleView& t = sig.settle;
  if (t.present() && (t.time.values == nullptr || t.quantiles == 0 || t.quantiles > max_settle_quantiles ||
                      std::uint64_t(t.quantiles) * rest.count != t.time.size))
    return Status::invalid_shape;
  const ContactView<D>& c = sig.contact;
  if (c.support_size == 0) return Status::ok;
  if (c.support_size < 2 || c.support_size > max_support_size || !readable(c.support)) return Status::invalid_shape;
  // The map's layout follows from S, so its length is exactly S's: any other is the wrong S.
  if (c.support.count() != c.support_count()) return Status::invalid_shape;
  if ((c.pair_mean == nullptr) != (c.pair_stddev == nullptr)) return Status::invalid_shape;
  if (c.pair_mean != nullptr && (c.pair_mean.count() < heights || c.pair_stddev.count() < heights))
    return Status::invalid_shape;
  if (c.face_count > max_contact_faces || (c.face_count > 0 && c.faces == nullptr)) return Status::invalid_shape;
  if (c.faces.size / face_values(D) < c.face_count) return Status::invalid_shape;
  return Status::ok;
}

/// The numbers of a signature: every one finite, axes strictly increasing, heights positive,
/// rest normals unit, rest frequencies in [0, 1]. Table values are bounded (|x| <= 1e6:
/// normalised responses are O(1)) so that scaling them by a speed cannot overflow. One pass over
/// the tables, at add_shape only; the layout must have passed `check_signature_layout`.
template <int D>
Status check_signature_values(const SignatureView<D>& sig)
{
  constexpr Scalar bound = Scalar(1e6);
  const auto bad = [](Scalar x) { return !(x >= -bound && x <= bound); };  // NaN is bad
  const auto bad_axis = [&bad](const AxisView& a) {
    for (std::uint32_t i = 0; i < a.size; ++i)
      if (bad(a.values[i]) || (i > 0 && !(a.values[i] > a.values[i - 1]))) return true;
    return false;
  };
  const Material& m = sig.material;
  if (bad(m.restitution) || bad(m.friction) || bad(m.rolling_resistance) || bad(sig.restitution_threshold) ||
      !finite(sig.mass) || bad(sig.unit_inertia[0]) || bad(sig.unit_inertia[1]) || bad(sig.unit_inertia[2]))
    return Status::non_finite;
  // The mass is the default of every body made from the table: it must be one add_body accepts.
  // 0 stands for "not recorded" (then bodies must give theirs).
  if (sig.mass < 0) return Status::invalid_mass;
  if (sig.mass > 0 && (sig.mass < limits::min_mass || sig.mass > limits::max_mass)) return Status::out_of_range;
  if (m.rolling_resistance < 0 || sig.restitution_threshold < 0) return Status::invalid_material;
  if (sig.unit_inertia[0] < 0 || sig.unit_inertia[1] < 0 || sig.unit_inertia[2] < 0) return Status::invalid_shape;
  // `gyration` and `energy` divide the drawn spin by each radius of gyration (`energy` the
  // incoming one by their mean): every moment must be recorded and not vanish against L^2 (a
  // needle 1e4 times longer than thick is still above).
  if (sig.spin != ResponseSpin::length)
    for (const Scalar k : sig.unit_inertia)
      if (!(k > Scalar(1e-8) * sig.length * sig.length)) return Status::invalid_shape;
  const HeightTableView& h = sig.height;
  if (bad_axis(h.spin_ratio)) return Status::invalid_shape;
  for (std::uint32_t i = 0; i < h.spin_ratio.size; ++i)
    if (bad(h.mean[i]) || !(h.mean[i] > 0) || bad(h.stddev[i])) return Status::invalid_shape;
  const ResponseTableView& r = sig.response;
  std::uint32_t cells = 1;
  for (std::uint32_t a = 0; a < r.axis_count; ++a) {
    if (bad_axis(r.axes[a])) return Status::invalid_shape;
    cells *= r.axes[a].size;
  }
  if (bad(r.mean.scale) || bad(r.mean.offset) || bad(r.spread.scale) || bad(r.spread.offset))
    return Status::invalid_shape;
  for (std::uint32_t i = 0; i < cells * r.components; ++i)
    if (bad(r.mean[i])) return Status::invalid_shape;
  for (std::uint32_t i = 0; i < cells * r.spread_per_cell; ++i)
    if (bad(r.spread[i])) return Status::invalid_shape;
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    const typename Space<D>::Vec n = sig.rest.normal(i);
    if (!finite(n) || !(std::fabs(n.squaredNorm() - 1) < Scalar(2e-3))) return Status::invalid_shape;
    if (bad(sig.rest.heights[i]) || !(sig.rest.heights[i] > 0)) return Status::invalid_shape;
    const Scalar f = sig.rest.frequencies[i];
    if (!(f >= 0 && f <= 1)) return Status::invalid_shape;  // NaN fails too
  }
  // Landing data: probabilities in [-1, 1]; the spin ratio and Froude axes not negative.
  const LandingView& l = sig.landing;
  if (l.present()) {
    for (const AxisView& a : l.axes)
      if (bad_axis(a)) return Status::invalid_shape;
    if (!(l.axes[1].values[0] >= 0) || !(l.axes[2].values[0] >= 0)) return Status::invalid_shape;
    if (!(l.hop >= 0) || bad(l.hop)) return Status::invalid_shape;
    for (std::uint32_t i = 0; i < l.probability.size; ++i)
      if (!(l.probability[i] >= -1 && l.probability[i] <= 1)) return Status::invalid_shape;  // NaN fails too
  }
  // Settling data: times in [0, max_settle_time] s, non-decreasing within each pose (quantiles).
  const SettleView& t = sig.settle;
  if (t.present()) {
    for (std::uint32_t i = 0; i < t.time.size; ++i) {
      if (!(t.time.values[i] >= 0 && t.time.values[i] <= max_settle_time)) return Status::invalid_shape;  // NaN too
      if (i % t.quantiles != 0 && !(t.time.values[i] >= t.time.values[i - 1])) return Status::invalid_shape;
    }
  }
  // Body-body data: support values are distances of the hull's farthest point along a direction
  // with a cube-face coordinate up to sqrt(3) (2D: sqrt(2)) long, so within that many bounding
  // radii of the centre; face normals unit; packing ratios in (0, 2].
  const ContactView<D>& c = sig.contact;
  if (!c.present()) return Status::ok;
  if (bad(c.support.scale) || bad(c.support.offset) || !(c.offset_scale > 0) || bad(c.offset_scale))
    return Status::invalid_shape;
  const Scalar reach = 2 * sig.bounding_radius;
  for (std::uint32_t i = 0; i < c.support_count(); ++i)
    if (bad(c.support[i]) || !(std::fabs(c.support[i]) <= reach)) return Status::invalid_shape;
  if (c.pair_mean != nullptr)
    for (std::uint32_t i = 0; i < h.spin_ratio.size; ++i)
      if (!(c.pair_mean[i] > 0 && c.pair_mean[i] <= reach) || bad(c.pair_stddev[i]) || c.pair_stddev[i] < 0)
        return Status::invalid_shape;
  for (std::uint32_t k = 0; k < c.face_count; ++k) {
    const Scalar* f = c.faces.values + k * face_values(D);
    Scalar n2 = 0;
    for (int d = 0; d < D; ++d) n2 += f[d] * f[d];
    if (!(std::fabs(n2 - 1) < Scalar(2e-3)) || !(std::fabs(c.face_offset(k)) <= sig.bounding_radius))
      return Status::invalid_shape;
    if (!(f[D + 1] > 0 && f[D + 1] <= 2)) return Status::invalid_shape;
  }
  for (std::size_t k = 0; k < 3; ++k)
    if (!(c.packing_mean[k] > 0 && c.packing_mean[k] <= 2) || !(c.packing_stddev[k] >= 0 && c.packing_stddev[k] <= 2))
      return Status::invalid_shape;
  return Status::ok;
}

/// A whole signature: its scalars, its layout, then its values.
template <int D>
Status check_signature(const SignatureView<D>& sig)
{
  if (!finite(sig.length) || !finite(sig.bounding_radius)) return Status::non_finite;
  if (!(sig.length > 0) || !(sig.bounding_radius > 0)) return Status::invalid_radius;
  if (sig.material.restitution < 0 || sig.material.restitution > 1 || sig.material.friction < 0)
    return Status::invalid_material;
  const Status layout = check_signature_layout(sig);
  if (layout != Status::ok) return layout;
  return check_signature_values(sig);
}

}  // namespace detail
}  // namespace statsim
