#pragma once
/// @file
/// Decimation of a closed mesh with meshoptimizer (meshopt_simplify: quadric-error edge
/// collapses that keep the topology, so a closed mesh stays closed).

#include "mesh/mesh.hpp"

namespace statsim::tools {

struct Decimation {
  TriMesh mesh;                       ///< the kept vertices, in their input order, and the new triangles
  std::size_t target_index_count = 0; ///< the meshopt_simplify target that gave this result
  float relative_error = 0.0f;        ///< meshoptimizer's result_error (relative to the mesh extent)
  float absolute_error = 0.0f;        ///< relative_error * meshopt_simplifyScale (mesh units)
};

/// Decimates a validated closed mesh to about `vertices` vertices: meshopt_simplify is run for
/// target triangle counts 2V-4 +- 20 (a closed genus-0 mesh of V vertices has 2V-4 triangles),
/// with no error limit, and the valid (closed, non-degenerate) result whose vertex count is
/// closest to `vertices` is kept (ties: smaller error, then fewer indices). Deterministic.
bool decimate_mesh(const TriMesh& mesh, int vertices, Decimation& out, MeshError& error);

}  // namespace statsim::tools
