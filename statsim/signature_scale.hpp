#pragma once
/// @file
/// One table at any size: the view of a signature for a shape `s` times the size the table was
/// gathered at (tools/ref3d/README.md, "One table at any size").
///
/// With constant restitution and Coulomb friction, an impact of a rigid body is scale-free once
/// lengths are divided by L and velocities by |V-|: the impulse equations hold the mass only as a
/// common factor and the inertia only as I / (m L^2). So a body s times larger has, for the same
/// dimensionless inputs (cos theta, cos phi, spin ratio |W-| L / |V-|), the same normalised
/// responses (W+ L / |V-|, dv / |V-|), and every length of the table times s:
///   - s^1: L, the bounding radius, h_coll mean and spread, rest heights, the support map, the
///     hull faces' offsets, the pair distance and its spread, the mesh frame (`scale`);
///   - s^3: the mass (same density); s^2: the unit inertia I / m (so I goes as s^5);
///   - s^0: the response tables and their axes (cos theta, cos phi, spin ratio and, in the
///     `with_speed` layout, the speed axis in m/s, which stays in m/s: the speed dependence a table
///     holds comes from the absolute thresholds below, not from the size), the h_coll axis (spin
///     ratios), rest normals and frequencies, packing ratios, the material;
///   - not scaled, and not scale-free: the restitution threshold (m/s), gravity against |V-| in
///     the rest-pose drops, the reference's contact margin, its time step against the size, and
///     rolling resistance (a deceleration of about rr g whatever the size). Where these matter is
///     measured in tools/ref3d/README.md.

#include "statsim/signature.hpp"

namespace statsim {

/// Smallest and largest size factor `scaled_view` and `add_shape(sig, scale)` take. Beyond
/// these a body's lengths leave what the world checks anyway (`limits::min_radius`,
/// `limits::max_radius`, the mass limits), and the tables' validity was measured over a much
/// narrower range (1 cm to 10 m bodies; see tools/ref3d/README.md).
constexpr Scalar min_shape_scale = Scalar(1e-3);
constexpr Scalar max_shape_scale = Scalar(1e3);

namespace detail {
/// The values of `v` times `s`: the float view's scale (1 for a table's own view), or an i16
/// view's scale and offset.
inline ValuesView scaled_values(const ValuesView& v, Scalar s)
{
  ValuesView r = v;
  r.scale = v.scale * s;
  if (v.f32 == nullptr) r.offset = v.offset * s;
  return r;
}
}  // namespace detail

/// The view of `sig` for a shape `s` times its size (see the file comment for what scales and
/// how): lengths times s, mass times s^3, unit inertia times s^2, everything else as it is. The
/// tables are not copied: the view points into the same ones as `sig` and applies s as it reads
/// them. `s` is in [`min_shape_scale`, `max_shape_scale`] (the caller checks; `add_shape(sig,
/// scale)` does). With s = 1 the view reads every number of `sig` bit for bit.
template <int D>
SignatureView<D> scaled_view(const SignatureView<D>& sig, Scalar s)
{
  SignatureView<D> v = sig;
  v.scale = sig.scale * s;
  v.length = sig.length * s;
  v.bounding_radius = sig.bounding_radius * s;
  v.mass = sig.mass * (s * s * s);
  for (Scalar& k : v.unit_inertia) k = k * (s * s);
  v.height.mean = detail::scaled_values(sig.height.mean, s);
  v.height.stddev = detail::scaled_values(sig.height.stddev, s);
  v.rest.heights = detail::scaled_values(sig.rest.heights, s);
  if (sig.contact.present()) {
    v.contact.support = detail::scaled_values(sig.contact.support, s);
    if (sig.contact.pair_mean != nullptr) {
      v.contact.pair_mean = detail::scaled_values(sig.contact.pair_mean, s);
      v.contact.pair_stddev = detail::scaled_values(sig.contact.pair_stddev, s);
    }
    v.contact.offset_scale = sig.contact.offset_scale * s;
  }
  return v;
}

}  // namespace statsim
