#include "mesh/shapes.hpp"

#include <cmath>
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

TriMesh make_nut(double across_corners, double thickness, double hole_diameter, int hole_segments)
{
  constexpr double kPi = 3.14159265358979323846;
  const double outer = 0.5 * across_corners, inner = 0.5 * hole_diameter, h = 0.5 * thickness;
  const int n = hole_segments, per_side = hole_segments / 6;
  TriMesh m;
  // Vertices: the hexagon at -h, at +h, then the hole's polygon at -h, at +h; corner k of the
  // hexagon and vertex k * per_side of the hole at angle 60 k degrees.
  for (double z : {-h, h})
    for (int k = 0; k < 6; ++k) m.vertices.emplace_back(outer * std::cos(kPi * k / 3.0), outer * std::sin(kPi * k / 3.0), z);
  for (double z : {-h, h})
    for (int k = 0; k < n; ++k)
      m.vertices.emplace_back(inner * std::cos(2.0 * kPi * k / n), inner * std::sin(2.0 * kPi * k / n), z);
  const auto hex = [](int k, int top) { return top * 6 + k % 6; };
  const auto hole = [n](int k, int top) { return 12 + top * n + k % n; };
  // The caps' rings: hexagon side k (corners k, k + 1) faces the hole's vertices k * per_side ..
  // (k + 1) * per_side; the first half are fanned from corner k, the second from corner k + 1,
  // and one triangle joins both corners to the middle one. Every triangle then spans at most 30
  // degrees about the axis, so none crosses the hole while it is narrower than the flats.
  const int half = per_side / 2;
  for (int k = 0; k < 6; ++k) {
    const int mid = k * per_side + half;
    for (int j = k * per_side; j < (k + 1) * per_side; ++j) {
      const int corner = j < mid ? k : k + 1;
      m.triangles.push_back({hex(corner, 1), hole(j + 1, 1), hole(j, 1)});  // top, normal +z
      m.triangles.push_back({hex(corner, 0), hole(j, 0), hole(j + 1, 0)});  // bottom, normal -z
    }
    m.triangles.push_back({hex(k, 1), hex(k + 1, 1), hole(mid, 1)});
    m.triangles.push_back({hex(k, 0), hole(mid, 0), hex(k + 1, 0)});
  }
  // The hexagon's sides, facing out; the hole's wall, facing the axis.
  for (int k = 0; k < 6; ++k) {
    m.triangles.push_back({hex(k, 0), hex(k + 1, 0), hex(k + 1, 1)});
    m.triangles.push_back({hex(k, 0), hex(k + 1, 1), hex(k, 1)});
  }
  for (int k = 0; k < n; ++k) {
    m.triangles.push_back({hole(k, 0), hole(k + 1, 1), hole(k + 1, 0)});
    m.triangles.push_back({hole(k, 0), hole(k, 1), hole(k + 1, 1)});
  }
  return m;
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
