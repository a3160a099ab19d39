#include "ref3d/model.hpp"

#include "mesh/shapes.hpp"
#include "bullet/bullet.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#ifndef STATSIM_MESHES_DIR
#define STATSIM_MESHES_DIR "tools/meshes"
#endif

namespace statsim::tools::ref3d {

std::uint64_t fnv1a64(const std::string& bytes)
{
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

std::string meshes_directory()
{
  return STATSIM_MESHES_DIR;
}

namespace {

// The convex hull of the mesh through Bullet's exact-integer hull: its vertices (each mapped
// back to the input vertex it came from, in input order) and its faces' outward unit normals
// and offsets (Newell's normal of each face polygon).
void convex_hull(const TriMesh& mesh, std::vector<Eigen::Vector3d>& vertices, std::vector<Eigen::Vector4d>& planes)
{
  std::vector<double> coords;
  coords.reserve(mesh.vertices.size() * 3);
  for (const auto& v : mesh.vertices) coords.insert(coords.end(), {v.x(), v.y(), v.z()});
  btConvexHullComputer hull;
  hull.compute(coords.data(), static_cast<int>(3 * sizeof(double)), static_cast<int>(mesh.vertices.size()), 0.0, 0.0);
  std::vector<int> original(static_cast<std::size_t>(hull.vertices.size()));
  for (int i = 0; i < hull.vertices.size(); ++i) {
    const Eigen::Vector3d p(hull.vertices[i].x(), hull.vertices[i].y(), hull.vertices[i].z());
    int best = 0;
    double best_d = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
      const double d = (mesh.vertices[k] - p).squaredNorm();
      if (d < best_d) {
        best_d = d;
        best = static_cast<int>(k);
      }
    }
    original[static_cast<std::size_t>(i)] = best;
  }
  std::vector<int> picked = original;
  std::sort(picked.begin(), picked.end());
  picked.erase(std::unique(picked.begin(), picked.end()), picked.end());
  vertices.clear();
  for (int k : picked) vertices.push_back(mesh.vertices[k]);
  planes.clear();
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const btConvexHullComputer::Edge* e = first;
    std::vector<Eigen::Vector3d> poly;
    do {
      poly.push_back(mesh.vertices[original[static_cast<std::size_t>(e->getSourceVertex())]]);
      e = e->getNextEdgeOfFace();
    } while (e != first && poly.size() <= static_cast<std::size_t>(hull.vertices.size()));
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < poly.size(); ++i) n += poly[i].cross(poly[(i + 1) % poly.size()]);
    if (!(n.norm() > 0)) continue;
    n.normalize();
    if (n.dot(poly[0]) < 0) n = -n;  // the origin (centre of mass) is inside: outward has a positive offset
    // Rounding noise of axis-aligned faces (a box's) becomes exact zeros.
    for (int k = 0; k < 3; ++k)
      if (std::fabs(n[k]) < 1e-12) n[k] = 0.0;
    n.normalize();
    double d = -std::numeric_limits<double>::infinity();
    for (const auto& p : poly) d = std::max(d, n.dot(p));
    planes.emplace_back(n.x(), n.y(), n.z(), d);
  }
}

std::string read_file_bytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Fills the mass properties, body-frame mesh, hull, radius and unit inertia of `m` from `mesh`.
void finish_model(ShapeModel& m, const TriMesh& mesh)
{
  m.mass = compute_mass_properties(mesh, m.density);
  m.body_mesh = to_body_frame(mesh, m.mass);
  convex_hull(m.body_mesh, m.hull, m.hull_planes);
  m.bounding_radius = 0.0;
  for (const auto& p : m.body_mesh.vertices) m.bounding_radius = std::max(m.bounding_radius, p.norm());
  m.unit_inertia = m.mass.principal_moments / m.mass.mass;
}

// A box part given in the mesh frame, moved into the body frame.
BodyBox to_body(const BoxPart& part, const MassProperties& mp)
{
  BodyBox b;
  const Eigen::Matrix3d rt = mp.principal_axes.transpose();
  b.centre = rt * (part.centre - mp.com);
  b.rotation = rt;
  b.half_extents = part.half_extents;
  return b;
}

