#pragma once
/// @file
/// A few-sphere approximation of a closed mesh (the paper's 7-sphere bunny).
///
/// Method (deterministic), "fitted to the surface":
/// 1. Voxelize: a grid of cell size h = (longest bounding-box extent) / resolution covering the
///    bounding box plus a margin of resolution/4 cells; each cell centre is classified inside or
///    outside the mesh by the winding number along a ray in +z (exact ray/triangle crossings).
/// 2. Sample the surface: 4 points per triangle (the centroids of its midpoint subdivision), each
///    weighted by a quarter of the triangle's area.
/// 3. Cluster: area-weighted k-means (Lloyd) of the surface samples into `count` clusters,
///    k-means++ seeding from a fixed-seed mt19937_64, 16 restarts, the lowest weighted sum of
///    squares kept. Each cluster starts a sphere at the inside cell centre nearest to its
///    centroid, with the radius that maximizes (inside cells covered) - (outside cells covered)
///    for that sphere alone: it grows while the shell it adds is mostly inside the solid.
/// 4. Fit: coordinate descent on all centres and radii (moves of 2h, h, h/2, h/4 along x, y, z and
///    the radius) minimizing E = vol(union xor solid) + integral over the mesh surface of |d(p)|,
///    d(p) = min_j (|p - c_j| - r_j) (the distance to the union's boundary, negative inside). Both
///    terms are volumes: the first balances covering the solid against protruding from it, the
///    second makes the union's boundary follow the surface, thin parts (the bunny's ears) included,
///    which the volume term alone would leave uncovered.
/// Values are then rounded to 6 decimals (1 um for a mesh in metres), and the figures below
/// describe the rounded spheres.

#include "mesh/mesh.hpp"

#include <Eigen/Core>

#include <vector>

namespace statsim::tools {

struct Sphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

struct SphereFit {
  std::vector<Sphere> spheres;
  double cell = 0.0;              ///< voxel size h
  double voxel_volume = 0.0;      ///< inside cells * h^3 (the exact volume is the mesh's)
  double coverage = 0.0;          ///< fraction of the solid's volume inside the union of spheres
  double protrusion = 0.0;        ///< volume of the union outside the solid / volume of the solid
  double max_protrusion = 0.0;    ///< largest distance from a protruding covered cell centre to the surface
  double surface_rms = 0.0;       ///< RMS distance from the surface to the union's boundary (area-weighted triangle centroids)
  double surface_mean_abs = 0.0;  ///< mean absolute distance, same samples
  double max_uncovered = 0.0;     ///< largest distance from a mesh vertex outside the union to the union
};

/// Fits `count` spheres (1..64) to a validated closed mesh; `resolution` (8..256) is the number of
/// voxels along the longest extent. Returns false with `error` set on bad arguments.
bool fit_spheres(const TriMesh& mesh, int count, int resolution, SphereFit& fit, MeshError& error);

}  // namespace statsim::tools
