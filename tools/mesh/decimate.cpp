#include "mesh/decimate.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

namespace statsim::tools {

bool decimate_mesh(const TriMesh& mesh, int vertices, Decimation& out, MeshError& error)
{
  const std::size_t nv = mesh.vertices.size();
  if (vertices < 4) {
    error.message = "decimation target must be at least 4 vertices, got " + std::to_string(vertices);
    return false;
  }
  if (static_cast<std::size_t>(vertices) >= nv) {
    error.message = "decimation target " + std::to_string(vertices) + " is not below the mesh's " +
                    std::to_string(nv) + " vertices";
    return false;
  }
  std::vector<float> positions(3 * nv);
  for (std::size_t i = 0; i < nv; ++i) {
    for (int d = 0; d < 3; ++d) positions[3 * i + static_cast<std::size_t>(d)] = static_cast<float>(mesh.vertices[i][d]);
  }
  std::vector<unsigned int> indices;
  indices.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (int i : t) indices.push_back(static_cast<unsigned int>(i));
  }
  const float scale = meshopt_simplifyScale(positions.data(), nv, 3 * sizeof(float));

  bool found = false;
  long best_diff = 0;
  Decimation best;
  std::vector<unsigned int> dest(indices.size());
  for (int dt = -20; dt <= 20; ++dt) {
    const long tris = 2L * vertices - 4 + dt;
    if (tris < 4) continue;
    const std::size_t target = static_cast<std::size_t>(3 * tris);
    float result_error = 0.0f;
    const std::size_t count = meshopt_simplify(dest.data(), indices.data(), indices.size(), positions.data(), nv,
                                               3 * sizeof(float), target, 1.0f, 0, &result_error);
    // Keep the vertices the result uses, in their input order.
    std::vector<int> remap(nv, -1);
    for (std::size_t k = 0; k < count; ++k) remap[dest[k]] = 0;
    Decimation d;
    for (std::size_t i = 0; i < nv; ++i) {
      if (remap[i] < 0) continue;
      remap[i] = static_cast<int>(d.mesh.vertices.size());
      d.mesh.vertices.push_back(mesh.vertices[i]);
    }
    for (std::size_t k = 0; k + 2 < count; k += 3) {
      d.mesh.triangles.push_back({remap[dest[k]], remap[dest[k + 1]], remap[dest[k + 2]]});
    }
    MeshError ignored;
    if (!validate_mesh(d.mesh, "decimated", ignored)) continue;
    d.target_index_count = target;
    d.relative_error = result_error;
    d.absolute_error = result_error * scale;
    const long diff = std::labs(static_cast<long>(d.mesh.vertices.size()) - vertices);
    const bool better = !found || diff < best_diff ||
                        (diff == best_diff && (d.relative_error < best.relative_error ||
                                               (d.relative_error == best.relative_error && count < 3 * best.mesh.triangles.size())));
    if (better) {
      found = true;
      best_diff = diff;
      best = std::move(d);
    }
  }
  if (!found) {
    error.message = "meshoptimizer could not decimate the mesh to about " + std::to_string(vertices) +
                    " vertices and keep it closed";
    return false;
  }
  out = std::move(best);
  return true;
}

}  // namespace statsim::tools
