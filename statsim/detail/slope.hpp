#pragma once
/// @file
/// Which contacts with planes a body meets at its hull rather than its collision sphere: a
/// tilted plane (`is_tilted_plane`) for a statistical body with a support map (`slope_hull`),
/// level ground after the first impact and in slow landings (`ground_hull`, `slow_landing`), and
/// a settling body that other bodies hold (`hull_radius`). What happens at those contacts is
/// slope_contact.hpp's.

#include "statsim/detail/hull.hpp"
#include "statsim/detail/narrow_phase.hpp"
#include "statsim/detail/world_data.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace statsim {
namespace detail {

/// True when the plane of unit normal `n` is tilted: it carries weight (n.g < 0) and gravity
/// `g` pulls along it (a part that is not exactly zero). Writes g.n to `gn`.
template <class Vec>
bool is_tilted_plane(const Vec& g, const Vec& n, Scalar& gn)
{
  gn = g.dot(n);
  return gn < 0 && (g - n * gn).squaredNorm() > 0;
}

/// True when some plane is tilted (`WorldData::tilted_planes`, set as planes are added).
template <int D>
bool any_tilted_plane(const WorldData<D>& w)
{
  Scalar gn;
  for (std::uint32_t p = 0; p < w.plane_count; ++p)
    if (is_tilted_plane(w.def.gravity, w.planes[p].normal, gn)) return true;
  return false;
}

/// True when the bodies of shape `s` can meet a plane with their hull: statistical, with a
/// support map and principal moments.
template <int D>
bool hull_shape(const Shape<D>& s)
{
  if (!s.statistical || !s.signature.contact.present()) return false;
  for (int k = 0; k < (D == 3 ? 3 : 1); ++k)
    if (!(s.signature.unit_inertia[std::size_t(k)] > 0)) return false;
  return true;
}

/// True when body `b` meets the plane of unit normal `n` with its hull, as a rigid body would
/// (statsim/detail/slope_contact.hpp): the plane is tilted (`is_tilted_plane`) and the body statistical,
/// with a support map and principal moments (`hull_shape`).
template <class FS = AllFeatures, int D>
bool slope_hull(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n)
{
  if constexpr (!FS::slopes || !FS::statistical) {
    return false;
  }
  if (!w.tilted_planes) return false;
  if (!hull_shape(w.shapes[b.shape])) return false;
  Scalar gn;
  return is_tilted_plane(w.def.gravity, n, gn);
}

/// True when body `b` can meet the plane of unit normal `n` with its hull on level ground: with
/// `WorldDef::ground_hulls` and `rest_conditions`, the body statistical with a support map and
/// principal moments (`hull_shape`), the plane level ground (it carries weight, and gravity has no
/// part along it). When it does: `ground_hull`, `ground_impact_on_hull`.
template <class FS = AllFeatures, int D>
bool hull_meets_ground(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n)
{
  if constexpr (!FS::slopes || !FS::statistical) {
    return false;
  }
  if (!w.def.ground_hulls || !w.def.rest_conditions || !hull_shape(w.shapes[b.shape])) return false;
  Scalar gn;
  return !is_tilted_plane(w.def.gravity, n, gn) && gn < 0;
}

/// True when body `b` meets the plane of unit normal `n` with its hull because it is level ground
/// (it carries weight, and gravity has no part along it) and the body is marked in
/// `WorldData::hull_ground` for the step (on the ground as the step began, or landing slowly:
/// `slow_landing`), the body statistical with a support map and principal moments.
/// The statistical response stands for a collision as a whole: the tables give what a rigid body
/// leaves the ground with after it, however many times its corners strike within it. A body
/// already on the ground, though, tumbles over its edges and hops on its corners, each strike set
/// by the one before; drawing a fresh collision at each contact would make a sphere bounce where
/// the rigid body rocks, and a sphere that rolls cannot hop. So the first impact from flight is
/// the table's, taken where the hull touches (`ground_impact_on_hull`), and the contacts after it
/// are the hull's, as on a slope, until a rest pose is chosen (`rolls_on`) or the body flies off
/// (`leaves_ground`). Only with `WorldDef::ground_hulls` and `rest_conditions` (without them
/// bodies stay the paper's spheres), in worlds with `Features::slopes`.
template <class FS = AllFeatures, int D>
bool ground_hull(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n)
{
  return hull_meets_ground<FS>(w, b, n) && bit_set(w.hull_ground, std::uint32_t(&b - w.bodies));
}

/// The Froude number |v|^2 / (|g| L) below which a landing on level ground is a hop's
/// (`slow_landing`): the centre fell from about L / 2 or less. A constant of the runtime, not the
/// first Froude sample of a table's landing axis: with `--landing-froude 0,0.1,...` the box's hops
/// landing between F = 0.1 and 1 drew fresh collisions, each another bounce (tools/fidelity/LOG.md,
/// "The hops' landing at a fixed Froude number").
constexpr Scalar hop_froude = 1;

/// True when body `b`, statistical with landing data (`LandingView`), falls (its velocity has a
/// part along gravity) slower than a hop's landing: |v|^2 < F_h |g| L, F_h = `hop_froude`, L the
/// signature's length. A hop of a tumbling body ends in such a landing. The landing data and the
/// response tables hold impacts of a body from flight at any orientation; a landing that slow is
/// the tumble going on, the body coming down on the part of its hull it turned over: with
/// `WorldDef::ground_hulls` the body meets level ground with its hull (`ground_hull`), as one
/// that was on it, and a hop's landing draws no fresh collision. Without landing data (tables
/// before format 2.2, and 2D tables) it is false: bodies from flight keep the statistical
/// response, as before.
template <int D>
bool slow_landing(const WorldData<D>& w, const Body<D>& b)
{
  const Shape<D>& s = w.shapes[b.shape];
  if (!s.statistical || !s.signature.landing.present() || !(b.linear_velocity.dot(w.def.gravity) > 0)) return false;
  // |v|^2 < F_h |g| L, squared: no root of |g|^2.
  const Scalar v2 = b.linear_velocity.squaredNorm(), limit = hop_froude * s.signature.length;
  return v2 * v2 < limit * limit * w.def.gravity.squaredNorm();
}

/// True when body `b`, statistical with landing data (`LandingView`), leaves the ground as a
/// flight: its velocity against gravity v_up has v_up^2 > 2 |g| h L, its centre rising by more
/// than the table's `hop` L (h) before it falls. A statistical response that sends a body off
/// stands for the whole collision, every strike of its corners in it (the tables give what a
/// rigid body leaves the ground with); were it still on its hull (`ground_hull`) in the next
/// step, the corners its drawn spin turns down would strike again and take the flight out. So
/// it flies, and lands on its hull (`ground_impact_on_hull`) with the table's response again or,
/// as slowly as a hop's landing (`slow_landing`), on its hull. Without landing data it is false.
template <int D>
bool leaves_ground(const WorldData<D>& w, const Body<D>& b)
{
  const Shape<D>& s = w.shapes[b.shape];
  if (!s.statistical || !s.signature.landing.present()) return false;
  const Scalar up = -b.linear_velocity.dot(w.def.gravity);  // v_up |g|
  // v_up^2 > 2 |g| h L, times |g|^2: no root of |g|^2.
  return up > 0 && up * up > 2 * s.signature.landing.hop * s.signature.length * w.def.gravity.squaredNorm() *
                                 std::sqrt(w.def.gravity.squaredNorm());
}

/// True when some body may meet a plane with its hull (`rolls_on`): the world has a tilted plane
/// or `WorldDef::ground_hulls`. The step tests it before `rolls_on` in its loops over bodies and
/// planes, which then cost nothing in worlds that have neither.
template <class FS = AllFeatures, int D>
bool hull_planes(const WorldData<D>& w)
{
  return FS::slopes && (w.tilted_planes || w.def.ground_hulls);
}

/// True when body `b` (one of `w`'s bodies, not a copy) meets a plane of unit normal `n` (towards
/// the body) with its hull (`slope_hull`, `ground_hull`) and has no rest pose chosen: its
/// contacts there are `slope_hull_response`'s.
template <class FS = AllFeatures, int D>
bool rolls_on(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n)
{
  return b.rest_pose == no_rest_pose && (slope_hull<FS>(w, b, n) || ground_hull<FS>(w, b, n));
}

/// The radius a body (one of `w`'s bodies, not a copy) keeps from a plane of normal `n`: its
/// collision radius; or its hull's support toward the plane on a slope (`slope_hull`) or on level
/// ground it was on as the step began (`ground_hull`: with a rest pose too, so that the body that
/// takes one turns into it on its hull, as it stood, instead of jumping to its collision radius);
/// or, for a settling body with a hull
/// (`BodyContacts::hulls`), at least its hull's support toward the plane, so that a body resting
/// out of its rest poses (propped by others) does not sink its hull into the ground or a wall.
template <class FS = AllFeatures, int D>
Scalar hull_radius(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n)
{
  if constexpr (!FS::statistical || (!FS::slopes && !FS::hull_contacts)) {
    return b.radius;
  }
  const Shape<D>& s = w.shapes[b.shape];
  if (slope_hull<FS>(w, b, n) || ground_hull<FS>(w, b, n))
    return support_along(s.signature.contact, to_body(b.orientation, typename Space<D>::Vec(-n)));
  if (!(FS::hull_contacts && hull_contacts_on(w)) || b.state != MotionState::settling || !s.statistical ||
      !s.signature.contact.present())
    return b.radius;
  const Scalar hull = support_along(s.signature.contact, to_body(b.orientation, typename Space<D>::Vec(-n)));
  return hull > b.radius ? hull : b.radius;
}

/// The radius at which a plane holds body `b` (one of `w`'s bodies): `hull_radius`, but on level
/// ground with no other body near (`WorldData::paired`) no more than its collision radius plus
/// the height its kinetic energy could lift its centre, e / g_n (e per unit mass, of its spin and
/// of its velocity along the plane; g_n gravity's part along the normal).
///
/// Why: a statistical body's orientation as it starts to settle is not the one its collision
/// radius was measured at, and its hull's support there may stand centimetres above that radius.
/// Held at the support it was lifted there in one step with no velocity, a hop that a rigid body,
/// whose centre rises over an edge only as far as its energy takes it, does not make
/// (tools/fidelity/README.md, "The hull's hold"). Near other bodies and against walls the hold is
/// whole: a body propped by others must not sink into the ground or a wall. `hull_radius` itself,
/// which tells whether others prop a body out of its pose, is unchanged.
template <class FS = AllFeatures, int D>
Scalar held_radius(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n)
{
  const Scalar hull = hull_radius<FS>(w, b, n);
  if constexpr (!FS::statistical || !FS::hull_contacts) {
    return hull;
  }
  if (!(hull > b.radius) || !(n[Space<D>::up_axis] >= w.def.ground_cosine) ||
      bit_set(w.paired, std::uint32_t(&b - w.bodies)) || slope_hull<FS>(w, b, n) || ground_hull<FS>(w, b, n))
    return hull;
  const Scalar gn = -w.def.gravity.dot(n);
  if (!(gn > 0)) return hull;
  // The approach into the plane, a resting body's g dt among it, lifts nothing.
  const typename Space<D>::Vec along = b.linear_velocity - n * b.linear_velocity.dot(n);
  const Scalar reach =
      b.radius + kinetic_energy_per_mass<D>(w.shapes[b.shape].signature, b.orientation, along, b.angular_velocity) / gn;
  return hull < reach ? hull : reach;
}

/// True when body `b` (one of `w`'s bodies) meets level ground of unit normal `n` at its hull's
/// support also from flight, not only once on its hull there (`ground_hull`): a body that
/// `hull_meets_ground` and has no rest pose. Its first impact is still the table's response, but taken
/// where its hull touches, as the rigid body's is. Met at its collision radius instead, it stood
/// where its hull was in the ground or above it, and the hull's contact that follows the impact
/// lifted the centre to the support in a step, or let it fall there: a rise of centimetres on a
/// long body (tools/fidelity/LOG.md, "Ground hulls: the first impact at the hull").
template <class FS = AllFeatures, int D>
bool ground_impact_on_hull(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& n)
{
  return b.rest_pose == no_rest_pose && hull_meets_ground<FS>(w, b, n);
}

/// `held_radius` against a plane, where it matters: the support is read only when the plane is
/// within the body's bounding radius. With `WorldDef::ground_hulls`, a body that flies onto
/// level ground meets it at its hull's support too (`ground_impact_on_hull`).
template <class FS = AllFeatures, int D>
Scalar plane_radius(const WorldData<D>& w, const Body<D>& b, const Plane<D>& plane)
{
  // `hull_radius`'s first tests, before the plane's distance: every body meets every plane in
  // every pass, and most need neither.
  const std::uint32_t i = std::uint32_t(&b - w.bodies);
  const bool slopes = FS::slopes && w.tilted_planes;
  const bool ground_hulls = FS::slopes && w.def.ground_hulls;
  const bool ground = ground_hulls && bit_set(w.hull_ground, i);
  const bool hulls = FS::hull_contacts && hull_contacts_on(w) && b.state == MotionState::settling;
  if (!slopes && !ground_hulls && !hulls) return b.radius;
  if (!(plane.normal.dot(b.position) - plane.offset < w.shapes[b.shape].bounding_radius)) return b.radius;
  if (ground_hulls && ground_impact_on_hull<FS>(w, b, plane.normal))
    return support_along(w.shapes[b.shape].signature.contact, to_body(b.orientation, typename Space<D>::Vec(-plane.normal)));
  if (!slopes && !ground && !hulls) return b.radius;
  return held_radius<FS>(w, b, plane.normal);
}

}  // namespace detail
}  // namespace statsim
