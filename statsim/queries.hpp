#pragma once
/// @file
/// Queries: a ray cast and a sphere overlap against the bodies and the planes of a world. A
/// body is its collision sphere here (`Body::radius`, the sphere it collides with in the last
/// step), not its shape's hull; sleeping bodies count, removed ones do not. Queries read the
/// world and change nothing; they allocate nothing and call back into the caller for each hit.
///
/// They search the records of the broad phase in use (statsim/detail/query_search.hpp), so their cost
/// grows with the bodies near the ray or sphere, not with the world's bodies. The records hold
/// where bodies were when the last step's broad phase ran; the step measures how far any body has
/// moved from its record since (`detail::measure_drift`), and a query widens its search by that
/// distance: the rule that makes the records a conservative index. Bodies added since, or moved
/// between steps by `set_transform` or a reused slot's `add_body`, are tested one by one (up to
/// `detail::QueryIndex::max_moved` of them between two steps). Every candidate is then tested as
/// it is now, so the hits, their order and their numbers are those of a test of every slot
/// (`detail::ray_cast_all_scan`, `detail::overlap_sphere_scan`). The records cannot answer, and a
/// query tests every slot instead, before the first step, after more than `max_moved` such moves,
/// when a grid search would visit more cells than there are bodies (a ray much longer than the
/// world is wide, or a sphere as large as it), or when bodies went non-finite.
/// With the grid, a query visits the cells within its reach (query radius, largest bounding
/// radius and drift) of the ray or centre; with sweep-and-prune, the entries whose interval on
/// the sweep axis meets the query's, a slab across the world.

#include "statsim/detail/query_search.hpp"
#include "statsim/world.hpp"

#include <cmath>
#include <cstdint>

namespace statsim {

/// `QueryHit::plane` of a hit on a body.
constexpr PlaneId no_plane = 0xffff;

/// A body or plane a query met.
template <int D>
struct QueryHit {
  using Vec = typename Space<D>::Vec;
  BodyId body = no_body;     ///< the body, or `no_body` for a plane
  PlaneId plane = no_plane;  ///< the plane, or `no_plane` for a body
  /// Ray cast: where the ray enters the sphere or meets the plane, m. Overlap: the point of
  /// the body's sphere (or of the plane) nearest the query's centre, m.
  Vec point = Vec::Zero();
  /// Unit: the sphere's outward normal at `point`, or the plane's normal.
  Vec normal = Vec::Zero();
  /// Ray cast: distance along the ray, m. Overlap: distance from the query's surface to the
  /// body's sphere or the plane, m, <= 0 (minus the depth of the overlap).
  Scalar distance = 0;
  constexpr bool hit() const { return body != no_body || plane != no_plane; }
};

namespace detail {

/// A ray (unit direction `d`) against a sphere: true and `t` where it enters, for rays that
/// start outside it. |m + t d|^2 = r^2, m = o - c: t = -b - sqrt(b^2 - (m.m - r^2)), b = m.d.
template <class Vec>
bool ray_sphere(const Vec& o, const Vec& d, const Vec& c, Scalar r, Scalar& t)
{
  const Vec m = o - c;
  const Scalar b = m.dot(d);
  const Scalar cc = m.squaredNorm() - r * r;
  if (!(cc > 0) || b > 0) return false;
  const Scalar disc = b * b - cc;
  if (disc < 0) return false;
  t = -b - std::sqrt(disc);
  return true;
}

/// Body `i` (a live one) as a ray from `o` along unit `d` meets it within `max_distance`: the
/// hit into `h`, or false.
template <int D>
bool ray_body(const WorldData<D>& w, std::uint32_t i, const typename Space<D>::Vec& o,
              const typename Space<D>::Vec& d, Scalar max_distance, QueryHit<D>& h)
{
  const Body<D>& b = w.bodies[i];
  Scalar t;
  if (!ray_sphere(o, d, b.position, b.radius, t) || t > max_distance) return false;
  h.body = w.slots.id(i, w.body_count);
  h.point = o + d * t;
  h.normal = (h.point - b.position) / b.radius;
  h.distance = t;
  return true;
}

/// Body `i` (a live one) as the sphere of `radius` about `center` overlaps it: the hit into `h`,
/// or false.
template <int D>
bool overlap_body(const WorldData<D>& w, std::uint32_t i, const typename Space<D>::Vec& center, Scalar radius,
                  QueryHit<D>& h)
{
  using Vec = typename Space<D>::Vec;
  const Body<D>& b = w.bodies[i];
  const Vec d = center - b.position;
  const Scalar reach = radius + b.radius;
  const Scalar d2 = d.squaredNorm();
  if (!(d2 <= reach * reach)) return false;
  const Scalar dist = std::sqrt(d2);
  h.body = w.slots.id(i, w.body_count);
  // Coincident centres: any direction will do; up keeps it defined.
  h.normal = dist > 0 ? Vec(d / dist) : Vec(Vec::Unit(Space<D>::up_axis));
  h.point = b.position + h.normal * b.radius;
  h.distance = dist - reach;
  return true;
}

/// The planes a ray from `o` along unit `d` enters within `max_distance`, in order, to `on_hit`;
/// false when it stopped.
template <int D, class OnHit>
bool ray_planes(const WorldData<D>& w, const typename Space<D>::Vec& o, const typename Space<D>::Vec& d,
                Scalar max_distance, OnHit& on_hit)
{
  for (std::uint32_t p = 0; p < w.plane_count; ++p) {
    const Plane<D>& plane = w.planes[p];
    const Scalar gap = plane.normal.dot(o) - plane.offset;
    const Scalar rate = plane.normal.dot(d);
    if (gap < 0 || !(rate < 0)) continue;
    const Scalar t = -gap / rate;
    if (t > max_distance) continue;
    QueryHit<D> h;
    h.plane = PlaneId(p);
    h.point = o + d * t;
    h.normal = plane.normal;
    h.distance = t;
    if (!on_hit(static_cast<const QueryHit<D>&>(h))) return false;
  }
  return true;
}

/// The planes the sphere reaches into, in order, to `on_hit`; false when it stopped.
template <int D, class OnHit>
bool overlap_planes(const WorldData<D>& w, const typename Space<D>::Vec& center, Scalar radius, OnHit& on_hit)
{
  for (std::uint32_t p = 0; p < w.plane_count; ++p) {
    const Plane<D>& plane = w.planes[p];
    const Scalar gap = plane.normal.dot(center) - plane.offset;
    if (gap > radius) continue;
    QueryHit<D> h;
    h.plane = PlaneId(p);
    h.normal = plane.normal;
    h.point = center - plane.normal * gap;
    h.distance = gap - radius;
    if (!on_hit(static_cast<const QueryHit<D>&>(h))) return false;
  }
  return true;
}

/// `ray_cast_all` by testing every body slot in order: the reference the search through the
/// records must equal, and what it falls back to. `direction` is unit; the query checked.
template <int D, class OnHit>
void ray_cast_all_scan(const WorldData<D>& w, const typename Space<D>::Vec& origin,
                       const typename Space<D>::Vec& direction, Scalar max_distance, OnHit&& on_hit,
                       QueryStats& stats)
{
  stats.scanned = true;
  stats.bodies_examined += w.body_count;
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    QueryHit<D> h;
    if (!w.slots.live(i) || !ray_body(w, i, origin, direction, max_distance, h)) continue;
    if (!on_hit(static_cast<const QueryHit<D>&>(h))) return;
  }
  ray_planes(w, origin, direction, max_distance, on_hit);
}

/// `overlap_sphere` by testing every body slot in order (as `ray_cast_all_scan`).
template <int D, class OnHit>
void overlap_sphere_scan(const WorldData<D>& w, const typename Space<D>::Vec& center, Scalar radius,
                         OnHit&& on_hit, QueryStats& stats)
{
  stats.scanned = true;
  stats.bodies_examined += w.body_count;
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    QueryHit<D> h;
    if (!w.slots.live(i) || !overlap_body(w, i, center, radius, h)) continue;
    if (!on_hit(static_cast<const QueryHit<D>&>(h))) return;
  }
  overlap_planes(w, center, radius, on_hit);
}