// Checks that `mesh` is an axis-aligned box (its volume fills its bounding box) and returns its
// size; throws otherwise.
Eigen::Vector3d box_size_of(const TriMesh& mesh, const std::string& name)
{
  Eigen::Vector3d lo, hi;
  bounding_box(mesh, lo, hi);
  const Eigen::Vector3d size = hi - lo;
  const MassProperties mp = compute_mass_properties(mesh, 1.0);
  if (mesh.vertices.size() != 8 || std::fabs(mp.volume - size.prod()) > 1e-9 * size.prod())
    throw std::runtime_error(name + ": not an axis-aligned box (volume " + std::to_string(mp.volume) +
                             ", bounding box volume " + std::to_string(size.prod()) + ")");
  return size;
}

}  // namespace

ShapeModel make_box_model(const Eigen::Vector3d& size, double density, const std::string& name)
{
  ShapeModel m;
  m.name = name;
  m.kind = ShapeKind::box;
  m.density = density;
  finish_model(m, make_box(size));
  m.boxes.push_back(to_body(BoxPart{Eigen::Vector3d::Zero(), 0.5 * size}, m.mass));
  return m;
}

ShapeModel load_shape_model(const std::string& shape, const std::string& mesh_file, double density, double scale,
                            bool units_given)
{
  if (!(scale > 0) || !std::isfinite(scale)) throw std::runtime_error("--scale must be positive");
  if (!(density > 0) || !std::isfinite(density)) throw std::runtime_error("density must be positive");
  std::string path = mesh_file, label = mesh_file, name;
  if (mesh_file.empty()) {
    if (shape != "box" && shape != "lshape" && shape != "bunny")
      throw std::runtime_error("unknown shape '" + shape + "' (box, lshape, bunny, or --mesh FILE)");
    path = meshes_directory() + "/" + shape + ".obj";
    label = "tools/meshes/" + shape + ".obj";
    name = shape;
  } else {
    std::string stem = mesh_file;
    const auto slash = stem.find_last_of('/');
    if (slash != std::string::npos) stem.erase(0, slash + 1);
    const auto dot = stem.find_last_of('.');
    if (dot != std::string::npos && dot > 0) stem.erase(dot);
    name = stem.empty() ? std::string("mesh") : stem;
  }
  TriMesh mesh;
  MeshError error;
  if (!load_mesh(path, mesh, error)) throw std::runtime_error(error.message);
  if (!mesh_file.empty()) {
    if (scale != 1.0) scale_mesh(mesh, scale);
    if (!check_mesh_size(mesh, path, units_given, error)) throw std::runtime_error(error.message);
  }
  const std::string bytes = read_file_bytes(path);

  ShapeModel m;
  m.name = name;
  m.source = label;
  m.source_hash = fnv1a64(bytes);
  m.density = density;
  if (mesh_file.empty() && shape == "box") {
    const Eigen::Vector3d size = box_size_of(mesh, label);
    Eigen::Vector3d lo, hi;
    bounding_box(mesh, lo, hi);
    m.kind = ShapeKind::box;
    finish_model(m, mesh);
    m.boxes.push_back(to_body(BoxPart{0.5 * (lo + hi), 0.5 * size}, m.mass));
  } else if (mesh_file.empty() && shape == "lshape") {
    m.kind = ShapeKind::compound;
    finish_model(m, mesh);
    double parts_volume = 0.0;
    for (const BoxPart& part : lshape_boxes()) {
      m.boxes.push_back(to_body(part, m.mass));
      parts_volume += 8.0 * part.half_extents.prod();
    }
    if (std::fabs(parts_volume - m.mass.volume) > 1e-9 * parts_volume || m.mass.com.norm() > 1e-9)
      throw std::runtime_error(label + ": does not match the L-shape's two boxes (tools/mesh/shapes.hpp)");
  } else {
    m.kind = ShapeKind::mesh;
    finish_model(m, mesh);
  }
  return m;
}

// ---- free flight -----------------------------------------------------------------------------

FreeFlight::FreeFlight(const Eigen::Vector3d& unit_inertia) : inertia_(unit_inertia)
{
  const double hi = inertia_.maxCoeff(), lo = inertia_.minCoeff();
  isotropic_ = hi - lo <= 1e-12 * hi;
}

double FreeFlight::spin_bound(const RigidState& s) const
{
  if (isotropic_) return s.spin.norm();
  const Eigen::Vector3d wb = s.orientation.conjugate() * s.spin;
  return inertia_.cwiseProduct(wb).norm() / inertia_.minCoeff();
}

