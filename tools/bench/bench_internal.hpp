// Internals of `statsim bench`: one interface for every simulated method, and the factories of
// the engines (Bullet, Box2D, statsim). Not installed; only tools/bench and its test use it.
#pragma once

#include "bench/bench.hpp"
#include "bullet/drop_world.hpp"
#include "scenes/scenes.hpp"
#include "statsim/world_def.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <chrono>
#include <ctime>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace statsim {
template <int D>
struct SignatureView;
}

namespace statsim::tools::bench {

using Clock = std::chrono::steady_clock;

inline std::int64_t elapsed_ns(Clock::time_point a, Clock::time_point b)
{
  return std::chrono::duration_cast<std::chrono::nanoseconds>(b - a).count();
}

/// CPU time this thread has used, ms (CLOCK_THREAD_CPUTIME_ID): on a shared machine it leaves out
/// the time spent waiting for a core. Read once per repeat: each read is a system call, too slow
/// to bracket single steps of a few microseconds.
inline double thread_cpu_ms()
{
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

/// Phase times of the last step, ns; negative when the engine does not report them.
struct PhaseTimes {
  std::int64_t broad = -1;   ///< broad phase (AABB update and pair search)
  std::int64_t narrow = -1;  ///< narrow phase (contact generation)
  std::int64_t collision() const { return broad < 0 || narrow < 0 ? -1 : broad + narrow; }
};

/// What a world looks like after a run (not timed): for sanity checks across methods.
struct EndState {
  std::size_t asleep = 0;
  double mean_height = 0.0;  ///< mean of the centres' up coordinate, m
  std::size_t contacts = 0;  ///< touching pairs (body-body and body-ground) the engine reports
};

/// One simulated world of one method, built from a scene. `step()` is what is timed.
class Sim {
public:
  virtual ~Sim() = default;
  virtual void step() = 0;
  virtual PhaseTimes phases() const { return {}; }
  /// Bodies asleep now (called between steps, not timed).
  virtual std::size_t asleep() const = 0;
  virtual EndState end_state() const = 0;
  /// Problems of the last step worth a note in the report (e.g. a full pair buffer); empty if none.
  virtual std::string warning() const { return {}; }
  /// Number of bodies of the scene (body i is the scene's body i).
  virtual std::size_t body_count() const { return 0; }
  /// State of body i now (centre of mass, orientation body to world, velocities in the world
  /// frame), read between steps for the fidelity measurements (`statsim fidelity`), not timed.
  virtual scenes::BodyState3 body_state(std::size_t i) const
  {
    (void)i;
    return {};
  }
  /// True when body i is asleep (Bullet: deactivated; statsim: MotionState::asleep).
  virtual bool body_asleep(std::size_t i) const
  {
    (void)i;
    return false;
  }
  /// Moves body i to state `s` and wakes it (a body poured during a run); between steps.
  /// Throws std::logic_error where a method does not support it.
  virtual void place_body(std::size_t i, const scenes::BodyState3& s)
  {
    (void)i;
    (void)s;
    throw std::logic_error("place_body: not supported by this method");
  }
  /// statsim: sampled responses applied so far (World::statistical_response_count); 0 elsewhere.
  virtual std::uint64_t statistical_responses() const { return 0; }
  /// statsim: of those, the ones the energy guard scaled down (World::energy_clamp_count).
  virtual std::uint64_t energy_clamps() const { return 0; }
  // Measurements of `statsim stress`, read between steps; NaN where a method does not give them.
  /// Kinetic energy of all bodies, J.
  virtual double kinetic_energy() const { return std::numeric_limits<double>::quiet_NaN(); }
  /// Deepest overlap now: Bullet the deepest contact point of any manifold (m); statsim between
  /// collision spheres (fraction of their radius sum).
  virtual double overlap() const { return std::numeric_limits<double>::quiet_NaN(); }
  /// Height of the lowest point of body i above z = 0, m (negative: below the ground).
  virtual double lowest(std::size_t i) const
  {
    (void)i;
    return std::numeric_limits<double>::quiet_NaN();
  }
};

/// Material and thresholds every method uses, from the statistical table (or defaults).
struct Surface {
  double restitution = 0.3;
  double friction = 0.5;
  double rolling_resistance = 0.05;   ///< statsim's dimensionless rolling resistance
  double restitution_threshold = 0.5; ///< m/s: the statsim world's (WorldDef::restitution_threshold)
  double sleep_speed = 0.05;          ///< m/s: statsim's WorldDef::sleep_speed (speed = max(|v|, |w| R))
  double sleep_time = 0.5;            ///< s: statsim's WorldDef::sleep_time
};

/// The 3D body: its geometry in the body frame (centre of mass, principal axes of the full mesh;
/// the same frame for every representation), mass properties and what the table says.
struct Body3 {
  std::string shape;                      ///< bunny, box, lshape
  std::vector<Eigen::Vector3d> full_vertices;
  std::vector<int> full_indices;          ///< 3 per triangle
  std::vector<Eigen::Vector3d> low_vertices;  ///< bunny_low.obj, in the full mesh's body frame
  std::vector<int> low_indices;
  std::vector<Eigen::Vector4d> spheres;   ///< bunny_spheres7.txt: centre (body frame), radius
  /// Boxes of box-built shapes (box: one; lshape: two): centre, rotation (columns: box axes in
  /// the body frame), half extents.
  struct Box {
    Eigen::Vector3d centre;
    Eigen::Matrix3d rotation;
    Eigen::Vector3d half_extents;
  };
  std::vector<Box> boxes;
  double bounding_radius = 0.0;           ///< m, of the full mesh about its centre of mass
  double mass = 0.0;                      ///< kg (the table's, or density 1000 x volume)
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();  ///< principal moments, kg m^2
  double sphere_radius = 0.0;             ///< radius of the `sphere` method, m
  std::string sphere_radius_note;         ///< where it comes from
  Surface surface;
  bool has_table = false;                 ///< a statistical table is compiled in for the shape
  std::string table_name;
};

/// The 2D body: the unit square.
struct Body2 {
  double half_side = 0.5;
  double bounding_radius = 0.70710678118654752;
  double mass = 1.0;
  double circle_radius = 0.0;
  std::string circle_radius_note;
  Surface surface;
  bool has_table = false;
  std::string table_name;
};

// ---- statsim (bench_statsim.cpp) -----------------------------------------------------------------
/// Fills the table-derived fields of `body` (has_table, mass, sphere radius, surface) for
/// `shape` from its committed table.
void describe_table3(const std::string& shape, Body3& body);
/// The same from tables/square2d.hpp.
void describe_table2(Body2& body);
/// Largest N the statsim worlds of the benchmark hold.
std::uint32_t statsim_capacity();
/// The runtime's default broad phase: "auto" (BroadPhase::automatic), "grid" or "sap".
std::string statsim_default_broad_phase();
/// The statistical table compiled in for `shape`; false if none.
bool statsim_table3(const std::string& shape, SignatureView<3>& out);
/// WorldDef variations of the statistical methods that `statsim fidelity` compares.
struct StatsimVariant {
  bool rest_conditions = true;     ///< WorldDef::rest_conditions
  bool independent_pairs = false;  ///< WorldDef::pair_response = independent (default: momentum)
  /// WorldDef::body_contacts as the runtime's default (`automatic`: hulls where the table has
  /// body-body data); false: collision spheres, the paper's rule.
  bool hull_contacts = true;
  /// Threads stepping the world (WorldDef::workers, through a tools::TaskPool); 1: none started.
  unsigned workers = 1;
  /// A 3D world compiled with every feature (`Features::all`) instead of the smallest set that
  /// covers the scene (statsim/features.hpp); the bits are the same either way.
  bool all_features = false;
  /// WorldDef fields set by name after the ones above, in order (`world_setting_names()`): the
  /// pile-model candidates of `statsim fidelity` ("statistical+shock_propagation=0").
  std::vector<std::pair<std::string, double>> settings;
};
/// The WorldDef fields a `StatsimVariant::settings` entry may name, with the meaning of the
/// value (booleans: 0 or 1).
const std::vector<std::pair<std::string, std::string>>& world_setting_names();
/// Throws std::invalid_argument naming the known fields when `name` is not one of them, or when
/// `value` is not one the field takes.
void check_world_setting(const std::string& name, double value);
/// The parameters of every statsim world of the bench and the fidelity tool: `WorldDef`'s defaults
/// (the library's model) but for the seed and what `variant` and `broad_phase` (as for
/// `make_statsim3`) change; `WorldDef::workers` is left to the caller.
template <int D>
WorldDef<D> statsim_world_def(std::uint64_t seed, const std::string& broad_phase, const StatsimVariant& variant);
/// A statsim world with any signature (e.g. one loaded at run time); `sig`'s storage must outlive it.
/// `walls`: static planes besides the ground (at most 7).
std::unique_ptr<Sim> make_statsim3_table(const SignatureView<3>& sig, double mass, const scenes::DropScene3& scene,
                                         std::uint64_t seed, double dt, const std::string& broad_phase,
                                         const StatsimVariant& variant, const std::vector<bullet::Plane>& walls = {});
/// A statsim world of one or two shapes (a mixed pile): body i of shape `of_body[i]` (an index
/// into `sigs` and `masses`, kg; all the first when empty), the runtime's default broad phase.
std::unique_ptr<Sim> make_statsim3_mixed(const std::vector<SignatureView<3>>& sigs, const std::vector<double>& masses,
                                          const std::vector<int>& of_body, const scenes::DropScene3& scene,
                                          std::uint64_t seed, double dt, const StatsimVariant& variant,
                                          const std::vector<bullet::Plane>& walls = {});
/// `broad_phase`: "" = the runtime's default, "grid" or "sap" (sweep-and-prune).
std::unique_ptr<Sim> make_statsim3(const Body3& body, const scenes::DropScene3& scene, std::uint64_t seed, double dt,
                                   const std::string& broad_phase, const StatsimVariant& variant);
std::unique_ptr<Sim> make_statsim2(const Body2& body, const scenes::DropScene2& scene, std::uint64_t seed, double dt,
                                   const std::string& broad_phase, const StatsimVariant& variant);

// ---- Bullet (bench_bullet.cpp) ------------------------------------------------------------------
/// Shapes shared by every Bullet world of a run (built once).
class BulletShapes;
std::shared_ptr<BulletShapes> make_bullet_shapes(const Body3& body);
/// True when `method` can be built for the body (e.g. spheres7 needs the sphere file).
bool bullet_supports(const BulletShapes& shapes, const std::string& method, std::string& why_not);
/// The benchmark's Bullet world for `method`: the table's material and thresholds, the ground
/// z = 0, `broadphase` "sap" (within the scene's bounds) or "dbvt".
bullet::DropSettings bullet_drop_settings(const Body3& body, const std::string& method, const std::string& broadphase,
                                          const scenes::DropScene3& scene);
/// A Bullet world of the benchmark's settings; step() advances it by dt.
std::unique_ptr<Sim> make_bullet(const std::shared_ptr<BulletShapes>& shapes, const std::string& method,
                                 const std::string& broadphase, const scenes::DropScene3& scene, double dt);
/// A Bullet world of other settings (e.g. bullet_drop_settings() with walls) from these states.
std::unique_ptr<Sim> make_bullet(const std::shared_ptr<BulletShapes>& shapes, const std::string& method,
                                 const bullet::DropSettings& settings, const std::vector<scenes::BodyState3>& states,
                                 double dt);
/// A Bullet world of several shapes (a mixed pile): body i of `shapes[of_body[i]]` (all the first
/// when empty), each with its own mass properties, the settings of the first.
std::unique_ptr<Sim> make_bullet_mixed(const std::vector<std::shared_ptr<BulletShapes>>& shapes,
                                              const std::vector<int>& of_body, const std::string& method,
                                              const bullet::DropSettings& settings,
                                              const std::vector<scenes::BodyState3>& states, double dt);
/// Lowest point of `method`'s representation of the body below its centre for orientation q, m:
/// the minimum over its geometry of (R p).z (negative).
double lowest_offset(const Body3& body, const std::string& method, const Eigen::Quaterniond& q);
/// Every Bullet setting the benchmark makes, one per line, for the report.
std::vector<std::string> bullet_settings(const Body3& body);

// ---- Box2D (bench_box2d.cpp) --------------------------------------------------------------------
std::unique_ptr<Sim> make_box2d(const Body2& body, const std::string& method, const scenes::DropScene2& scene,
                                double dt);
std::vector<std::string> box2d_settings(const Body2& body);

// ---- loading (bench.cpp) -------------------------------------------------------------------------
/// Loads the meshes of `shape` from `meshes_dir` into the body frame. Throws std::runtime_error.
Body3 load_body3(const std::string& shape, const std::string& meshes_dir);

}  // namespace statsim::tools::bench
