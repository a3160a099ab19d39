#pragma once
/// @file
/// Contacts of statistical bodies with tilted planes, taken on the body's hull.
///
/// A statistical body is a sphere whose contact point has no lever arm: at a resting contact
/// friction stops its slide and nothing turns its spin into a roll. On level ground that is
/// what the rest poses need; on a tilted plane a rigid body that lands with speed tumbles and
/// rolls downhill on its hull, losing energy each time a new face or edge strikes the plane,
/// and stops only on a face that holds it against the tilt. So on a tilted plane a statistical
/// body with a support map and no rest pose meets the plane as its hull does: its centre stands
/// at the hull's support toward the plane (`hull_radius`), and the contact acts at a few points
/// of the hull read from the table's support map (`support_point`), with normal impulses
/// (restitution above the threshold), Coulomb friction and the body's principal moments
/// (`slope_hull_response`). Static friction at the corner it pivots on turns the downhill pull
/// into a roll; the impulse that stops the next corner as it strikes takes what a rigid body
/// loses there; a face whose extent downhill holds the line of gravity holds the body still.
/// No table holds anything for this: the support map and the principal moments are the table's
/// own. Level ground and walls are not affected.

#include "statsim/hull_contact.hpp"
#include "statsim/tipping.hpp"
#include "statsim/world_data.hpp"

#include <array>
#include <cmath>
#include <cstdint>

