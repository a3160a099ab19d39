#pragma once
/// @file
/// Narrow phase: sphere against plane and sphere against sphere (paper 3.3.1: the same sphere
/// serves both), giving the collision-plane normal of paper 3.3.2 step 1 and the overlap depth.

#include "statsim/math.hpp"
#include "statsim/world_def.hpp"

namespace statsim {

/// A touching pair: the collision-plane normal and how far the spheres overlap.
template <int D>
struct Contact {
  typename Space<D>::Vec normal;  ///< unit; out of the plane, or from body a to body b
  Scalar depth;                   ///< overlap, m, > 0
};

/// Sphere (centre `c`, radius `r`) against a plane: true and `out` filled when they overlap.
template <int D>
bool sphere_plane_contact(const typename Space<D>::Vec& c, Scalar r, const Plane<D>& plane, Contact<D>& out)
{
  const Scalar depth = r - (plane.normal.dot(c) - plane.offset);
  if (!(depth > 0)) return false;
  out.normal = plane.normal;
  out.depth = depth;
  return true;
}

/// Sphere a against sphere b: true and `out` filled when they overlap. The normal is the
/// separating plane's, from a to b; for coincident centres (closer than 1e-6 of the radii's sum)
/// it is the up axis, so the result is still defined and deterministic.
template <int D>
bool sphere_sphere_contact(const typename Space<D>::Vec& ca, Scalar ra, const typename Space<D>::Vec& cb, Scalar rb,
                           Contact<D>& out)
{
  using Vec = typename Space<D>::Vec;
  const Vec d = cb - ca;
  const Scalar reach = ra + rb;
  const Scalar dist2 = d.squaredNorm();
  if (!(dist2 < reach * reach)) return false;
  const Scalar dist = std::sqrt(dist2);
  out.normal = dist > reach * Scalar(1e-6) ? Vec(d / dist) : Vec(Vec::Unit(Space<D>::up_axis));
  out.depth = reach - dist;
  return true;
}

}  // namespace statsim
