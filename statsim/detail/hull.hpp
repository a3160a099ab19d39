#pragma once
/// @file
/// Body-body contact from the shapes' hulls (`BodyContacts::hulls`): where two bodies at their
/// current orientations touch, from the support maps and largest faces of their signatures
/// (`ContactView`), instead of at the sum of their collision radii.
///
/// For any unit n with n.e > 0 (e: the unit line of centres, from a to b), two convex hulls are
/// apart while the separation of their centres along n exceeds the sum of their supports,
/// (c_b - c_a).n > s_a(n) + s_b(-n). Along e they therefore touch no farther apart than
///     d(e) = min over n of [s_a(n) + s_b(-n)] / (n.e),
/// exactly at the contact normal when it is among the candidates. Candidates: e itself and
/// the stored faces of either body (n = R_a f, or n = -R_b g), whose own support is their offset
/// exactly; the other body's support comes from its support map, which never reads below the
/// hull's. Each candidate k carries a packing ratio p_k (how much nearer than their hulls allow
/// neighbours rest in reference piles): a face of the shape itself holds its neighbour at the
/// hull (p = 1), a hull face that spans a hollow lets it nest (p < 1), and a contact along the
/// line of centres takes the ratio for its angle to the vertical. A pair touches when
///     |c_b - c_a| < min over k of p_k d_k(e),   d_k(e) = [s_a(n_k) + s_b(-n_k)] / (n_k.e),
/// and the contact is taken along the minimising candidate n*, with the separation it needs
/// target = p* [s_a(n*) + s_b(-n*)]: so a box resting on two offset boxes is held along their
/// faces' normal, not pushed sideways along the line of centres. The minimum is over the packed
/// distances, not the ratio of the geometric minimum: each p_k d_k changes continuously as the
/// bodies move and turn, and so does their minimum, where the ratio of whichever candidate is
/// geometrically least jumps when that candidate changes (for an L-shape from 0.7 to 1, a
/// third of the distance): a body nested along one face would be thrown out of the hollow by
/// the overlap correction as soon as another face became the least, fall back and be thrown
/// again, never coming to rest.
///
/// Cost per pair: two rotations and two map reads for e, then per face with n.e > 0 that can
/// still beat the best candidate one rotation, one map read and one division; a fixed bound, no
/// square root beyond |c_b - c_a|. A plain sphere of radius r takes part with s(u) = r and no
/// faces, which is exact for a sphere against a hull.

#include "statsim/detail/narrow_phase.hpp"
#include "statsim/detail/world_data.hpp"

#include <cmath>
#include <cstdint>

