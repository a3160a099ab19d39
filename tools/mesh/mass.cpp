#include "mesh/mass.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace statsim::tools {

namespace {

// Volume (times 6) and first moment (times 24) of the solid, relative to the point r: each
// triangle (a, b, c) adds the tetrahedron (r, a, b, c) of signed volume d / 6, d = a . (b x c),
// whose centroid is (a + b + c) / 4.
void volume_and_moment(const TriMesh& mesh, const Eigen::Vector3d& r, double& volume6, Eigen::Vector3d& moment24)
{
  volume6 = 0.0;
  moment24.setZero();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]] - r;
    const Eigen::Vector3d b = mesh.vertices[t[1]] - r;
    const Eigen::Vector3d c = mesh.vertices[t[2]] - r;
    const double d = a.dot(b.cross(c));
    volume6 += d;
    moment24 += d * (a + b + c);
  }
}

// Largest-magnitude component positive (the first one within rounding of the largest on a tie).
Eigen::Vector3d canonical_sign(const Eigen::Vector3d& v)
{
  const double m = v.cwiseAbs().maxCoeff();
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(v[i]) >= m * (1.0 - 1e-9)) return v[i] < 0.0 ? Eigen::Vector3d(-v) : v;
  }
  return v;
}

// The unit vector in the plane orthogonal to the unit vector n closest to a mesh axis: the
// projection of the axis (x, y, z in that order on a tie) that is longest.
Eigen::Vector3d axis_in_plane(const Eigen::Vector3d& n)
{
  int best = 0;
  double best_len = -1.0;
  for (int i = 0; i < 3; ++i) {
    const double len = 1.0 - n[i] * n[i];  // squared length of the projection of axis i
    if (len > best_len * (1.0 + 1e-9)) {
      best = i;
      best_len = len;
    }
  }
  const Eigen::Vector3d e = Eigen::Vector3d::Unit(best);
  return (e - n * n.dot(e)).normalized();
}

}  // namespace

void principal_frame(const Eigen::Matrix3d& inertia, Eigen::Vector3d& moments, Eigen::Matrix3d& axes)
{
  const Eigen::Matrix3d sym = 0.5 * (inertia + inertia.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(sym);
  moments = solver.eigenvalues();  // ascending
  const Eigen::Matrix3d v = solver.eigenvectors();
  const double tol = 1e-9 * std::max(std::fabs(moments[2]), std::numeric_limits<double>::min());
  const bool eq01 = moments[1] - moments[0] <= tol;
  const bool eq12 = moments[2] - moments[1] <= tol;
  Eigen::Vector3d e1, e2, e3;
  if (eq01 && eq12) {
    axes.setIdentity();
    return;
  }
  if (eq01) {
    e3 = canonical_sign(v.col(2).normalized());
    e1 = axis_in_plane(e3);
    e2 = e3.cross(e1);
  } else if (eq12) {
    e1 = canonical_sign(v.col(0).normalized());
    e2 = axis_in_plane(e1);
    e3 = e1.cross(e2);
  } else {
    e1 = canonical_sign(v.col(0).normalized());
    e2 = canonical_sign(v.col(1).normalized());
    e2 = (e2 - e1 * e1.dot(e2)).normalized();
    e3 = e1.cross(e2);
  }
  axes.col(0) = e1;
  axes.col(1) = e2;
  axes.col(2) = e3;
}

MassProperties compute_mass_properties(const TriMesh& mesh, double density)
{
  MassProperties mp;
  mp.density = density;
  if (mesh.triangles.empty()) return mp;

  // Pass 1, about the bounding-box centre (keeps the sums well conditioned): volume and COM.
  Eigen::Vector3d lo, hi;
  bounding_box(mesh, lo, hi);
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  double volume6 = 0.0;
  Eigen::Vector3d moment24;
  volume_and_moment(mesh, centre, volume6, moment24);
  mp.volume = volume6 / 6.0;
  mp.mass = density * mp.volume;
  mp.com = centre + moment24 / (4.0 * volume6);

  // Pass 2, about the COM: second moments C = integral of x x^T dV. For the tetrahedron
  // (0, a, b, c): C = d / 120 (a a^T + b b^T + c c^T + s s^T), s = a + b + c.
  Eigen::Matrix3d c2 = Eigen::Matrix3d::Zero();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]] - mp.com;
    const Eigen::Vector3d b = mesh.vertices[t[1]] - mp.com;
    const Eigen::Vector3d c = mesh.vertices[t[2]] - mp.com;
    const Eigen::Vector3d s = a + b + c;
    const double d = a.dot(b.cross(c));
    c2 += d * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  c2 *= density / 120.0;
  // Rounding can leave a tiny first moment about the COM; it is below 1e-15 relative and ignored.
  mp.inertia = c2.trace() * Eigen::Matrix3d::Identity() - c2;
  mp.inertia = 0.5 * (mp.inertia + mp.inertia.transpose()).eval();
  principal_frame(mp.inertia, mp.principal_moments, mp.principal_axes);

  for (const auto& p : mesh.vertices) mp.bounding_radius = std::max(mp.bounding_radius, (p - mp.com).norm());
  return mp;
}

TriMesh to_body_frame(const TriMesh& mesh, const MassProperties& mp)
{
  TriMesh out;
  out.triangles = mesh.triangles;
  out.vertices.reserve(mesh.vertices.size());
  const Eigen::Matrix3d rt = mp.principal_axes.transpose();
  for (const auto& p : mesh.vertices) out.vertices.push_back(rt * (p - mp.com));
  return out;
}

}  // namespace statsim::tools