template <int D>
Status check_query(const WorldCore<D>& world, const typename Space<D>::Vec& origin, const typename Space<D>::Vec& v,
                   Scalar length)
{
  if (!includes(world.features(), Features::queries)) return Status::not_compiled;
  if (!finite(origin) || !finite(v) || !finite(length)) return Status::non_finite;
  if (!within(origin, limits::coordinate) || !within(v, limits::coordinate) || !(length >= 0) ||
      length > limits::coordinate)
    return Status::out_of_range;
  return Status::ok;
}


/// `check_query` of a ray, and its unit direction into `d`; `invalid_parameter` for a zero direction.
template <int D>
Status check_ray(const WorldCore<D>& world, const typename Space<D>::Vec& origin,
                 const typename Space<D>::Vec& direction, Scalar max_distance, typename Space<D>::Vec& d)
{
  const Status s = check_query<D>(world, origin, direction, max_distance);
  if (s != Status::ok) return s;
  const Scalar len = direction.norm();
  if (!(len > Scalar(1e-12))) return Status::invalid_parameter;
  d = direction / len;
  return Status::ok;
}

}  // namespace detail

/// Casts a ray from `origin` (m) along `direction` (any length > 0; it is normalised) up to
/// `max_distance` (m) and calls `on_hit(const QueryHit<D>&)` for every body sphere and plane it
/// enters, bodies in slot order, then planes; `on_hit` returns false to stop. A ray that starts
/// inside a sphere, or on the solid side of a plane, does not hit it. Returns `ok`;
/// `non_finite`; `out_of_range` (beyond `limits::coordinate`, or a negative distance);
/// `invalid_parameter` for a zero direction; `not_compiled` in a world without
/// `Features::queries`. `stats`, if given, is added what the query examined.
template <int D, class OnHit>
Status ray_cast_all(const WorldCore<D>& world, const typename Space<D>::Vec& origin,
                    const typename Space<D>::Vec& direction, Scalar max_distance, OnHit&& on_hit,
                    QueryStats* stats = nullptr)
{
  using Vec = typename Space<D>::Vec;
  Vec d;
  const Status s = detail::check_ray<D>(world, origin, direction, max_distance, d);
  if (s != Status::ok) return s;
  const detail::WorldData<D>& w = detail::CoreAccess::data(world);
  QueryStats own;
  QueryStats& st = stats != nullptr ? *stats : own;
  const Vec end = origin + d * max_distance;
  const int done = detail::in_slot_order(
      [&](auto&& offer) { return detail::search_records(w, origin, end, Scalar(0), st, offer); },
      [&](std::uint32_t i) {
        QueryHit<D> h;
        return w.slots.live(i) && detail::ray_body(w, i, origin, d, max_distance, h);
      },
      [&](std::uint32_t i) {
        QueryHit<D> h;
        detail::ray_body(w, i, origin, d, max_distance, h);
        return bool(on_hit(static_cast<const QueryHit<D>&>(h)));
      });
  if (done == 0) detail::ray_cast_all_scan(w, origin, d, max_distance, on_hit, st);
  else if (done == 1) detail::ray_planes(w, origin, d, max_distance, on_hit);
  return Status::ok;
}

