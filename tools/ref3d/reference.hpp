// The 3D reference engine: one rigid body against the ground plane z = 0 in Bullet 3 (double
// precision), with the settings that make its impacts physically sound (see ReferenceSettings).
#pragma once

#include "ref3d/model.hpp"

#include <memory>
#include <string>

struct btContactSolverInfo;

namespace statsim::tools::ref3d {

/// Ground representation in Bullet.
enum class Ground {
  plane,  ///< btStaticPlaneShape (GImpact meshes test every vertex against it)
  box,    ///< a large static btBoxShape (box-box contacts come from btBoxBoxDetector, all 4 at once)
};

/// Reference settings. Defaults and why (evidence: tools/ref3d/README.md and
/// `statsim gather --settings-check | --speed-check | --step-check`):
/// - restitution 0.3, friction 0.5 on the body, 1 and 1 on the ground (Bullet multiplies), so
///   contacts use exactly the body's values, which the signature records for V_particle+;
/// - restitution threshold 0.02 m/s (Bullet: 0.2): 0.2 makes slow secondary contacts inelastic,
///   so normalised rebounds at 0.5 m/s differed from those at 2 m/s; 0.02 is above 2 g dt, so
///   resting bodies do not bounce;
/// - dt 1 ms: the statistics no longer change when it is halved (at 1/60 s they are far off);
/// - split impulse always (Bullet splits only below 4 cm of penetration; above, Baumgarte's
///   position correction adds real velocity in proportion to the penetration, i.e. to the speed);
/// - no speculative contacts (contact processing threshold 0): a point reported before the touch
///   stops the approach a step early and the touch then sees a slower approach, losing restitution;
/// - the convex-plane manifold built 4 points at a time (Bullet: one new point per step, so a
///   face-down cube is hit on one corner and leaves spinning);
/// - 30 solver iterations, no warm starting (impacts are fresh contacts);
/// - margin 0.5 mm (Bullet: 4 cm, which GImpact adds around a mesh and GJK around a box's core);
/// - ground: a static box for box and compound shapes (btBoxBoxDetector: the whole contact face
///   at once), a plane for meshes (GImpact tests every mesh vertex against it).
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

/// Puts `s` into a Bullet world's solver, so that the impacts of `statsim gather` and the pair
/// impacts of `statsim gather-pairs` are solved alike.
void apply_solver_settings(btContactSolverInfo& info, const ReferenceSettings& s);

/// What an impact trial produced.
struct ImpactResult {
  RigidState after;        ///< at separation (or at the time limit)
  int steps = 0;
  bool time_limited = false;
  double max_penetration = 0.0;  ///< m, deepest true-geometry penetration seen after a step
};

/// The two speeds that time a drop's settling (DropResult::settle_time), m/s. A body's speed at a
/// step is the larger of its centre's and its farthest point's by spin (|w| times the bounding
/// radius), instantaneous: the runtime starts settling a body below `settle`
/// (statsim::WorldDef::settle_speed), and a body below `quiet` no longer moves visibly.
struct SettleSpeeds {
  double settle = 0.0;
  double quiet = 0.0;  ///< below `settle`
};

/// What a rest drop produced.
struct DropResult {
  RigidState rest;          ///< when it settled (or at the time limit)
  double height = 0.0;      ///< centre of mass above the plane on the true geometry, m
  double time = 0.0;        ///< s of simulation
  bool settled = false;
  /// s from the last step at the settle speed or faster (0 when none was) to the step after the
  /// last one at the quiet speed or faster, when the body stayed slower for good. A drop that did
  /// not settle, or was still that fast at its last step, counts up to the end of its run: a
  /// lower bound of its settling time.
  double settle_time = 0.0;
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
  /// `still_time` seconds), or `max_time`; its settling time measured with `speeds`, which do
  /// not change the run.
  DropResult drop(const RigidState& start, double still_speed, double still_time, double max_time,
                  const SettleSpeeds& speeds) const;

  /// A world of its own with gravity stepped by the caller, for measurements outside the
  /// gathering (`statsim fidelity --reference gather`): the same Bullet world as drop()'s (same
  /// settings, ground, gravity and rest rolling friction), one step of settings().dt per step().
  /// The Reference must outlive it; like drop(), it never deactivates the body.
  class Run {
  public:
    ~Run();
    Run(const Run&) = delete;
    Run& operator=(const Run&) = delete;
    /// Advances by settings().dt.
    void step();
    /// The body's state now.
    RigidState state() const;

  private:
    friend class Reference;
    Run();
    struct World;
    std::unique_ptr<World> world_;
    double dt_ = 0.0;
  };
  std::unique_ptr<Run> run(const RigidState& start) const;

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
