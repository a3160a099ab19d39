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
/// own. With `WorldDef::ground_hulls` the same contact follows a body's first impact on level
/// ground (`ground_hull`): the statistical response gives what it leaves the ground with, and its
/// hull the tumbles and hops after it, until it takes a rest pose, in the same substeps: taken at
/// the step's length, the corner strikes of a tumble take out what a rigid body at that step loses,
/// and it stops on other faces than the reference's (tools/fidelity/LOG.md measures both). Walls
/// are not affected.

#include "statsim/detail/events.hpp"
#include "statsim/detail/hull.hpp"
#include "statsim/detail/slope.hpp"
#include "statsim/detail/tipping.hpp"
#include "statsim/detail/world_data.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace statsim {
namespace detail {

/// Gauss-Seidel passes over the corners of a slope contact (at most three in 2D, five in 3D).
constexpr int slope_contact_iterations = 6;

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
/// by central differences over a hundredth of a cell (within the cell the interpolation is
/// linear, so this is the point of the interpolated hull that meets the plane). Where `d` is
/// normal to a face or an edge of that hull the gradient jumps; the central difference takes the
/// mean of the two sides, so a face gives its centre and an edge its midpoint, symmetric about
/// the body, where a one-sided difference would pick one corner and the contact's friction would
/// turn a sliding body about the normal.
template <int D>
typename Space<D>::Vec support_point(const ContactView<D>& c, const typename Space<D>::Vec& d)
{
  using Vec = typename Space<D>::Vec;
  const Scalar eps = Scalar(0.02) / Scalar(c.support_size - 1) * d.norm();
  Vec q;
  for (int j = 0; j < D; ++j)
    q[j] = (support_along(c, Vec(d + Vec::Unit(j) * eps)) - support_along(c, Vec(d - Vec::Unit(j) * eps))) / (2 * eps);
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

/// The approach speed below which a contact of body `b` along unit normal `n` (towards it) is
/// resting, not a collision, in a step of `dt` seconds, m/s.
template <int D>
Scalar restitution_threshold(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n, Scalar dt)
{
  // A resting contact gets the inelastic particle response: the tables describe collisions, and
  // sampling a fresh spin at every resting step would keep a body from ever settling. A body
  // that is not settling bounces as the reference did when the table was gathered, down to the
  // table's threshold; a settling one approaches at |g| dt each step while it rests, so it keeps
  // the world's. The table's threshold is never taken below 2 |g.n| dt either: a body sliding or
  // rolling on a plane meets it at |g.n| dt every step, and a sampled response there would
  // replace the slide's friction and drain a roll's spin at every step.
  const Shape<D>& shape = w.shapes[b.shape];
  const WorldDef<D>& def = w.def;
  const bool table_threshold = shape.statistical && def.table_restitution_threshold && b.state != MotionState::settling;
  Scalar threshold = table_threshold ? shape.signature.restitution_threshold : def.restitution_threshold;
  if (table_threshold) {
    const Scalar gravity_step = 2 * std::fabs(def.gravity.dot(n)) * dt;
    if (threshold < gravity_step) threshold = gravity_step;
  }
  return threshold;
}

/// Longest time step of a slope contact, s: the step of the reference runs the tables are
/// gathered from. A hull contact is a rigid body's contact, and like the reference's it follows a
/// roll only at such steps: a corner that strikes within a long step strikes at the wrong time
/// and place, and the body loses to the impulses what it would have kept (tools/stress/README.md,
/// "Substeps on slopes", gives the distances rolled against the step).
constexpr Scalar slope_contact_step = Scalar(0.001);

/// Moves awake body `i` through a step of `dt` seconds in substeps of at most
/// `slope_contact_step` when it touched something in the last step and `rolls_on` a plane (a
/// slope, or level ground it was on, `ground_hull`) that it is within `slope_reach` of: gravity,
/// damping, the contacts with every such slope (`slope_hull_response`, the body kept out of the plane) and the move, in each
/// substep. Its impacts with those slopes faster than `WorldDef::impact_threshold` go to `log`
/// (each substep's, with the approach speed of the centre, as `record_impacts` measures it).
/// Marks the body in `WorldData::rolled`: the step's contact passes leave its slope contacts
/// alone. Returns false, changing nothing, for any other body.
template <class FS, int D, class IdOf>
bool roll_on_slopes(WorldData<D>& w, std::uint32_t i, Scalar dt, ImpactLog<D>& log, IdOf&& id_of)
{
  using Vec = typename Space<D>::Vec;
  Body<D>& b = w.bodies[i];
  const Shape<D>& shape = w.shapes[b.shape];
  const WorldDef<D>& def = w.def;
  const Scalar reach = shape.bounding_radius * slope_reach;
  // A body arriving at a slope meets it in the step's impact pass; one that touched last step and
  // is still within reach rolls on it.
  bool near = false;
  for (std::uint32_t p = 0; p < w.plane_count && b.touching && !near; ++p) {
    const Plane<D>& plane = w.planes[p];
    if (!rolls_on<FS>(w, b, plane.normal)) continue;
    // The hull's support never exceeds the bounding radius: read it only when that can reach.
    const Scalar distance = plane.normal.dot(b.position) - plane.offset;
    near = distance - shape.bounding_radius < reach && distance - hull_radius<FS>(w, b, plane.normal) < reach;
  }
  if (!near) return false;
  const int steps = int(std::ceil(dt / slope_contact_step));  // dt <= limits::time_step
  const Scalar h = dt / Scalar(steps);
  const Scalar lin_damp = Scalar(1) / (1 + h * def.linear_damping);
  const Scalar ang_damp = Scalar(1) / (1 + h * def.angular_damping);
  for (int k = 0; k < steps; ++k) {
    b.linear_velocity = (b.linear_velocity + def.gravity * h) * lin_damp;
    b.angular_velocity = b.angular_velocity * ang_damp;
    for (std::uint32_t p = 0; p < w.plane_count; ++p) {
      const Plane<D>& plane = w.planes[p];
      if (!rolls_on<FS>(w, b, plane.normal)) continue;
      Scalar gap = plane.normal.dot(b.position) - plane.offset - hull_radius<FS>(w, b, plane.normal);
      if (gap < 0) {
        b.position -= plane.normal * gap;
        gap = 0;
      }
      if (!(gap < reach)) continue;
      const Scalar approach = -b.linear_velocity.dot(plane.normal);
      const Scalar threshold = restitution_threshold(w, b, plane.normal, h);
      if (!slope_hull_response(shape, b, plane.normal, def.gravity, gap, h, threshold)) continue;
      if (log.capacity > 0 && approach > def.impact_threshold) {
        const Vec foot = b.position - plane.normal * (plane.normal.dot(b.position) - plane.offset);
        log.add(Impact<D>{id_of(i), no_body, PlaneId(p), foot, plane.normal, approach});
      }
    }
    b.position += b.linear_velocity * h;
    b.orientation = integrate(b.orientation, b.angular_velocity, h);
  }
  set_bit(w.rolled, i);
  return true;
}

/// On a ground plane of unit normal `n` that gravity pulls bodies along (`downhill`, and
/// `slope` = |g_t| / |g.n| = tan of the tilt a): whether rest pose `pose` of a body of shape
/// `shape`, turned from `orientation` into the pose against the plane, fails to hold it. A rigid
/// body stands on its support set, the face under it; the line of gravity through its centre
/// meets the plane h tan(a) downhill of the point under the centre (h the support toward the
/// plane), and the body tips over the face's downhill edge once that point is beyond the edge:
/// e < h tan(a), e the face's extent downhill (`support_extent`). The tilt at which a pose stops
/// holding, atan(e / h), thus depends on the direction the slope falls in the body's frame, and
/// is read from the support map: no table holds it. The shape must have a support map.
template <int D>
bool pose_tips(const Shape<D>& shape, const typename Space<D>::Rot& orientation, std::uint32_t pose,
               const typename Space<D>::Vec& n, const typename Space<D>::Vec& downhill, Scalar slope)
{
  using Vec = typename Space<D>::Vec;
  const SignatureView<D>& sig = shape.signature;
  const typename Space<D>::Rot at_rest = snap_to_rest(orientation, sig.rest.normal(pose), n);
  const Vec down = to_body(at_rest, Vec(-n));
  const Scalar h = support_along(sig.contact, down);
  return h * slope > support_extent(shape, down, to_body(at_rest, downhill), h);
}

/// What `settle_on_slope` decided for a body settling on a tilted ground plane.
enum class SlopeSettle {
  pose,     ///< it settles as on level ground, in its pose or the nearest that holds it
  tipping,  ///< it tips on: no pose, no sleep in this step
  held,     ///< no pose holds it, but what it stands on does: no pose, it may sleep where it is
};

/// A statistical body settling on a tilted ground plane of unit normal `n`: a pose that does not
/// hold it there (`pose_tips`) is no rest pose. Its pose (the chosen one, else the nearest) is
/// kept where it holds. Else, where the line of gravity passes downhill of the support set the
/// body stands on now, it tips over that set's downhill edge (`tip_over`) toward the next pose
/// downhill and takes none; where that set holds it, it settles into the nearest pose that
/// holds on this plane, or, with none, stays where it is (it may sleep there, as a body propped
/// out of its poses). Level ground (no pull along it) never gets here: its bits are unchanged.
template <class FS, int D>
SlopeSettle settle_on_slope(const WorldData<D>& w, Body<D>& b, const typename Space<D>::Vec& n)
{
  using Vec = typename Space<D>::Vec;
  const Shape<D>& shape = w.shapes[b.shape];
  const SignatureView<D>& sig = shape.signature;
  const WorldDef<D>& def = w.def;
  if constexpr (!FS::slopes || !FS::statistical) {
    return SlopeSettle::pose;
  }
  if (!shape.statistical || !def.rest_conditions || sig.rest.count == 0 || !sig.contact.present())
    return SlopeSettle::pose;
  const Scalar gn = def.gravity.dot(n);
  const Vec gt = def.gravity - n * gn;
  const Scalar pull = gt.norm();
  if (!(gn < 0) || !(pull > 0)) return SlopeSettle::pose;
  const Vec downhill = gt / pull;
  const Scalar slope = pull / -gn;
  const Scalar* bias = shape.rest_bias.data();
  const std::uint32_t pose =
      b.rest_pose != no_rest_pose ? b.rest_pose : nearest_rest_pose<D>(sig, b.orientation, n, bias);
  if (pose >= sig.rest.count || !pose_tips(shape, b.orientation, pose, n, downhill, slope)) return SlopeSettle::pose;
  // The support set it stands on now: the line of gravity meets the plane h tan(a) downhill of
  // the point under the centre; beyond the set's downhill extent e the body turns about the
  // set's edge, e downhill of that point.
  const Vec down = to_body(b.orientation, Vec(-n));
  const Scalar h = support_along(sig.contact, down);
  const Scalar e = support_extent(shape, down, to_body(b.orientation, downhill), h);
  // A tip slower than the sleep speed (the body near balance over the edge: on a curved part of
  // its hull it rolls until the line of gravity meets the point it stands on) counts as held.
  const Scalar g = def.gravity.norm();
  if (h * slope > e) {
    const Scalar spin = tip_over(shape, b, Vec(b.position - n * h + downhill * e), Vec(def.gravity / g), g,
                                 def.settle_speed);
    if (spin * shape.bounding_radius >= def.sleep_speed) {
      b.rest_pose = no_rest_pose;
      b.rest_blend = 0;
      return SlopeSettle::tipping;
    }
  }
  // Held where it stands: the nearest pose among those that hold (the score of
  // `nearest_rest_pose`); a new pose starts its radius blend afresh.
  std::uint32_t best = no_rest_pose;
  Scalar best_score = -std::numeric_limits<Scalar>::infinity();
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    const Scalar score = (b.orientation * sig.rest.normal(i)).dot(n) + bias[i];
    if (score > best_score && !pose_tips(shape, b.orientation, i, n, downhill, slope)) {
      best_score = score;
      best = i;
    }
  }
  if (best != b.rest_pose) b.rest_blend = 0;
  b.rest_pose = std::uint8_t(best);
  return best == no_rest_pose ? SlopeSettle::held : SlopeSettle::pose;
}

}  // namespace detail
}  // namespace statsim
