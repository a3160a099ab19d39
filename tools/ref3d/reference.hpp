// The 3D reference engine: one rigid body against the ground plane z = 0 in Bullet 3 (double
// precision), with the settings that make its impacts physically sound (see ReferenceSettings).
#pragma once

#include "ref3d/model.hpp"

#include <memory>
#include <string>

namespace statsim::tools::ref3d {

/// Ground representation in Bullet.
enum class Ground {
  plane,  ///< btStaticPlaneShape (GImpact meshes test every vertex against it)
  box,    ///< a large static btBoxShape (box-box contacts come from btBoxBoxDetector, all 4 at once)
};

/// Reference settings. Defaults and why (the evidence is in the README / `gather --speed-check`):
/// - restitution 0.3, friction 0.5 (Coulomb, combined with the ground's 1: Bullet multiplies);
/// - restitution threshold 0.2 m/s (Bullet's default; the runtime's V_particle+ uses the same);
/// - dt 1/1000 s: the bunny jitters at 1/60, and the statistics no longer change when halved;
/// - 30 solver iterations, no warm starting (an impact is a fresh contact: warm starting carries
///   impulses of the previous step into a resolving contact);
/// - split impulse always on (penetration recovery never adds real velocity: with Bullet's default
///   threshold of -0.04 m, Baumgarte's position correction adds velocity for penetrations below
///   4 cm, which is most of them for a 20 cm body);
/// - margins 0.5 mm: Bullet's 4 cm default rounds a 20 cm box's corners by a fifth of its size;
/// - ground: a static box for box and compound shapes (btBoxBoxDetector gives the whole contact
///   face at once; against a plane Bullet's convex-plane algorithm adds one point per step, so a
///   face-down cube is hit on one corner and leaves spinning), a plane for meshes.
struct ReferenceSettings {
  double restitution = 0.3;
  double friction = 0.5;
  double restitution_threshold = 0.02;  ///< m/s of approach at a contact point
  double dt = 1.0 / 1000.0;            ///< s
  int solver_iterations = 30;
  bool warm_starting = false;
  bool split_impulse = true;           ///< always split (penetration threshold +inf)
  double erp = 0.2;
  double margin = 0.0005;              ///< m, of the body's Bullet shape
  bool ground_auto = true;             ///< box ground for box/compound, plane for meshes
  Ground ground = Ground::plane;       ///< used when !ground_auto
  bool multipoint_plane = true;        ///< convex-plane: 3 perturbation iterations (Bullet's option)
  bool speculative_contacts = false;   ///< Bullet's default: true
  bool mesh_hull = false;              ///< meshes as btConvexHullShape of their hull (exact against a plane)
  double gravity = 9.81;               ///< m/s^2, rest drops only
  double rest_rolling_friction = 0.0;  ///< m, Bullet's rolling and spinning friction, rest drops only
};

/// What an impact trial produced.
struct ImpactResult {
  RigidState after;        ///< at separation (or at the time limit)
  int steps = 0;
  bool time_limited = false;
  double max_penetration = 0.0;  ///< m, deepest true-geometry penetration seen after a step
};

/// What a rest drop produced.
struct DropResult {
  RigidState rest;          ///< when it settled (or at the time limit)
  double height = 0.0;      ///< centre of mass above the plane on the true geometry, m
  double time = 0.0;        ///< s of simulation
  bool settled = false;
};

/// Bullet objects for one shape (one per thread: nothing is shared between threads). Every
/// trial builds a fresh world, so a trial's result depends only on its inputs.
class Reference {
public:
  Reference(const ShapeModel& model, const ReferenceSettings& settings);
  ~Reference();
  Reference(const Reference&) = delete;
  Reference& operator=(const Reference&) = delete;

  /// No gravity: from `start` (usually at the first contact), until the body has left the
  /// ground for good (its exact free flight never comes back within the margin) or `max_time`.
  ImpactResult impact(const RigidState& start, double max_time) const;

  /// With gravity: from `start` until the body is still (its centre and its farthest point
  /// moved on average slower than `still_speed` over each of two consecutive windows of
  /// `still_time` seconds), or `max_time`.
  DropResult drop(const RigidState& start, double still_speed, double still_time, double max_time) const;

  /// The ground actually used.
  Ground ground() const { return ground_; }
  const ShapeModel& model() const { return model_; }
  const ReferenceSettings& settings() const { return settings_; }

private:
  struct Impl;
  const ShapeModel& model_;
  ReferenceSettings settings_;
  Ground ground_;
  FreeFlight flight_;
  std::unique_ptr<Impl> impl_;
};

/// The Bullet version the library was built from ("3.24").
std::string bullet_version();

}  // namespace statsim::tools::ref3d