/// The nearest hit of `ray_cast_all` into `closest` (`closest.hit()` false when the ray meets
/// nothing within `max_distance`): of equally near ones, the body of the lowest slot, and a body
/// before a plane. Statuses as `ray_cast_all`; on an error `closest` is left as it was.
template <int D>
Status ray_cast(const WorldCore<D>& world, const typename Space<D>::Vec& origin,
                const typename Space<D>::Vec& direction, Scalar max_distance, QueryHit<D>& closest,
                QueryStats* stats = nullptr)
{
  using Vec = typename Space<D>::Vec;
  Vec d;
  const Status s = detail::check_ray<D>(world, origin, direction, max_distance, d);
  if (s != Status::ok) return s;
  const detail::WorldData<D>& w = detail::CoreAccess::data(world);
  QueryStats own;
  QueryStats& st = stats != nullptr ? *stats : own;
  QueryHit<D> best;
  const auto keep = [&best](const QueryHit<D>& h) {
    if (!best.hit() || h.distance < best.distance) best = h;
    return true;
  };
  // The nearest body, the lowest slot of equally near ones: what keeping the first strictly
  // nearer hit in slot order keeps. Bodies offered twice or out of order change nothing.
  std::uint32_t nearest = detail::no_slot;
  Scalar nearest_t = 0;
  const bool answered = detail::search_records(w, origin, Vec(origin + d * max_distance), Scalar(0), st,
                                               [&](std::uint32_t i) {
                                                 QueryHit<D> h;
                                                 if (!w.slots.live(i) || !detail::ray_body(w, i, origin, d, max_distance, h))
                                                   return;
                                                 if (nearest == detail::no_slot || h.distance < nearest_t ||
                                                     (h.distance == nearest_t && i < nearest)) {
                                                   nearest = i;
                                                   nearest_t = h.distance;
                                                 }
                                               });
  if (!answered) {
    detail::ray_cast_all_scan(w, origin, d, max_distance, keep, st);
  } else {
    if (nearest != detail::no_slot) detail::ray_body(w, nearest, origin, d, max_distance, best);
    detail::ray_planes(w, origin, d, max_distance, keep);
  }
  closest = best;
  return Status::ok;
}

/// Calls `on_hit(const QueryHit<D>&)` for every body whose collision sphere overlaps the sphere
/// of `radius` (m, >= 0) about `center` (m), in slot order, then every plane it reaches into;
/// `on_hit` returns false to stop. Touching counts (a distance of 0). Returns `ok`, `non_finite`
/// `out_of_range` (beyond `limits::coordinate`, or a negative radius) or `not_compiled` (a world
/// without `Features::queries`). `stats`, if given, is added what the query examined.
template <int D, class OnHit>
Status overlap_sphere(const WorldCore<D>& world, const typename Space<D>::Vec& center, Scalar radius, OnHit&& on_hit,
                      QueryStats* stats = nullptr)
{
  using Vec = typename Space<D>::Vec;
  const Status s = detail::check_query<D>(world, center, Vec::Zero(), radius);
  if (s != Status::ok) return s;
  const detail::WorldData<D>& w = detail::CoreAccess::data(world);
  QueryStats own;
  QueryStats& st = stats != nullptr ? *stats : own;
  const int done = detail::in_slot_order(
      [&](auto&& offer) { return detail::search_records(w, center, center, radius, st, offer); },
      [&](std::uint32_t i) {
        QueryHit<D> h;
        return w.slots.live(i) && detail::overlap_body(w, i, center, radius, h);
      },
      [&](std::uint32_t i) {
        QueryHit<D> h;
        detail::overlap_body(w, i, center, radius, h);
        return bool(on_hit(static_cast<const QueryHit<D>&>(h)));
      });
  if (done == 0) detail::overlap_sphere_scan(w, center, radius, on_hit, st);
  else if (done == 1) detail::overlap_planes(w, center, radius, on_hit);
  return Status::ok;
}

}  // namespace statsim
