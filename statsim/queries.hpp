#pragma once
/// @file
/// Queries: a ray cast and a sphere overlap against the bodies and the planes of a world. A
/// body is its collision sphere here (`Body::radius`, the sphere it collides with in the last
/// step), not its shape's hull; sleeping bodies count, removed ones do not. Queries read the
/// world and change nothing; they allocate nothing and call back into the caller for each hit.
///
/// They visit every body slot, so they cost time in proportion to the world's bodies. The broad
/// phase's records are not used: they hold the positions the bodies had when the step's broad phase ran, before the
/// contact passes moved them, and a body moved or added since is not in them.

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

template <int D>
Status check_query(const typename Space<D>::Vec& origin, const typename Space<D>::Vec& v, Scalar length)
{
  if (!finite(origin) || !finite(v) || !finite(length)) return Status::non_finite;
  if (!within(origin, limits::coordinate) || !within(v, limits::coordinate) || !(length >= 0) ||
      length > limits::coordinate)
    return Status::out_of_range;
  return Status::ok;
}

}  // namespace detail

/// Casts a ray from `origin` (m) along `direction` (any length > 0; it is normalised) up to
/// `max_distance` (m) and calls `on_hit(const QueryHit<D>&)` for every body sphere and plane it
/// enters, bodies in slot order, then planes; `on_hit` returns false to stop. A ray that starts
/// inside a sphere, or on the solid side of a plane, does not hit it. Returns `ok`;
/// `non_finite`; `out_of_range` (beyond `limits::coordinate`, or a negative distance);
/// `invalid_parameter` for a zero direction.
template <int D, class OnHit>
Status ray_cast_all(const WorldCore<D>& world, const typename Space<D>::Vec& origin,
                    const typename Space<D>::Vec& direction, Scalar max_distance, OnHit&& on_hit)
{
  using Vec = typename Space<D>::Vec;
  const Status s = detail::check_query<D>(origin, direction, max_distance);
  if (s != Status::ok) return s;
  const Scalar len = direction.norm();
  if (!(len > Scalar(1e-12))) return Status::invalid_parameter;
  const Vec d = direction / len;
  const detail::WorldData<D>& w = world.data();
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    const BodyId id = world.id_of(i);
    if (id == no_body) continue;
    const Body<D>& b = w.bodies[i];
    Scalar t;
    if (!detail::ray_sphere(origin, d, b.position, b.radius, t) || t > max_distance) continue;
    QueryHit<D> h;
    h.body = id;
    h.point = origin + d * t;
    h.normal = (h.point - b.position) / b.radius;
    h.distance = t;
    if (!on_hit(static_cast<const QueryHit<D>&>(h))) return Status::ok;
  }
  for (std::uint32_t p = 0; p < w.plane_count; ++p) {
    const Plane<D>& plane = w.planes[p];
    const Scalar gap = plane.normal.dot(origin) - plane.offset;
    const Scalar rate = plane.normal.dot(d);
    if (gap < 0 || !(rate < 0)) continue;
    const Scalar t = -gap / rate;
    if (t > max_distance) continue;
    QueryHit<D> h;
    h.plane = PlaneId(p);
    h.point = origin + d * t;
    h.normal = plane.normal;
    h.distance = t;
    if (!on_hit(static_cast<const QueryHit<D>&>(h))) return Status::ok;
  }
  return Status::ok;
}

/// The nearest hit of `ray_cast_all` into `closest` (`closest.hit()` false when the ray meets
/// nothing within `max_distance`). Statuses as `ray_cast_all`; on an error `closest` is left as
/// it was.
template <int D>
Status ray_cast(const WorldCore<D>& world, const typename Space<D>::Vec& origin,
                const typename Space<D>::Vec& direction, Scalar max_distance, QueryHit<D>& closest)
{
  QueryHit<D> best;
  const Status s = ray_cast_all(world, origin, direction, max_distance, [&best](const QueryHit<D>& h) {
    if (!best.hit() || h.distance < best.distance) best = h;
    return true;
  });
  if (s == Status::ok) closest = best;
  return s;
}

/// Calls `on_hit(const QueryHit<D>&)` for every body whose collision sphere overlaps the sphere
/// of `radius` (m, >= 0) about `center` (m), in slot order, then every plane it reaches into;
/// `on_hit` returns false to stop. Touching counts (a distance of 0). Returns `ok`, `non_finite`
/// or `out_of_range` (beyond `limits::coordinate`, or a negative radius).
template <int D, class OnHit>
Status overlap_sphere(const WorldCore<D>& world, const typename Space<D>::Vec& center, Scalar radius, OnHit&& on_hit)
{
  using Vec = typename Space<D>::Vec;
  const Status s = detail::check_query<D>(center, Vec::Zero(), radius);
  if (s != Status::ok) return s;
  const detail::WorldData<D>& w = world.data();
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    const BodyId id = world.id_of(i);
    if (id == no_body) continue;
    const Body<D>& b = w.bodies[i];
    const Vec d = center - b.position;
    const Scalar reach = radius + b.radius;
    const Scalar d2 = d.squaredNorm();
    if (!(d2 <= reach * reach)) continue;
    const Scalar dist = std::sqrt(d2);
    QueryHit<D> h;
    h.body = id;
    // Coincident centres: any direction will do; up keeps it defined.
    h.normal = dist > 0 ? Vec(d / dist) : Vec(Vec::Unit(Space<D>::up_axis));
    h.point = b.position + h.normal * b.radius;
    h.distance = dist - reach;
    if (!on_hit(static_cast<const QueryHit<D>&>(h))) return Status::ok;
  }
  for (std::uint32_t p = 0; p < w.plane_count; ++p) {
    const Plane<D>& plane = w.planes[p];
    const Scalar gap = plane.normal.dot(center) - plane.offset;
    if (gap > radius) continue;
    QueryHit<D> h;
    h.plane = PlaneId(p);
    h.normal = plane.normal;
    h.point = center - plane.normal * gap;
    h.distance = gap - radius;
    if (!on_hit(static_cast<const QueryHit<D>&>(h))) return Status::ok;
  }
  return Status::ok;
}

}  // namespace statsim
