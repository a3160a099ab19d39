#include "mesh/shapes.hpp"

#include <vector>

namespace statsim::tools {

namespace {

// Extrudes the counter-clockwise polygon `profile` (in the xy plane) from z = -half_depth to
// +half_depth. Caps are triangulated as a fan from profile vertex `apex`, which must see every
// other vertex. Vertices: the profile at -half_depth, then at +half_depth.
TriMesh extrude(const std::vector<Eigen::Vector2d>& profile, int apex, double half_depth)
{
  TriMesh m;
  const int n = static_cast<int>(profile.size());
  for (double z : {-half_depth, half_depth}) {
    for (const auto& p : profile) m.vertices.emplace_back(p.x(), p.y(), z);
  }
  for (int k = 1; k + 1 < n; ++k) {
    const int b = (apex + k) % n, c = (apex + k + 1) % n;
    m.triangles.push_back({n + apex, n + b, n + c});  // top, normal +z
    m.triangles.push_back({apex, c, b});              // bottom, normal -z
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
  }
  return m;
}

}  // namespace

std::array<BoxPart, 2> lshape_boxes()
{
  return {BoxPart{Eigen::Vector3d(0.025, -0.025, 0.0), Eigen::Vector3d(0.1, 0.025, 0.025)},
          BoxPart{Eigen::Vector3d(-0.05, 0.05, 0.0), Eigen::Vector3d(0.025, 0.05, 0.025)}};
}

TriMesh make_box(const Eigen::Vector3d& size)
{
  const Eigen::Vector3d h = 0.5 * size;
  return extrude({{-h.x(), -h.y()}, {h.x(), -h.y()}, {h.x(), h.y()}, {-h.x(), h.y()}}, 0, h.z());
}

TriMesh make_wedge(double leg_x, double leg_y, double depth)
{
  // The centroid of a triangle is the mean of its corners: (leg_x / 3, leg_y / 3) from the right angle.
  const double cx = leg_x / 3.0, cy = leg_y / 3.0;
  return extrude({{-cx, -cy}, {leg_x - cx, -cy}, {-cx, leg_y - cy}}, 0, 0.5 * depth);
}

TriMesh make_lshape()
{
  // Profile, counter-clockwise: the foot spans x in [-0.075, 0.125], y in [-0.05, 0]; the upright
  // x in [-0.075, -0.025], y in [0, 0.1]. Vertex 3 (-0.025, 0) is the inner (reflex) corner,
  // which sees every other vertex.
  return extrude({{-0.075, -0.05}, {0.125, -0.05}, {0.125, 0.0}, {-0.025, 0.0}, {-0.025, 0.1}, {-0.075, 0.1}}, 3,
                 0.025);
}

}  // namespace statsim::tools
