// The bodies of the 3D reference: true geometry, mass properties and the Bullet representation
// of each shape, and the exact torque-free flight of a rigid body with its first contact with the
// ground plane z = 0.
#pragma once

#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace statsim::tools::ref3d {

/// How Bullet represents a shape.
enum class ShapeKind {
  box,       ///< one btBoxShape
  compound,  ///< a btCompoundShape of btBoxShapes (the L-shape)
  mesh,      ///< a btGImpactMeshShape of the full triangle mesh
};

/// A box of a box or compound shape, in the body frame.
struct BodyBox {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< box axes (columns) in the body frame
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
};

/// A shape ready for the reference: everything in the body frame (origin at the centre of mass,
/// axes the principal axes with ascending moments; see mesh/mass.hpp).
struct ShapeModel {
  std::string name;          ///< "box", "lshape", "bunny" or the mesh's file stem
  ShapeKind kind = ShapeKind::mesh;
  std::string source;        ///< the OBJ the true geometry comes from, as given
  std::uint64_t source_hash = 0;  ///< FNV-1a 64 of the OBJ's bytes (0 for a generated mesh)
  double density = 1000.0;   ///< kg/m^3
  MassProperties mass;       ///< of the mesh, in the mesh's frame (com, principal axes)
  TriMesh body_mesh;         ///< the true geometry in the body frame
  /// Vertices of the convex hull of `body_mesh`: the lowest point of the solid against any plane
  /// is one of them, so first contacts and rest heights are exact when computed from them.
  std::vector<Eigen::Vector3d> hull;
  /// The hull's faces: outward unit normal (x, y, z) and offset w (n . p <= w inside).
  std::vector<Eigen::Vector4d> hull_planes;
  std::vector<BodyBox> boxes;  ///< box: one; compound: its boxes; mesh: none
  double bounding_radius = 0.0;           ///< m, farthest vertex from the centre of mass
  Eigen::Vector3d unit_inertia = Eigen::Vector3d::Zero();  ///< principal moments / mass, m^2
};

/// FNV-1a, 64 bits, of a byte string.
std::uint64_t fnv1a64(const std::string& bytes);

/// The directory of the committed meshes (tools/meshes of the source tree).
std::string meshes_directory();

/// Builds the model of a built-in shape ("box", "lshape", "bunny": tools/meshes/NAME.obj) or of
/// any mesh file (`mesh_file` non-empty, `shape` ignored). Throws std::runtime_error with a message
/// naming the problem (unknown shape, unreadable or invalid mesh, a box mesh that is not a box).
/// A mesh file (`mesh_file`, any format `load_mesh` reads) is scaled by `scale`, metres per file
/// unit, and must then span 1 cm to 10 m (`check_mesh_size`) unless `units_given`.
ShapeModel load_shape_model(const std::string& shape, const std::string& mesh_file, double density,
                            double scale = 1.0, bool units_given = false);

/// A box of full size `size` (m) as a model (btBoxShape); `name` labels it.
ShapeModel make_box_model(const Eigen::Vector3d& size, double density, const std::string& name = "box");

/// Rigid-body state in the world frame (z up, ground plane z = 0).
struct RigidState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();    ///< centre of mass, m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< body to world
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();    ///< m/s
  Eigen::Vector3d spin = Eigen::Vector3d::Zero();        ///< angular velocity, rad/s, world frame
};

/// Torque-free motion without gravity (constant velocity; angular momentum conserved, the spin
/// following Euler's equations), integrated with RK4 in the body frame at a step of at most
/// 0.01 rad of rotation (exact rotation when the inertia is isotropic).
class FreeFlight {
public:
  explicit FreeFlight(const Eigen::Vector3d& unit_inertia);
  /// The state `t` seconds after `s` (t >= 0).
  RigidState advance(const RigidState& s, double t) const;
  /// An upper bound of |spin| over the whole free flight from `s` (|L| / smallest moment).
  double spin_bound(const RigidState& s) const;

private:
  Eigen::Vector3d inertia_;
  bool isotropic_ = false;
};

/// Height of the lowest point of the hull above the plane z = 0 (negative: below).
double lowest_point(const std::vector<Eigen::Vector3d>& hull, const RigidState& s);

/// The first moment the hull, in free flight from `s`, comes within `clearance` of the plane
/// z = 0 (by conservative advancement: exact up to `tolerance`, never steps over a contact).
struct FirstContact {
  bool hit = false;        ///< false: no contact within the horizon
  bool undecided = false;  ///< the iteration limit was reached before a decision
  double time = 0.0;       ///< s after `s`
  RigidState state;        ///< the state at `time` (when hit)
  int iterations = 0;
};
FirstContact first_contact(const std::vector<Eigen::Vector3d>& hull, double hull_radius, const FreeFlight& flight,
                           const RigidState& s, double clearance, double horizon, double tolerance,
                           int max_iterations);

}  // namespace statsim::tools::ref3d
