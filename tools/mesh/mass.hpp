#pragma once
/// @file
/// Mass properties of a closed triangle mesh of uniform density, by exact integration over the
/// triangles (divergence theorem: the solid is a sum of signed tetrahedra, one per triangle, with
/// a common apex; each contributes closed-form volume, first and second moments).
///
/// Body-frame convention (the frame the signature tables and the runtime use):
/// - origin at the centre of mass;
/// - axes e1, e2, e3 (the columns of `principal_axes`) are the principal axes with the principal
///   moments in ascending order, I1 <= I2 <= I3;
/// - signs: e1 and e2 each have their largest-magnitude component positive (the first such
///   component on a tie), and e3 = e1 x e2, so the frame is a proper right-handed rotation;
/// - equal moments (relative difference below 1e-9): the axes are not unique, so the frame is
///   chosen to follow the mesh axes: all three equal (a cube, a sphere) -> the identity; two equal
///   -> the unique axis as above, and for the pair, the mesh axis (x, then y, then z on a tie)
///   closest to their plane, projected into it, then the cross product.
/// A point p of the mesh has body coordinates R^T (p - com), R = principal_axes.

#include "mesh/mesh.hpp"

#include <Eigen/Core>

namespace statsim::tools {

/// Density of a shape when none is given, kg/m^3 (about water, plastics, wood): `statsim mesh
/// info` and `statsim gather` both use it.
constexpr double default_density = 1000.0;

struct MassProperties {
  double volume = 0.0;                       ///< m^3 (mesh units cubed)
  double density = 1.0;                      ///< kg/m^3
  double mass = 0.0;                         ///< density * volume
  Eigen::Vector3d com = Eigen::Vector3d::Zero();            ///< centre of mass, mesh frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();        ///< inertia tensor about the COM, mesh axes
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();  ///< ascending
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity(); ///< columns e1 e2 e3, det +1
  double bounding_radius = 0.0;              ///< largest distance of a vertex from the COM
};

/// Mass properties of a closed, consistently outward-wound mesh (see validate_mesh) with uniform
/// `density`. In double precision; the integration is exact for the polyhedron (no sampling).
/// inertia == principal_axes * diag(principal_moments) * principal_axes^T up to rounding.
MassProperties compute_mass_properties(const TriMesh& mesh, double density = 1.0);

/// Principal moments and axes of a symmetric inertia tensor with the convention above.
void principal_frame(const Eigen::Matrix3d& inertia, Eigen::Vector3d& moments, Eigen::Matrix3d& axes);

/// The mesh in its body frame: vertices R^T (p - com); triangles unchanged (R is a proper
/// rotation, so the winding stays outward).
TriMesh to_body_frame(const TriMesh& mesh, const MassProperties& mp);

}  // namespace statsim::tools
