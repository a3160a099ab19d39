#pragma once
/// @file
/// Tipping with hull contacts: a statistical body takes no torque at its contacts, so one that
/// comes to rest on an edge or corner of another would balance there. From the two tables'
/// support maps the runtime finds the region where the bodies touch; a body whose line of
/// gravity passes outside it, and that nothing holds from the far side, is given the spin of a
/// body tipping over the region's nearest point. The shock pass marks from which sides each
/// body is held (`mark_supports`) and then tips the bodies that are held from one side only
/// (`tip_unsupported`).

#include "statsim/detail/hull.hpp"
#include "statsim/detail/narrow_phase.hpp"
#include "statsim/detail/slope.hpp"
#include "statsim/detail/world_data.hpp"

#include <array>
#include <cmath>
#include <cstdint>

namespace statsim {
namespace detail {

/// Tangent axes of a contact plane of unit normal `n`: in 3D the direction of the tangent `x`
/// (any perpendicular of n when |x| <= `tiny`: the smallest component of n crossed out) and
/// n x that; in 2D the plane's one direction.
inline void contact_axes(const Vector3& n, const Vector3& x, Scalar tiny, Vector3 (&axes)[2])
{
  const Scalar xn = x.norm();
  if (xn > tiny) {
    axes[0] = x / xn;
  } else {
    const Vector3 ax = n.cwiseAbs();
    const int k = ax.x() <= ax.y() ? (ax.x() <= ax.z() ? 0 : 2) : (ax.y() <= ax.z() ? 1 : 2);
    axes[0] = n.cross(Vector3::Unit(k)).normalized();
  }
  axes[1] = n.cross(axes[0]);
}
inline void contact_axes(const Vector2& n, const Vector2&, Scalar, Vector2 (&axes)[1]) { axes[0] = Vector2(-n.y(), n.x()); }

/// How far a body's support extends from its centre across a contact: the one-sided
/// derivative of the support function at body direction `n` toward the tangent `a`,
/// (s(n + h a) - s(n)) / h, with `s0` = s(n) and h one cell of the support map. For a convex
/// hull s is convex along n + h a, so the quotient grows with h from the extent of the support
/// set (the face or edge that touches) toward s(a); over one cell it is the face's extent where
/// the map's creases lie on its grid (a cube's exactly), and never less. 0 for a plain sphere,
/// whose support set is the point under its centre.
template <int D>
Scalar support_extent(const Shape<D>& s, const typename Space<D>::Vec& n, const typename Space<D>::Vec& a, Scalar s0)
{
  if (!s.statistical) return 0;
  const ContactView<D>& c = s.signature.contact;
  const Scalar h = Scalar(2) / Scalar(c.support_size - 1);
  return (support_along(c, typename Space<D>::Vec(n + a * h)) - s0) / h;
}

/// Where a body `up` resting on a body `lo` along the unit normal `n` (from lo to up) is held:
/// `pivot`, the point of the contact region nearest to where the line of gravity through up's
/// centre meets the contact plane, and `overhang`, from the pivot to that point (zero when the
/// region holds the centre of mass). The contact plane is lo's support plane along n; the region
/// is, along the tangent u toward the centre's line of gravity and (3D) along w = n x u, the
/// overlap of lo's support set, [-e_lo(-u), e_lo(u)] about lo's centre, and up's support set
/// along -n, [-e_up(-u), e_up(u)] about up's centre (`support_extent`): a box about the two
/// support sets' common part. False when gravity does not press up onto lo.
template <int D>
bool support_overhang(const Shape<D>& slo, const Body<D>& lo, const Shape<D>& sup, const Body<D>& up,
                      const typename Space<D>::Vec& n, const typename Space<D>::Vec& gravity_unit,
                      typename Space<D>::Vec& pivot, typename Space<D>::Vec& overhang)
{
  using Vec = typename Space<D>::Vec;
  const Scalar press = -gravity_unit.dot(n);
  if (!(press > 0)) return false;
  const Vec d = up.position - lo.position;
  const Vec n_lo = to_body(lo.orientation, n), n_up = to_body(up.orientation, Vec(-n));
  const Scalar s_lo = shape_support(slo, n_lo), s_up = shape_support(sup, n_up);
  // The line of gravity through up's centre meets lo's support plane, n.x = n.c_lo + s_lo, at
  // x = c_up + g^ t with t = (d.n - s_lo) / (-g^.n): relative to lo's centre, x - c_lo - n s_lo
  // lies in the plane.
  const Scalar above = d.dot(n) - s_lo;
  const Vec x = d + gravity_unit * (above / press) - n * s_lo;
  // Up's centre projected along n onto the plane, relative to lo's centre.
  const Vec c = d - n * d.dot(n);
  Vec axes[D == 3 ? 2 : 1];
  contact_axes(n, x, Scalar(1e-6) * sup.bounding_radius, axes);
  pivot = lo.position + n * s_lo;
  overhang = Vec::Zero();
  for (const Vec& a : axes) {
    const Vec a_lo = to_body(lo.orientation, a), a_up = to_body(up.orientation, a);
    const Scalar ca = c.dot(a), xa = x.dot(a);
    const Scalar lo_hi = support_extent(slo, n_lo, a_lo, s_lo), lo_lo = -support_extent(slo, n_lo, Vec(-a_lo), s_lo);
    const Scalar up_hi = ca + support_extent(sup, n_up, a_up, s_up);
    const Scalar up_lo = ca - support_extent(sup, n_up, Vec(-a_up), s_up);
    Scalar from = lo_lo > up_lo ? lo_lo : up_lo, to = lo_hi < up_hi ? lo_hi : up_hi;
    // Sets that meet at a point (an edge on a face, a corner on an edge) come out a little apart
    // or overlapping from the interpolated map: apart, they meet halfway.
    if (from > to) from = to = Scalar(0.5) * (from + to);
    const Scalar held = xa < from ? from : (xa > to ? to : xa);
    pivot += a * held;
    overhang += a * (xa - held);
  }
  return true;
}

/// Sector of the horizontal part of `v`: 0 to 7, 45 degrees each, counter-clockwise from the
/// first world axis (2D: 0 along +x, 4 along -x); 8 when v has no horizontal part.
template <int D>
std::uint32_t horizontal_sector(const typename Space<D>::Vec& v)
{
  const Scalar p = v[0];
  const Scalar q = D == 3 ? v[1] : Scalar(0);
  if (p > 0 && q >= 0) return p > q ? 0u : 1u;
  if (p <= 0 && q > 0) return q > -p ? 2u : 3u;
  if (p < 0 && q <= 0) return -p > -q ? 4u : 5u;
  if (p >= 0 && q < 0) return -q > p ? 6u : 7u;
  return 8u;
}

/// True when the sectors from which a body is held (`Body::supports`) all lie within three
/// consecutive ones (135 degrees): nothing on the far side keeps it from tipping. Supports in
/// sectors four apart (opposite) or, with their extent, three apart hold the centre of mass
/// between them, as a board lying across two blocks.
inline bool one_sided(std::uint8_t sectors)
{
  if (sectors == 0) return false;
  for (unsigned s = 0; s < 8; ++s) {
    const unsigned window = ((7u << s) | (7u >> (8 - s))) & 0xffu;
    if ((sectors & ~window & 0xffu) == 0) return true;
  }
  return false;
}

/// A supporting hull contact of the touching pair (normal within 60 degrees of up, as for the
/// bottom-up passes): the lower and the upper body and the normal from the lower to the upper.
/// False for a side contact, a pair without hulls, and an upper body that is asleep or not
/// statistical.
template <int D>
bool supporting(const WorldData<D>& w, Body<D>& a, Body<D>& b, const typename Space<D>::Vec& n, Body<D>*& lo,
                Body<D>*& up, typename Space<D>::Vec& n_up)
{
  const Scalar v = n[Space<D>::up_axis];
  if (!(v >= Scalar(0.5) || v <= Scalar(-0.5))) return false;
  lo = v > 0 ? &a : &b;
  up = v > 0 ? &b : &a;
  n_up = v > 0 ? n : typename Space<D>::Vec(-n);
  return up->state != MotionState::asleep && w.shapes[up->shape].statistical;
}

/// Gives a body resting on a pivot (`support_overhang`), with its centre of mass beyond it, the
/// spin and velocity of a body that tipped from balance over the pivot to where it is: a
/// statistical body takes no torque at its contacts, and without this it balances on an edge or
/// corner of the body below. With r from the pivot to the centre and the centre fallen by
/// drop = |r| - r.(-g^) from above the pivot, energy gives
///     |w| = sqrt(2 |g| drop / (k^2 + |r|^2)),
/// k^2 the unit moment of inertia about the axis r x g^; the spin about that axis is raised to
/// |w| (never lowered) and the centre moves with it about the pivot, w x r. The spin depends on
/// where the body is, not on how long it has tipped: contacts that stop the spin between steps
/// (rolling resistance at a resting contact) cannot hold it, and it never exceeds what falling
/// from balance gives. As the rest turn on the ground, it is capped where the body's farthest
/// point would move faster than `settle_speed`: contacts correct positions, not orientations, so
/// a fast turn would swing the body into its neighbours. Returns that spin, rad/s (0 where the
/// centre has not fallen from balance, or with no axis to turn about).
template <int D>
Scalar tip_over(const Shape<D>& shape, Body<D>& b, const typename Space<D>::Vec& pivot,
              const typename Space<D>::Vec& gravity_unit, Scalar gravity, Scalar settle_speed)
{
  using Vec = typename Space<D>::Vec;
  const Vec r = b.position - pivot;
  const Scalar r2 = r.squaredNorm();
  const Scalar drop = std::sqrt(r2) + r.dot(gravity_unit);
  if (!(drop > 0)) return 0;
  const std::array<Scalar, 3>& inertia = shape.signature.unit_inertia;
  const Scalar cap = settle_speed / shape.bounding_radius;
  if constexpr (D == 3) {
    const Vector3 axis = r.cross(gravity_unit);
    const Scalar length = axis.norm();
    if (!(length > 0)) return 0;
    const Vector3 k = axis / length;
    const Vector3 kb = to_body(b.orientation, k);
    const Scalar k2 = inertia[0] * kb.x() * kb.x() + inertia[1] * kb.y() * kb.y() + inertia[2] * kb.z() * kb.z();
    const Scalar fall = std::sqrt(2 * gravity * drop / (k2 + r2));
    const Scalar spin = fall < cap ? fall : cap;
    const Scalar now = b.angular_velocity.dot(k);
    if (!(now < spin)) return spin;
    const Vector3 dw = k * (spin - now);
    b.angular_velocity += dw;
    b.linear_velocity += dw.cross(r);
    return spin;
  } else {
    const Scalar turn = moment(r, gravity_unit);
    if (turn == 0) return 0;
    const Scalar sign = turn > 0 ? Scalar(1) : Scalar(-1);
    const Scalar fall = std::sqrt(2 * gravity * drop / (inertia[0] + r2));
    const Scalar spin = fall < cap ? fall : cap;
    const Scalar now = b.angular_velocity * sign;
    if (!(now < spin)) return spin;
    const Scalar dw = sign * (spin - now);
    b.angular_velocity += dw;
    b.linear_velocity += cross(dw, r);
    return spin;
  }
}

/// Gravity's unit direction and magnitude for the tipping rule, or false when it does not apply
/// (sphere contacts, or no gravity).
template <class FS, int D>
bool tip_gravity(const WorldData<D>& w, typename Space<D>::Vec& unit, Scalar& magnitude)
{
  if (!(FS::hull_contacts && hull_contacts_on(w))) return false;
  magnitude = w.def.gravity.norm();
  if (!(magnitude > 0)) return false;
  unit = w.def.gravity / magnitude;
  return true;
}

/// With hull contacts, records from which horizontal sectors the touching pair holds each of its
/// bodies (`Body::supports`, cleared by the shock pass before its loop): a supporting contact
/// that holds the upper body's centre of mass holds it outright (all sectors), one it overhangs
/// from the overhang's side, a side contact from the side it pushes from. True when the upper body
/// overhangs (a candidate for `tip_unsupported`).
template <class FS, int D>
bool mark_supports(const WorldData<D>& w, Body<D>& a, Body<D>& b, const typename Space<D>::Vec& n,
                   const typename Space<D>::Vec& gravity_unit)
{
  using Vec = typename Space<D>::Vec;
  if (!hull_pair<FS>(w, a, b)) return false;
  Body<D>*lo, *up;
  Vec n_up;
  if (supporting(w, a, b, n, lo, up, n_up)) {
    Vec pivot, over;
    if (!support_overhang(w.shapes[lo->shape], *lo, w.shapes[up->shape], *up, n_up, gravity_unit, pivot, over))
      return false;
    const std::uint32_t s = horizontal_sector<D>(over);
    up->supports = std::uint8_t(s == 8 ? 0xffu : (up->supports | (1u << s)));
    return s != 8;
  }
  if (std::fabs(n[Space<D>::up_axis]) < Scalar(0.5)) {
    const std::uint32_t sa = horizontal_sector<D>(Vec(-n)), sb = horizontal_sector<D>(n);
    if (sa < 8) a.supports = std::uint8_t(a.supports | (1u << sa));
    if (sb < 8) b.supports = std::uint8_t(b.supports | (1u << sb));
  }
  return false;
}

/// With hull contacts, tips awake statistical bodies that rest on bodies beyond their support,
/// after `mark_supports` saw every touching pair: every supporting contact a body overhangs tips
/// it (`tip_over`) where all the sectors it is held from lie on one side (`one_sided`), planes
/// included (a wall holds it from its side, the ground outright: its rest poses turn it there,
/// as they do a body that chose one).
/// A body wedged between neighbours, leaning on a wall or lying across two others is left alone,
/// so the rule cannot rock a body between supports, and it stops as soon as a support holds the
/// centre. One pass over the first `touching` pairs, whose contacts are taken as the passes after
/// the impact pass take them (grown by `slop_fraction`, `contact_slop`), a fixed number of
/// support map reads per contact (`support_overhang`).
template <class FS, int D>
void tip_unsupported(WorldData<D>& w, std::uint32_t touching, const typename Space<D>::Vec& gravity_unit,
                     Scalar gravity, Scalar slop_fraction)
{
  using Vec = typename Space<D>::Vec;
  for (std::uint32_t k = 0; k < touching; ++k) {
    Body<D>& a = w.bodies[w.pairs[k].a];
    Body<D>& b = w.bodies[w.pairs[k].b];
    Contact<D> c;
    Scalar reach, pair_slop;
    if (!body_contact<FS>(w, a, b, w.pairs[k], false, slop_fraction, c, reach, pair_slop,
                      STATSIM_HULL_CACHE && k < w.max_pair_hulls ? &w.pair_hulls[k] : nullptr))
      continue;
    if (!hull_pair<FS>(w, a, b)) continue;
    Body<D>*lo, *up;
    Vec n;
    // A body that chose a rest pose on the ground turns there (and keeps the pose while briefly
    // off it): tipping it too would undo that turn every other step.
    if (!supporting(w, a, b, c.normal, lo, up, n) || up->rest_pose != no_rest_pose || !one_sided(up->supports))
      continue;
    const Scalar slop = up->radius * slop_fraction;
    for (std::uint32_t p = 0; p < w.plane_count; ++p) {
      const Plane<D>& plane = w.planes[p];
      Contact<D> pc;
      if (!sphere_plane_contact<D>(up->position, plane_radius<FS>(w, *up, plane) + slop, plane, pc)) continue;
      const std::uint32_t s = horizontal_sector<D>(plane.normal);
      up->supports = std::uint8_t(plane.normal[Space<D>::up_axis] >= Scalar(0.5) || s == 8 ? 0xffu
                                                                                           : (up->supports | (1u << s)));
    }
    if (!one_sided(up->supports)) continue;
    Vec pivot, over;
    if (!support_overhang(w.shapes[lo->shape], *lo, w.shapes[up->shape], *up, n, gravity_unit, pivot, over)) continue;
    if (horizontal_sector<D>(over) != 8) tip_over(w.shapes[up->shape], *up, pivot, gravity_unit, gravity, w.def.settle_speed);
  }
}

}  // namespace detail
}  // namespace statsim
