// The pile scenes users build: a heap poured from a point, a square bin filled from above, and
// stacks (a column, a wall) placed in a rest pose; and what is measured on each once it has
// settled. Defined once here for `statsim fidelity`, the benchmark, the stress matrix, the
// pictures and the tests; every engine starts from the same states.
//
// Scenes (SI units, z up, ground plane z = 0):
//  - heap: N bodies poured one at a time from a nozzle above the origin. Body k is released at
//    t_k = k interval from one of `spots` points (1: the axis; 2, 3 or 4: the corners of a
//    segment, a triangle or a square of side s centred on the axis, taken in turn, so that a
//    spot is reused only every `spots` intervals) at the nozzle height
//    h = (1.5 + 0.75 N^(1/3)) s, s = 2 R spacing (the tip of a cone of N bodies at 30 degrees
//    stays below it), jittered by up to s/2 - R per axis, with a random orientation (as
//    drop_scene3()), a small random spin and velocity, and a downward speed `pour_speed`. Until
//    then it waits asleep (no gravity, no contact) in a lattice of cells of side s far above the
//    nozzle (its bottom 10 s above it, out of reach of any bounce); the runner moves it at t_k
//    (PileScene3::release). A stream of bodies falling from a fixed height meets the heap with
//    the same speed all along, as a poured heap does; a column released at once would hit it
//    faster and faster, splashing the last bodies over the floor.
//  - bin: four vertical walls at x, y = +-W, W = cells s / 2; N bodies in the cells of a
//    cells x cells lattice of side s inside the walls, layer after layer from z = s up (a full
//    layer before the next; within the top layer, the cells in a random order), jittered,
//    oriented and moving as above.
//  - mixed heap or bin (`shapes` = 2): the same scene, its bodies of two shapes taken in turn
//    (body i of shape i % 2: half and half, spread evenly through the pour and the layers); R is
//    the larger bounding radius of the two, so that either fits a cell.
//  - stack: `columns` columns of `height` bodies, all in one orientation (a rest pose) with no
//    velocity; in a column, each body's lowest point touches the highest point of the body below
//    (the first touches the ground); columns side by side along x, touching: the pitches are the
//    extents of the body's axis-aligned box in that orientation, exact for boxes and for prisms
//    lying on a flat face.
// Random numbers: one SceneRng stream per scene seeded with `seed` (same options, same bits).
//
// Measurements (of the final centres; see each function):
//  - heap: angle of repose from the profile of the heap's surface, heap height;
//  - bin: fill height, packing fraction;
//  - stack: top centre height held against the placed one, largest overlap of neighbours.
#pragma once

#include "scenes/scenes.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace statsim::tools::scenes {

/// A static plane n . x = offset, n a unit vector; bodies belong on the side n . x > offset.
struct ScenePlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;  ///< m
};

/// A pile scene: initial states, the static planes (the ground first) and world bounds.
struct PileScene3 {
  std::string kind;  ///< "heap", "bin", "column" or "wall"
  std::vector<BodyState3> bodies;
  std::vector<ScenePlane> planes;
  double cell = 0.0;  ///< heap, bin: lattice cell side s, m
  double bin_half_width = 0.0;  ///< bin: W, m (the walls' inner faces at x, y = +-W)
  int columns = 0;  ///< stack: number of columns (body i is in column i / height)
  int height = 0;   ///< stack: bodies per column
  double pitch = 0.0;  ///< stack: vertical distance between neighbouring centres, m
  double width = 0.0;  ///< stack: horizontal distance between neighbouring columns, m
  /// heap: the state body i is moved to (PileScene3's bodies[i] waits asleep until then) and its
  /// time, s; empty for scenes whose bodies all start where they are.
  std::vector<BodyState3> release;
  std::vector<double> release_time;
  /// heap, bin: the shape of body i (0 or 1, an index into the runner's shapes) when the scene
  /// mixes two; empty when every body is of one shape.
  std::vector<int> shapes;
  double nozzle_height = 0.0;  ///< heap: m
  double pour_speed = 0.0;     ///< heap: m/s downwards at release, besides the random velocity
  Eigen::Vector3d bounds_lo = Eigen::Vector3d::Zero();  ///< m, a box that holds the run
  Eigen::Vector3d bounds_hi = Eigen::Vector3d::Zero();
  /// The same bodies and bounds as a DropScene3 (for factories that take one).
  DropScene3 as_drop_scene() const;
};

/// Heap: `count` bodies poured from a nozzle above the origin (see the file comment).
struct HeapOptions {
  int count = 60;                ///< N, >= 1
  double bounding_radius = 0.1;  ///< R, m, > 0
  std::uint64_t seed = 1;
  int spots = 4;                 ///< release points, 1 to 4
  double interval = 0.1;         ///< s between releases, > 0
  double pour_speed = 1.0;       ///< m/s downwards at release, >= 0
  double spacing = 1.05;         ///< s / (2 R), >= 1
  double max_speed = 0.05;       ///< m/s, bound of each velocity component (besides pour_speed), >= 0
  double max_spin = 0.5;         ///< rad/s, bound of each spin component, >= 0
  int shapes = 1;                ///< 1, or 2: bodies of two shapes in turn (PileScene3::shapes)
};
/// Throws std::invalid_argument naming the first option out of range.
PileScene3 heap_scene(const HeapOptions& options);