namespace statsim {
namespace detail {

/// A direction from the world frame into the body frame of orientation q (body to world).
inline Vector3 to_body(const Quaternion& q, const Vector3& v) { return q.conjugate() * v; }
inline Vector2 to_body(const Rot2& r, const Vector2& v) { return {r.c * v.x() + r.s * v.y(), r.c * v.y() - r.s * v.x()}; }
inline Vector3 to_world(const Quaternion& q, const Vector3& v) { return q * v; }
inline Vector2 to_world(const Rot2& r, const Vector2& v) { return r * v; }

/// Cell and fraction of a face coordinate a in [-1, 1] on S nodes -1 + 2 i / (S - 1), clamped.
inline void support_cell(Scalar a, std::uint32_t size, std::uint32_t& i, Scalar& t)
{
  const Scalar x = (a + 1) * (Scalar(0.5) * Scalar(size - 1));
  const Scalar top = Scalar(size - 2);
  const Scalar cell = x > 0 ? (x < top ? Scalar(static_cast<std::uint32_t>(x)) : top) : Scalar(0);
  i = static_cast<std::uint32_t>(cell);
  const Scalar f = x - cell;
  t = f > 0 ? (f < 1 ? f : Scalar(1)) : Scalar(0);
}

/// The support map's value in body direction u (any length; s is homogeneous of degree 1):
/// the face of u's largest component u_m (the first of equals), interpolated at the face
/// coordinates of u / |u_m|, times |u_m|.
inline Scalar support_along(const ContactView<3>& c, const Vector3& u)
{
  // The axis is picked by arithmetic on the comparisons, not by branches: over a step's pairs
  // it is random, and a mispredicted branch costs more than the whole selection.
  const Scalar a[3] = {std::fabs(u[0]), std::fabs(u[1]), std::fabs(u[2])};
  const std::uint32_t y = a[1] > a[0] ? 1u : 0u;
  const std::uint32_t z = a[2] > a[y] ? 1u : 0u;
  const std::uint32_t m = z * 2u + (1u - z) * y;
  const Scalar um = a[m];
  if (!(um > 0)) return 0;
  static constexpr std::uint8_t next_axis[3] = {1, 2, 0}, last_axis[3] = {2, 0, 1};
  const Scalar next = u[next_axis[m]], last = u[last_axis[m]];
  const std::uint32_t s = c.support_size;
  const std::uint32_t face = 2 * m + (u[m] < 0 ? 1u : 0u);
  std::uint32_t i, j;
  Scalar t, w;
  support_cell(next / um, s, i, t);
  support_cell(last / um, s, j, w);
  const std::uint32_t k = (face * s + i) * s + j;
  const ValuesView& v = c.support;
  const Scalar h = (1 - t) * ((1 - w) * v[k] + w * v[k + 1]) + t * ((1 - w) * v[k + s] + w * v[k + s + 1]);
  return um * h;
}

inline Scalar support_along(const ContactView<2>& c, const Vector2& u)
{
  const int m = std::fabs(u[1]) > std::fabs(u[0]) ? 1 : 0;
  const Scalar um = std::fabs(u[m]);
  if (!(um > 0)) return 0;
  const std::uint32_t s = c.support_size;
  const std::uint32_t side = std::uint32_t(2 * m) + (u[m] < 0 ? 1u : 0u);
  std::uint32_t i;
  Scalar t;
  support_cell(u[1 - m] / um, s, i, t);
  const std::uint32_t k = side * s + i;
  return um * ((1 - t) * c.support[k] + t * c.support[k + 1]);
}

/// The support of a shape in body direction u: its map, or a plain sphere's radius.
template <int D>
Scalar shape_support(const Shape<D>& s, const typename Space<D>::Vec& u)
{
  return s.statistical ? support_along(s.signature.contact, u) : s.radius;
}

/// Packing ratio of a shape for a pair touching along its line of centres, whose up component
/// is `up` (cos of its angle to the vertical, sign ignored): the table's three angle bins
/// (0-30, 30-60, 60-90 degrees) taken at their centres (cos 15, 45, 75 degrees) and
/// interpolated linearly between, constant beyond; 1 for a plain sphere.
template <int D>
Scalar packing_ratio(const Shape<D>& s, Scalar up)
{
  if (!s.statistical) return 1;
  const std::array<Scalar, 3>& p = s.signature.contact.packing_mean;
  constexpr Scalar c15 = Scalar(0.96592583), c45 = Scalar(0.70710678), c75 = Scalar(0.25881905);
  const Scalar x = std::fabs(up);
  if (x >= c15) return p[0];
  if (x >= c45) return p[1] + (p[0] - p[1]) * ((x - c45) / (c15 - c45));
  if (x >= c75) return p[2] + (p[1] - p[2]) * ((x - c75) / (c45 - c75));
  return p[2];
}

/// A candidate contact of two hulls: its normal (from a to b, world frame), the separation of
/// the centres along it at which the hulls touch, s_a(n) + s_b(-n) (m), and the packing ratio
/// of contacts along it (a face's own; 0 for the line of centres, whose ratio depends on the
/// pair, see `pair_packing`).
template <int D>
struct HullCandidate {
  typename Space<D>::Vec normal;
  Scalar reach;
  Scalar packing;
};

/// Candidate `k` of a pair: 0 the line of centres `e`, 1 + i face i of a, 1 + K_a + i face i of
/// b (K_a: a's face count).
template <int D>
HullCandidate<D> hull_candidate(const Shape<D>& sa, const Body<D>& a, const Shape<D>& sb, const Body<D>& b,
                                const typename Space<D>::Vec& e, std::uint32_t k)
{
  using Vec = typename Space<D>::Vec;
  constexpr std::uint32_t fv = face_values(D);
  const std::uint32_t ka = sa.statistical ? sa.signature.contact.face_count : 0u;
  if (k == 0) {
    const Vec ea = to_body(a.orientation, e), eb = to_body(b.orientation, e);
    return {e, shape_support(sa, ea) + shape_support(sb, Vec(-eb)), 0};
  }
  if (k <= ka) {
    const Scalar* f = sa.signature.contact.faces + (k - 1) * fv;
    const Vec n = to_world(a.orientation, Vec(Eigen::Map<const Vec>(f)));
    const Scalar offset = f[D] * sa.signature.contact.offset_scale;
    return {n, offset + shape_support(sb, to_body(b.orientation, Vec(-n))), f[D + 1]};
  }
  const Scalar* g = sb.signature.contact.faces + (k - 1 - ka) * fv;
  const Vec n = -to_world(b.orientation, Vec(Eigen::Map<const Vec>(g)));
  return {n, shape_support(sa, to_body(a.orientation, n)) + g[D] * sb.signature.contact.offset_scale, g[D + 1]};
}

/// Packing ratio of a pair touching along the line of centres `e`: each shape's by angle
/// (`packing_ratio`), their mean for two shapes.
template <int D>
Scalar pair_packing(const Shape<D>& sa, const Shape<D>& sb, bool same_shape, const typename Space<D>::Vec& e)
{
  const Scalar up = e[Space<D>::up_axis];
  return same_shape ? packing_ratio(sa, up) : Scalar(0.5) * (packing_ratio(sa, up) + packing_ratio(sb, up));
}

/// The largest packing ratio a contact of the shape can have (1 for a plain sphere): with it a
/// pair apart along its line of centres is known to be apart.
template <int D>
Scalar largest_packing(const Shape<D>& s)
{
  if (!s.statistical) return 1;
  const ContactView<D>& c = s.signature.contact;
  Scalar p = 0;
  for (Scalar x : c.packing_mean) p = x > p ? x : p;
  for (std::uint32_t i = 0; i < c.face_count; ++i) {
    const Scalar x = c.faces[i * face_values(D) + D + 1];
    p = x > p ? x : p;
  }
  return p;
}

/// The faces of shape `s` (its first `count`) that may beat the least distance `best` found so
/// far, as bits: face i with unit normal f_i (body frame) has cosine c_i = sign f_i.u > 0 with
/// the line of centres u (body frame; sign -1 for the second body, whose faces point back
/// along it) and p_i (o_i + floor) < best c_i, floor the least support of the other shape.
/// Fills `cosine` for every face counted. The tests are gathered before any face is read further
/// because their outcomes follow no pattern a branch predictor could learn; `best` only falls
/// while the faces are read, so a face not set here could not have beaten it later.
template <int D>
std::uint32_t face_mask(const Shape<D>& s, std::uint32_t count, const typename Space<D>::Vec& u, Scalar sign,
                        Scalar floor, Scalar best, bool packed, Scalar* cosine)
{
  using Vec = typename Space<D>::Vec;
  constexpr std::uint32_t fv = face_values(D);
  const ContactView<D>& v = s.signature.contact;
  std::uint32_t bits = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    const Scalar* f = v.faces + i * fv;
    const Scalar c = sign * Vec(Eigen::Map<const Vec>(f)).dot(u);
    const Scalar p = packed ? f[D + 1] : Scalar(1);
    cosine[i] = c;
    bits |= std::uint32_t((c > 0) & (p * (f[D] * v.offset_scale + floor) < best * c)) << i;
  }
  return bits;
}

/// The hull contact of a pair whose centres are `d` apart (d = c_b - c_a, |d| = `dist` > 0,
/// e = d / dist): the candidate with the least packed distance along e, p_k d_k(e), where
/// `line_packing` > 0 is the ratio along e itself (`pair_packing`), or with `line_packing` = 0
/// the least distance of the hulls' geometry alone (p_k = 1: what the gatherers measure packing
/// against); `no_witness` when the pair is apart: at least that distance away, or (first, from
/// e alone) farther than the distance along e times `packing`, the largest packing ratio either
/// shape has.
constexpr std::uint32_t no_witness = 0xffu;
// Candidates are numbered up to 2 `max_contact_faces`, below `no_witness`, in `Pair::witness`'s 8 bits.
static_assert(2 * max_contact_faces < no_witness, "candidate numbers must fit Pair::witness");

template <int D>
std::uint32_t find_hull_witness(const Shape<D>& sa, const Body<D>& a, const Shape<D>& sb, const Body<D>& b,
                                const typename Space<D>::Vec& e, Scalar dist, Scalar packing, Scalar line_packing = 0)
{
  using Vec = typename Space<D>::Vec;
  constexpr std::uint32_t fv = face_values(D);
  // Along e itself first: the least distance is at most this one, so a pair apart along e is
  // apart (the faces can only bring the distance down).
  const Vec ea = to_body(a.orientation, e), eb = to_body(b.orientation, e);
  Scalar best = shape_support(sa, ea) + shape_support(sb, Vec(-eb));
  if (!(dist < packing * best)) return no_witness;
  const bool packed = line_packing > 0;
  if (packed) best *= line_packing;
  std::uint32_t witness = 0;
  // A face of a with offset o, packing ratio p and n.e = c gives at least p (o + floor_b) / c,
  // floor_b the least support b's map can return: faces that cannot beat the best so far are
  // skipped unread.
  const Scalar floor_a = sa.statistical ? sa.support_floor : sa.radius;
  const Scalar floor_b = sb.statistical ? sb.support_floor : sb.radius;
  const std::uint32_t ka = sa.statistical ? sa.signature.contact.face_count : 0u;
  const std::uint32_t kb = sb.statistical ? sb.signature.contact.face_count : 0u;
  // Face i of a, whose cosine with e is c.
  const auto face_of_a = [&](std::uint32_t i, Scalar c) {
    const Scalar* f = sa.signature.contact.faces + i * fv;
    const Scalar offset = f[D] * sa.signature.contact.offset_scale;
    const Scalar pf = packed ? f[D + 1] : Scalar(1);
    if (!(c > 0) || !(pf * (offset + floor_b) < best * c)) return;
    const Vec n = to_world(a.orientation, Vec(Eigen::Map<const Vec>(f)));
    const Scalar along = pf * ((offset + shape_support(sb, to_body(b.orientation, Vec(-n)))) / c);
    if (!(along > best)) {
      best = along;
      witness = 1 + i;
    }
  };
  // Face i of b, whose cosine with -e is c.
  const auto face_of_b = [&](std::uint32_t i, Scalar c) {
    const Scalar* g = sb.signature.contact.faces + i * fv;
    const Scalar offset = g[D] * sb.signature.contact.offset_scale;
    const Scalar pg = packed ? g[D + 1] : Scalar(1);
    if (!(c > 0) || !(pg * (offset + floor_a) < best * c)) return;
    const Vec n = -to_world(b.orientation, Vec(Eigen::Map<const Vec>(g)));
    const Scalar along = pg * ((shape_support(sa, to_body(a.orientation, n)) + offset) / c);
    if (!(along > best)) {
      best = along;
      witness = 1 + ka + i;
    }
  };
  if constexpr (D == 3) {
    // A 3D pile's pairs meet at any angle, so which faces pass is random (`face_mask`); a 2D
    // pile's faces pass in patterns that branches predict, and the mask costs more there
    // (tools/bench/README.md).
    Scalar cosine[max_contact_faces];
    for (std::uint32_t bits = face_mask(sa, ka, ea, Scalar(1), floor_b, best, packed, cosine); bits != 0; bits &= bits - 1)
      face_of_a(lowest_bit(bits), cosine[lowest_bit(bits)]);
    for (std::uint32_t bits = face_mask(sb, kb, eb, Scalar(-1), floor_a, best, packed, cosine); bits != 0; bits &= bits - 1)
      face_of_b(lowest_bit(bits), cosine[lowest_bit(bits)]);
  } else {
    for (std::uint32_t i = 0; i < ka; ++i)
      face_of_a(i, Vec(Eigen::Map<const Vec>(sa.signature.contact.faces + i * fv)).dot(ea));
    for (std::uint32_t i = 0; i < kb; ++i)
      face_of_b(i, -Vec(Eigen::Map<const Vec>(sb.signature.contact.faces + i * fv)).dot(eb));
  }
  return dist < (packed ? best : packing * best) ? witness : no_witness;
}

/// True when two bodies touch at their hulls (`BodyContacts::hulls`, both shapes with a hull, at
/// least one statistical).
template <class FS = AllFeatures, int D>
bool hull_pair(const WorldData<D>& w, const Body<D>& a, const Body<D>& b)
{
  const Shape<D>& sa = w.shapes[a.shape];
  const Shape<D>& sb = w.shapes[b.shape];
  return FS::hull_contacts && hull_contacts_on(w) && has_hull(sa) && has_hull(sb) &&
         (sa.statistical || sb.statistical);
}

/// Whether a hull pair overlapping by `depth` of its `reach`, one of the two asleep, wakes the
/// sleeper (`hull_wake_overlap`).
template <class FS = AllFeatures, int D>
bool wakes_by_overlap(const WorldData<D>& w, const Body<D>& a, const Body<D>& b, Scalar depth, Scalar reach)
{
  if (!(depth > hull_wake_overlap * reach) || !hull_pair<FS>(w, a, b)) return false;
  const Body<D>& presser = a.state == MotionState::asleep ? b : a;
  return depth > 2 * hull_wake_overlap * reach || presser.slow_time <= 0 || squared_norm(presser.angular_velocity) > 0;
}

/// The unit line of centres `e` and the distance of two bodies `d` apart (b - a); false when
/// their bounding spheres are apart.
template <int D>
bool centre_line(const Shape<D>& sa, const Shape<D>& sb, const typename Space<D>::Vec& d, Scalar& dist,
                 typename Space<D>::Vec& e)
{
  using Vec = typename Space<D>::Vec;
  const Scalar dist2 = d.squaredNorm();
  const Scalar bound = sa.bounding_radius + sb.bounding_radius;
  if (!(dist2 < bound * bound)) return false;
  dist = std::sqrt(dist2);
  // Coincident centres: any direction is as good; up keeps it defined and deterministic.
  e = dist > bound * Scalar(1e-6) ? Vec(d / dist) : Vec(Vec::Unit(Space<D>::up_axis));
  return true;
}

/// The impact pass's search of a pair's hull candidate (`find_hull_witness`), into `pair.witness`.
template <int D>
void search_witness(const Shape<D>& sa, const Body<D>& a, const Shape<D>& sb, const Body<D>& b,
                    const typename Space<D>::Vec& e, Scalar dist, Pair& pair)
{
  const Scalar pa = sa.statistical ? sa.largest_packing : Scalar(1);
  const Scalar pb = sb.statistical ? sb.largest_packing : Scalar(1);
  const Scalar packing = pa > pb ? pa : pb;
  // A world's shapes support no farther than their bounding radius (`add_shape` makes it at least
  // the support map's ceiling; 1e-4 covers a lookup's rounding): a pair farther apart than the
  // packing times their sum is apart without a lookup (tools/bench/README.md: many pile pairs are).
  // (Not in `find_hull_witness`: the gatherers call it on shapes that no world set up.)
  if (!(dist < packing * (sa.bounding_radius + sb.bounding_radius) * Scalar(1.0001))) {
    pair.witness = no_witness;
    return;
  }
  pair.witness = find_hull_witness(sa, a, sb, b, e, dist, packing, pair_packing(sa, sb, a.shape == b.shape, e)) & 0xffu;
}

/// Whether the pair touches and how: at their collision spheres, or (`BodyContacts::hulls`,
/// both shapes with a hull) along a hull candidate, searched afresh when `fresh` (the impact
/// pass) and else the one the impact pass found. `slop_fraction`: spheres grown by this fraction
/// of the reach. Fills the contact and the reach (separation along the normal at which they
/// touch, m). `kept` (may be null): with `keep`, receives the pair's face contact (reach 0 for
/// none); without, a face contact kept earlier in the step, used as found (`PairHull`).
template <class FS = AllFeatures, int D>
bool body_contact(const WorldData<D>& w, Body<D>& a, Body<D>& b, Pair& pair, bool fresh, Scalar slop_fraction,
                  Contact<D>& c, Scalar& reach, Scalar& slop, PairHull<D>* kept = nullptr, bool keep = false)
{
  using Vec = typename Space<D>::Vec;
  const Shape<D>& sa = w.shapes[a.shape];
  const Shape<D>& sb = w.shapes[b.shape];
  if constexpr (!FS::hull_contacts) {
    reach = a.radius + b.radius;
    slop = reach * slop_fraction;
    return sphere_sphere_contact<D>(a.position, a.radius + slop, b.position, b.radius, c);
  }
  if (STATSIM_HULL_CACHE && kept && keep) kept->reach = 0;
  const bool known = STATSIM_HULL_CACHE && kept && !keep && kept->reach > 0;
  if (!known && !hull_pair<FS>(w, a, b)) {
    reach = a.radius + b.radius;
    slop = reach * slop_fraction;
    return sphere_sphere_contact<D>(a.position, a.radius + slop, b.position, b.radius, c);
  }
  const Vec d = b.position - a.position;
  Vec normal;
  if (known) {
    // `centre_line`'s test, without the line: a face's contact does not depend on it.
    const Scalar bound = sa.bounding_radius + sb.bounding_radius;
    if (!(d.squaredNorm() < bound * bound)) return false;
    normal = kept->normal;
    reach = kept->reach;
  } else {
    Scalar dist;
    Vec e;
    if (!centre_line(sa, sb, d, dist, e)) return false;
    if (fresh) search_witness(sa, a, sb, b, e, dist, pair);
    if (pair.witness == no_witness) return false;
    const HullCandidate<D> h = hull_candidate(sa, a, sb, b, e, pair.witness);
    normal = h.normal;
    reach = (pair.witness == 0 ? pair_packing(sa, sb, a.shape == b.shape, e) : h.packing) * h.reach;
    if (STATSIM_HULL_CACHE && kept && keep && pair.witness != 0) *kept = PairHull<D>{normal, reach};
  }
  slop = reach * slop_fraction;
  const Scalar depth = reach + slop - d.dot(normal);
  if (!(depth > 0)) return false;
  c.normal = normal;
  c.depth = depth;
  return true;
}

}  // namespace detail
}  // namespace statsim
