// The Bullet drop world of the host tools: rigid bodies of one shape dropped on static planes,
// built in one place for `statsim bench`, `statsim stress`, `statsim fidelity` (through the
// benchmark) and `statsim reference-run`. The settings that make Bullet fair to a body of 20 cm are
// explained where the benchmark chooses them (tools/bench/bench_bullet.cpp); this header only
// builds what it is given. Bullet's headers stay out of it (see bullet/bullet.hpp).
#pragma once

#include "scenes/scenes.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

class btCollisionShape;

namespace statsim::tools::bullet {

/// Margin of GImpact meshes, convex hulls and boxes, m: 1% of the bunny's extent (Bullet's default
/// 0.04 m is a fifth of the body).
inline constexpr double kMargin = 0.002;

/// Collision shapes in the body frame, owned here and shared by every world built from them (a
/// GImpact shape keeps its BVH in the body frame). Each call adds a shape and returns it.
class Shapes {
public:
  Shapes();
  ~Shapes();
  Shapes(const Shapes&) = delete;
  Shapes& operator=(const Shapes&) = delete;

  /// A triangle mesh (3 indices per triangle) as a btGImpactMeshShape with margin `margin`.
  btCollisionShape* mesh(const std::vector<Eigen::Vector3d>& vertices, const std::vector<int>& indices,
                         double margin = kMargin);
  /// The convex hull of `points` (btConvexHullShape).
  btCollisionShape* hull(const std::vector<Eigen::Vector3d>& points, double margin = kMargin);
  /// A compound of spheres: centre (body frame, m) and radius (m) each.
  btCollisionShape* spheres(const std::vector<Eigen::Vector4d>& spheres);
  /// One sphere of radius `radius`, m (a sphere's margin is its radius).
  btCollisionShape* sphere(double radius);
  /// A box centred on `centre` with the axes of `rotation` (columns) and these half extents, m;
  /// several boxes make a compound. One box at the origin without rotation is a plain btBoxShape.
  struct Box {
    Eigen::Vector3d centre;
    Eigen::Matrix3d rotation;
    Eigen::Vector3d half_extents;
  };
  btCollisionShape* boxes(const std::vector<Box>& boxes, double margin = kMargin);

private:
  struct Store;
  std::unique_ptr<Store> store_;
};

/// Plane n.x = offset with n a unit vector; the bodies belong on the side n.x > offset.
struct Plane {
  Eigen::Vector3d normal;
  double offset;
};

enum class BroadPhase {
  dbvt,  ///< btDbvtBroadphase (Bullet's default)
  sap,   ///< btAxisSweep3 within the world bounds (bt32BitAxisSweep3 above 16,000 handles)
};

/// How the world is built. Material values are those of a contact: Bullet multiplies the two
/// sides' coefficients, so every body and every plane gets the square root.
struct DropSettings {
  BroadPhase broad_phase = BroadPhase::dbvt;
  Eigen::Vector3d bounds_lo = Eigen::Vector3d::Constant(-100);  ///< m, world bounds of `sap`
  Eigen::Vector3d bounds_hi = Eigen::Vector3d::Constant(100);   ///< m
  Eigen::Vector3d gravity{0, 0, -9.81};                         ///< m/s^2
  std::vector<Plane> planes{{Eigen::Vector3d(0, 0, 1), 0.0}};   ///< static, added before the bodies
  double restitution = 0.3;
  double friction = 0.5;
  /// statsim's dimensionless rolling resistance c and the radius r it acts at, m. With r > 0 the
  /// bodies get Bullet's rolling friction c r / sqrt(friction), so that against a plane the combined
  /// coefficient (rolling_a friction_b + rolling_b friction_a) is c r; r = 0: none.
  double rolling_resistance = 0.0;
  double rolling_radius = 0.0;
  double restitution_threshold = 0.5;  ///< m/s of approach below which a contact does not bounce
  /// Deactivation: linear threshold sleep_speed (m/s), angular sleep_speed / bounding radius
  /// (rad/s), for sleep_time (s, Bullet's global gDeactivationTime).
  double sleep_speed = 0.05;
  double sleep_time = 0.5;
  bool sleeping = true;           ///< false: bodies never deactivate
  bool update_all_aabbs = true;   ///< false: AABBs of static and sleeping objects are not recomputed
  int solver_iterations = 10;     ///< iterations of the sequential impulse solver per step (Bullet's default)
};

/// The dropped body: its collision shape (from Shapes) and mass properties in the body frame.
struct DropBody {
  btCollisionShape* shape = nullptr;
  double mass = 1.0;                                  ///< kg
  Eigen::Vector3d inertia = Eigen::Vector3d::Ones();  ///< principal moments, kg m^2
  double bounding_radius = 1.0;                       ///< m, about the centre of mass
};

/// One btDiscreteDynamicsWorld with the sequential impulse solver at its defaults, no CCD, the
/// planes, then one body per initial state (body i is states[i]). Collision configuration pools
/// hold max(4096, 4 N) manifolds and algorithms, so big scenes do not fall back to malloc.
class DropWorld {
public:
  DropWorld(const DropBody& body, const std::vector<scenes::BodyState3>& states, const DropSettings& settings);
  /// Bodies of several shapes: body i is `bodies[of_body[i]]` (all the first when `of_body` is
  /// empty). Throws std::invalid_argument on an index out of range.
  DropWorld(const std::vector<DropBody>& bodies, const std::vector<int>& of_body,
            const std::vector<scenes::BodyState3>& states, const DropSettings& settings);
  ~DropWorld();
  DropWorld(const DropWorld&) = delete;
  DropWorld& operator=(const DropWorld&) = delete;

  /// Advances by dt, s: one internal step (substeps 1), or `substeps` fixed steps of dt / substeps.
  void step(double dt, int substeps = 1);

  std::size_t size() const;
  /// Body i now: centre of mass, orientation (body to world), velocities in the world frame.
  scenes::BodyState3 state(std::size_t i) const;
  bool asleep(std::size_t i) const;
  /// Moves body i to `s` (centre of mass, orientation, velocities) and wakes it.
  void set_state(std::size_t i, const scenes::BodyState3& s);
  std::size_t asleep_count() const;
  /// Contact manifolds holding at least one point (touching pairs, planes included).
  std::size_t touching_pairs() const;
  /// A contact point between two dropped bodies (planes left out).
  struct BodyContact {
    std::size_t a = 0, b = 0;        ///< body indices, a < b
    Eigen::Vector3d normal;          ///< world frame, unit, from a towards b
    Eigen::Vector3d point_a, point_b;  ///< world frame, on each body, m
    double distance = 0.0;           ///< m, negative when penetrating
  };
  /// Every contact point of every body-body manifold at a distance of at most `max_distance`, m.
  std::vector<BodyContact> body_contacts(double max_distance) const;
  /// Deepest penetration of any contact point, m (0 when nothing penetrates).
  double deepest_penetration() const;
  /// Time of the last step() spent in the broad phase (AABB update and pair search) and in the
  /// narrow phase (the dispatch of the pairs), ns.
  std::int64_t broad_ns() const;
  std::int64_t narrow_ns() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace statsim::tools::bullet