namespace {

// Derivative of (q, w_body) of a torque-free body: q' = q (0, w) / 2, I w' = (I w) x w.
void derivative(const Eigen::Vector3d& inertia, const Eigen::Quaterniond& q, const Eigen::Vector3d& w,
                Eigen::Quaterniond& dq, Eigen::Vector3d& dw)
{
  const Eigen::Quaterniond p = q * Eigen::Quaterniond(0.0, w.x(), w.y(), w.z());
  dq = Eigen::Quaterniond(0.5 * p.w(), 0.5 * p.x(), 0.5 * p.y(), 0.5 * p.z());
  dw = inertia.cwiseProduct(w).cross(w).cwiseQuotient(inertia);
}

Eigen::Quaterniond add(const Eigen::Quaterniond& q, const Eigen::Quaterniond& d, double h)
{
  return Eigen::Quaterniond(q.w() + h * d.w(), q.x() + h * d.x(), q.y() + h * d.y(), q.z() + h * d.z());
}

}  // namespace

RigidState FreeFlight::advance(const RigidState& s, double t) const
{
  RigidState r = s;
  r.position = s.position + s.velocity * t;
  const double w = s.spin.norm();
  if (!(t > 0) || w == 0.0) return r;
  if (isotropic_) {
    const double angle = w * t;
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(angle, s.spin / w));
    r.orientation = (turn * s.orientation).normalized();
    return r;
  }
  const double bound = spin_bound(s);
  const int n = std::max(1, static_cast<int>(std::ceil(bound * t / 0.01)));
  const double h = t / n;
  Eigen::Quaterniond q = s.orientation;
  Eigen::Vector3d wb = s.orientation.conjugate() * s.spin;
  for (int i = 0; i < n; ++i) {
    Eigen::Quaterniond k1q, k2q, k3q, k4q;
    Eigen::Vector3d k1w, k2w, k3w, k4w;
    derivative(inertia_, q, wb, k1q, k1w);
    derivative(inertia_, add(q, k1q, 0.5 * h), wb + 0.5 * h * k1w, k2q, k2w);
    derivative(inertia_, add(q, k2q, 0.5 * h), wb + 0.5 * h * k2w, k3q, k3w);
    derivative(inertia_, add(q, k3q, h), wb + h * k3w, k4q, k4w);
    q = Eigen::Quaterniond(q.w() + h / 6 * (k1q.w() + 2 * k2q.w() + 2 * k3q.w() + k4q.w()),
                           q.x() + h / 6 * (k1q.x() + 2 * k2q.x() + 2 * k3q.x() + k4q.x()),
                           q.y() + h / 6 * (k1q.y() + 2 * k2q.y() + 2 * k3q.y() + k4q.y()),
                           q.z() + h / 6 * (k1q.z() + 2 * k2q.z() + 2 * k3q.z() + k4q.z()))
            .normalized();
    wb += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
  }
  r.orientation = q;
  r.spin = q * wb;
  return r;
}

double lowest_point(const std::vector<Eigen::Vector3d>& hull, const RigidState& s)
{
  // Only the z row of the rotation matters.
  const Eigen::Matrix3d r = s.orientation.toRotationMatrix();
  const Eigen::RowVector3d row = r.row(2);
  double lo = std::numeric_limits<double>::infinity();
  for (const auto& p : hull) lo = std::min(lo, row.dot(p));
  return s.position.z() + lo;
}

FirstContact first_contact(const std::vector<Eigen::Vector3d>& hull, double hull_radius, const FreeFlight& flight,
                           const RigidState& s, double clearance, double horizon, double tolerance,
                           int max_iterations)
{
  FirstContact out;
  out.state = s;
  double gap = lowest_point(hull, s) - clearance;
  const double descent = std::max(0.0, -s.velocity.z()) + flight.spin_bound(s) * hull_radius;
  // With constant velocity the centre rises or falls linearly; if it rises faster than any
  // point can turn down, or is already too high while rising, there is no contact.
  if (gap <= tolerance) {
    out.hit = true;
    return out;
  }
  if (!(descent > 0)) return out;
  double t = 0.0;
  RigidState cur = s;
  for (int it = 0; it < max_iterations; ++it) {
    out.iterations = it + 1;
    // The centre above hull_radius + clearance while moving up: never again.
    if (s.velocity.z() >= 0 && cur.position.z() > hull_radius + clearance) return out;
    const double dt = gap / descent;
    if (t + dt > horizon) return out;
    t += dt;
    cur = flight.advance(cur, dt);
    gap = lowest_point(hull, cur) - clearance;
    if (gap <= tolerance) {
      out.hit = true;
      out.time = t;
      out.state = cur;
      return out;
    }
  }
  out.undecided = true;
  return out;
}

}  // namespace statsim::tools::ref3d