namespace statsim {
namespace detail {

/// Gauss-Seidel passes over the corners of a slope contact (at most three in 2D, five in 3D).
constexpr int slope_contact_iterations = 6;

/// True when body `b` meets a plane of unit normal `n` (towards the body) with its hull
/// (`slope_hull`) and has no rest pose chosen: its contacts there are `slope_hull_response`'s.
template <int D>
bool rolls_on(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n)
{
  return b.rest_pose == no_rest_pose && slope_hull(w, b, n);
}

/// How far a turned corner of a slope contact may stand above the support the body will have at
/// the end of the step and still take part (`slope_hull_response`), over that support.
constexpr Scalar slope_corner_tolerance = Scalar(0.01);

/// How far from a slope a body that `rolls_on` it is in contact, over its bounding radius: the
/// gap is closed speculatively (`slope_hull_response`).
constexpr Scalar slope_reach = Scalar(0.05);

/// Inverse inertia per unit mass applied to a moment `m` (world frame): R diag(1 / k^2) R^T m.
inline Vector3 unit_inverse_inertia(const Shape<3>& s, const Quaternion& q, const Vector3& m)
{
  const Vector3 mb = to_body(q, m);
  const std::array<Scalar, 3>& k2 = s.signature.unit_inertia;
  return to_world(q, Vector3(mb.x() / k2[0], mb.y() / k2[1], mb.z() / k2[2]));
}
inline Scalar unit_inverse_inertia(const Shape<2>& s, const Rot2&, Scalar m) { return m / s.signature.unit_inertia[0]; }

/// The body's velocity change per unit of impulse over mass along unit `t` at `r` from the
/// centre, and its inverse: 1 + t.((I^-1 (r x t)) x r), I per unit mass.
template <int D>
Scalar unit_effective_mass(const Shape<D>& s, const typename Space<D>::Rot& q, const typename Space<D>::Vec& r,
                           const typename Space<D>::Vec& t)
{
  const Scalar k = 1 + t.dot(cross(unit_inverse_inertia(s, q, moment(r, t)), r));
  return Scalar(1) / k;
}

/// The hull's support point, body frame, m, for the body direction `d` (any length): the
/// gradient of the support map's support function there, h being homogeneous of degree one,
/// by differences over a hundredth of a cell (within the cell the interpolation is linear, so
/// this is the point of the interpolated hull that meets the plane).
template <int D>
typename Space<D>::Vec support_point(const ContactView<D>& c, const typename Space<D>::Vec& d)
{
  using Vec = typename Space<D>::Vec;
  const Scalar eps = Scalar(0.02) / Scalar(c.support_size - 1) * d.norm();
  const Scalar h0 = support_along(c, d);
  Vec q;
  for (int j = 0; j < D; ++j) q[j] = (support_along(c, Vec(d + Vec::Unit(j) * eps)) - h0) / eps;
  return q;
}

/// The resting contact of a body that `rolls_on` a plane of unit normal `n`, its centre at its
/// hull's support above it (`plane_radius`) or `gap` (m, >= 0) more, under `gravity` (which
/// sets the downhill axis), in a step of `dt` seconds: inelastic normal impulses (restitution
/// above `restitution_threshold`) and Coulomb friction (the shape's material) at the corners of
/// the part of the hull that faces the plane, with the body's inertia from the table's
/// principal moments. The corners are the hull's support points (`support_point`) for the
/// direction toward the plane, and for that direction turned by one cell of the support map
/// either way about each tangent axis (downhill, and in 3D across): on a face, its far
/// vertices; on an edge or corner, that point and the ones the next turn would bring down, each
/// with its own height above the plane. Impulses accumulate per corner and stay pushing (normal)
/// and within the friction cone, so a corner that the body turns away from lets go. Returns false
/// when nothing approached.
template <int D>
bool slope_hull_response(const Shape<D>& s, Body<D>& b, const typename Space<D>::Vec& n,
                         const typename Space<D>::Vec& gravity, Scalar gap, Scalar dt, Scalar restitution_threshold)
{
  using Vec = typename Space<D>::Vec;
  constexpr int axes_count = D == 3 ? 2 : 1;
  constexpr int corners = D == 3 ? 5 : 3;
  const ContactView<D>& map = s.signature.contact;
  const Vec down = to_body(b.orientation, Vec(-n));
  const Scalar h = support_along(map, down);
  Vec axes[axes_count];
  contact_axes(n, Vec(gravity - n * gravity.dot(n)), Scalar(0), axes);
  const Scalar turn = Scalar(2) / Scalar(map.support_size - 1);
  // Where the body will have turned to by the end of the step, and its support toward the plane
  // there: a turned corner takes part only if it is (within `slope_corner_tolerance` of the
  // support) the lowest point by then, as a face's far vertex is now and an edge that is about to
  // strike will be; on a curved part of the hull the turned points only come down after a turn of
  // a cell, and taking them as contacts sooner would brake a roll.
  const typename Space<D>::Rot turned = integrate(b.orientation, b.angular_velocity, dt);
  const Vec next_down = to_body(turned, Vec(-n));
  const Scalar next_h = support_along(map, next_down);
  Vec r[corners];
  Scalar above[corners];
  bool active[corners];
  for (int k = 0; k < corners; ++k) {
    // The last corner is the lowest point itself.
    Vec d = down;
    if (k + 1 < corners) d += to_body(b.orientation, axes[k >> 1]) * (k & 1 ? turn : -turn);
    const Vec q = support_point(map, d);
    r[k] = to_world(b.orientation, q);
    // Height over the plane: the centre stands h + gap above it.
    above[k] = h + gap + r[k].dot(n);
    if (above[k] < 0) above[k] = 0;
    active[k] = k + 1 == corners || q.dot(next_down) >= next_h - slope_corner_tolerance * next_h;
  }
  // A corner above the plane may approach it at its height / dt, which closes the gap in the
  // step and no more (a speculative contact); one that reaches it within the step faster than
  // the threshold leaves it at e times its approach speed (the shape's restitution), as the
  // rigid body would.
  Scalar target[corners];
  bool approaching = false;
  for (int k = 0; k < corners; ++k) {
    const Scalar vn = (b.linear_velocity + cross(b.angular_velocity, r[k])).dot(n);
    const bool bounces = -vn > restitution_threshold && -vn * dt >= above[k];
    target[k] = bounces ? -vn * s.material.restitution : -above[k] / dt;
    approaching = approaching || (active[k] && vn < target[k]);
  }
  if (!approaching) return false;
  const Scalar mu = s.material.friction;
  Scalar pn[corners] = {};
  Vec pt[corners];
  for (int k = 0; k < corners; ++k) pt[k] = Vec::Zero();
  // Impulse over mass p at r: dv = p, dw = I^-1 (r x p).
  const auto apply = [&](const Vec& r_k, const Vec& p) {
    b.linear_velocity += p;
    b.angular_velocity += unit_inverse_inertia(s, b.orientation, moment(r_k, p));
  };
  for (int it = 0; it < slope_contact_iterations; ++it)
    for (int k = 0; k < corners; ++k) {
      if (!active[k]) continue;
      const Scalar vn = (b.linear_velocity + cross(b.angular_velocity, r[k])).dot(n) - target[k];
      Scalar next = pn[k] - vn * unit_effective_mass(s, b.orientation, r[k], n);
      next = next > 0 ? next : Scalar(0);
      apply(r[k], n * (next - pn[k]));
      pn[k] = next;
      // Friction: each tangent axis in turn, then the accumulated impulse back into the cone.
      Vec total = pt[k];
      for (int i = 0; i < axes_count; ++i) {
        const Scalar vt = (b.linear_velocity + cross(b.angular_velocity, r[k])).dot(axes[i]);
        total -= axes[i] * (vt * unit_effective_mass(s, b.orientation, r[k], axes[i]));
      }
      const Scalar limit = mu * pn[k], size = total.norm();
      if (size > limit) total *= size > 0 ? limit / size : Scalar(0);
      apply(r[k], Vec(total - pt[k]));
      pt[k] = total;
    }
  return true;
}

}  // namespace detail
}  // namespace statsim