/// Bin: `count` bodies filling a square bin of `cells` x `cells` lattice cells (file comment).
struct BinOptions {
  int count = 60;                ///< N, >= 1
  double bounding_radius = 0.1;  ///< R, m, > 0
  std::uint64_t seed = 1;
  int cells = 4;                 ///< lattice cells along each side of the bin, >= 1
  double spacing = 1.05;         ///< s / (2 R), >= 1
  double max_speed = 0.05;       ///< m/s
  double max_spin = 0.5;         ///< rad/s
  int shapes = 1;                ///< 1, or 2: bodies of two shapes in turn (PileScene3::shapes)
};
PileScene3 bin_scene(const BinOptions& options);

/// Stack: `columns` columns of `height` bodies in `orientation`, touching (file comment).
struct StackOptions {
  int height = 10;   ///< bodies per column, >= 1
  int columns = 1;   ///< 1: a column; more: a wall along x
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< body to world, unit
  /// Corners of the body's axis-aligned bounding box in `orientation`, relative to its centre of
  /// mass, m (lo < 0 < hi on every axis).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(-0.1);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(0.1);
};
PileScene3 stack_scene(const StackOptions& options);

/// The axis-aligned box of `points` (body frame, about the centre of mass) turned by q: its lowest
/// and highest corner, m.
void rotated_extent(const std::vector<Eigen::Vector3d>& points, const Eigen::Quaterniond& q, Eigen::Vector3d& lo,
                    Eigen::Vector3d& hi);

// ---- measurements -----------------------------------------------------------------------------

/// The heap's angle of repose and height from the final centres (x, y, z), m.
///  - axis: the centres' mean (x, y);
///  - profile: the plane about the axis cut into `sectors` equal angular sectors and, in each,
///    radial bins of width `bin` (m); each cell's top is its highest centre (r, z);
///  - flank of a sector: its cells from the one with the highest top outward, up to (without)
///    the first that is empty or whose top is less than `toe` above the lowest centre of all
///    (the bodies lying on the ground around the heap's foot);
///  - slope: least squares z = a + b r over the tops of every sector's flank together,
///    angle = atan(-b) in degrees (0 with fewer than 2 tops: a heap one layer high has no
///    slope). The sectors' profiles are read from the same heap, so a heap that is steeper on
///    one side than the other weighs both, and the fit has `sectors` times the points of one
///    radial profile (a heap of a hundred bodies has only a few bins along its flank);
///  - height: the highest centre, m.
struct HeapProfile {
  double angle_deg = 0.0;  ///< angle of repose, degrees
  double height = 0.0;     ///< m
  int flank_bins = 0;      ///< cells fitted
};
HeapProfile heap_profile(const std::vector<Eigen::Vector3d>& centres, double bin, double toe, int sectors = 8);

/// The bin's fill height and packing fraction from the final centre heights z_i (m):
///  - fill height H = 2 mean(z_i): the bodies fill [0, H] and, filled evenly, their centres'
///    mean lies halfway up (exact for whole layers of any lattice), without picking a top layer;
///  - packing fraction = N V / (A H), V the volume of one body (m^3), A the bin's floor area (m^2).
struct BinFill {
  double fill_height = 0.0;  ///< m
  double packing = 0.0;      ///< dimensionless
};
BinFill bin_fill(const std::vector<double>& heights, double body_volume, double floor_area);

/// A box of a shape built of boxes, in the body frame (centre of mass, principal axes).
struct SceneBox {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();     ///< m
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< columns: the box's axes
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  ///< m
};

/// Penetration depth of two boxes in the world frame (separating axis test over the 15 axes of
/// two boxes: the smallest overlap of their projections), m; 0 when they do not overlap.
double box_penetration(const SceneBox& a, const SceneBox& b);

/// The deepest overlap in a set of bodies built of `boxes` (body frame) at the given poses: the
/// largest box_penetration() between boxes of different bodies and depth of any box corner below
/// the ground z = 0, m; 0 when nothing overlaps.
double deepest_overlap(const std::vector<SceneBox>& boxes, const std::vector<Eigen::Vector3d>& centres,
                       const std::vector<Eigen::Quaterniond>& orientations);

/// A stack after its run, from the final poses of its bodies:
///  - held = (highest centre now) / (highest centre placed): 1 when the stack stands at its
///    true height, more when its bodies hang apart, less when it sinks or falls;
///  - overlap = deepest_overlap() of the bodies, m.
struct StackHold {
  double held = 0.0;     ///< dimensionless, 1 = the placed height
  double overlap = 0.0;  ///< m
};
StackHold stack_hold(const PileScene3& scene, const std::vector<SceneBox>& boxes,
                     const std::vector<Eigen::Vector3d>& centres, const std::vector<Eigen::Quaterniond>& orientations);

}  // namespace statsim::tools::scenes
