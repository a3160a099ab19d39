// The support function of a body's convex hull, s(u) = max over hull vertices p of u.p (body
// frame, u a unit direction), and a compact table of it that a runtime can read in O(1).
//
// Two convex bodies that touch with separating-plane normal n (from a to b) have their centres
// s_a(R_a^T n) + s_b(-R_b^T n) apart along n; along the line of centres e the same sum is an
// upper bound of their distance (the radial function of the Minkowski difference is at most its
// support function), exact when e is normal to a face of it (face-to-face stacks).
//
// Encoding (3D, "cube map"). Every direction u meets the cube |x|_inf = 1 at p = u / |u_m|, m
// the axis of u's largest component (the first of equals), on face (m, sign u_m), with face
// coordinates a = u_{m+1} / |u_m|, b = u_{m+2} / |u_m| in [-1, 1] (axes cyclic). The table holds
// h(p) = max_p' p.p' at S x S nodes a_i = -1 + 2 i / (S - 1) per face; a lookup interpolates
// h bilinearly in (a, b) and returns |u_m| h: since h is homogeneous of degree 1,
// s(u) = h(u) = |u_m| h(p). No square root, no trigonometry.
// On a face h is convex and piecewise linear in (a, b) (a maximum of affine functions
// +-p'_m + a p'_{m+1} + b p'_{m+2}), so bilinear interpolation is exact where a cell holds one
// piece and otherwise never below h (Jensen: the bilinear weights are a convex combination of
// the corners whose mean is the point): the table never predicts two bodies closer than their
// hulls allow. Nodes on a face's edges are stored on both faces (the same value), so the lookup
// is continuous.
//
// Encoding (2D, "square map"): the same on the square |x|_inf = 1, S nodes per side, linear
// interpolation: 4 S values, s(u) = |u_m| h(p).
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace statsim::tools {

/// Exact support of the point set `hull` (body frame) in direction `u` (any length): max u.p.
double support(const std::vector<Eigen::Vector3d>& hull, const Eigen::Vector3d& u);
double support(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& u);

/// The 3D table: 6 faces x S x S values, face f = 2 m + (u_m < 0), value index (f S + i) S + j
/// with i along a (axis m+1), j along b (axis m+2).
struct SupportMap3 {
  int size = 0;                ///< S, nodes per face side, >= 2
  std::vector<double> values;  ///< m: h at the nodes
  /// The table of `hull` with S nodes per side.
  static SupportMap3 build(const std::vector<Eigen::Vector3d>& hull, int size);
  /// The interpolated support in the unit direction `u` (m).
  double lookup(const Eigen::Vector3d& u) const;
  /// A bound of lookup(u) - support(hull, u) over every unit u (never negative by convexity):
  /// per cell the largest miss on a `sub` x `sub` grid of each cell plus the most the miss can
  /// change between grid points (Lipschitz: |grad h| <= r on the face plane, the bilinear
  /// interpolant's gradient at most sqrt(2) r, r = the hull's radius, over half a sub-cell
  /// diagonal), times |u_m| <= 1.
  double error_bound(const std::vector<Eigen::Vector3d>& hull, int sub = 24) const;
};

/// The 2D table: 4 sides x S values, side f = 2 m + (u_m < 0), index f S + i, i along axis 1 - m.
struct SupportMap2 {
  int size = 0;
  std::vector<double> values;
  static SupportMap2 build(const std::vector<Eigen::Vector2d>& hull, int size);
  double lookup(const Eigen::Vector2d& u) const;
  /// As SupportMap3::error_bound, along the sides (gradient bound 2 r).
  double error_bound(const std::vector<Eigen::Vector2d>& hull, int sub = 64) const;
};

/// Error of a table against the exact support over `n` directions: uniform random on the sphere
/// from a fixed seed (3D), evenly spaced on the circle (2D). The mean, largest and smallest of
/// lookup - support, m.
struct SupportError {
  double mean = 0.0, max = 0.0, min = 0.0;  ///< min: the most negative (should be >= -rounding)
};
SupportError measure_support_error(const SupportMap3& map, const std::vector<Eigen::Vector3d>& hull, int n);
SupportError measure_support_error(const SupportMap2& map, const std::vector<Eigen::Vector2d>& hull, int n);

}  // namespace statsim::tools
