// The shared scenes of the host tools: defined once here and used by the benchmark
// (`statsim bench`), the fidelity comparisons and the tests, so that every method starts from the
// same initial states.
//
// "Bunny drop" (3D, the paper's "n randomly dropped bunnies", Table 1 and Figure 6): N bodies
// with random orientations and small random linear and angular velocities, placed without
// overlapping in a vertical cylinder above the ground plane z = 0, from which they fall and pile
// up. The 2D version drops N bodies from a rectangle above the ground line y = 0.
//
// Layout (documented formula, see DropOptions):
//  - s = 2 R * spacing is the side of a cubic (square, in 2D) lattice cell, R the body's bounding
//    radius; a body's bounding sphere stays inside its cell, so no two bodies overlap;
//  - M = ceil(N / fill) cells are wanted, so about `fill` of the cells in the region are used;
//  - 3D: a cylinder of radius Rc = max(2 s, s * (M / (pi * aspect))^(1/3)) and height
//    H = aspect * Rc (its volume pi Rc^2 H is M cells), axis z, bottom at z0 = s;
//    2D: a rectangle of half width W = max(2 s, s * sqrt(M / (2 aspect))) and height
//    H = aspect * W, bottom at y0 = s;
//    so the region's linear size grows as N^(1/3) (N^(1/2) in 2D) and the footprint of the pile
//    grows more slowly than the number of bodies: they pile up. With the defaults (spacing 1.1,
//    fill 0.6, aspect 2) and the bunny (R = 0.1608 m, s = 0.354 m): Rc = 0.71, 1.06, 2.27, 4.90 m
//    and H = 1.42, 2.12, 4.55, 9.75 m for N = 10, 100, 1,000, 10,000 (bodies from 10 m up reach
//    the pile at about 14 m/s). The 2D region with aspect 2 is as tall as it is wide.
//  - the cells whose bodies (with any jitter) lie inside the region are listed, the list is
//    shuffled (Fisher-Yates) and the first N are taken (if there are fewer than N, H grows by
//    one layer at a time); the chosen cells are sorted bottom-up (z, then y, then x) so body i
//    is the i-th lowest;
//  - each body is jittered inside its cell by up to s/2 - R per axis, gets a uniformly random
//    orientation (a point drawn uniformly in the unit 4-ball by rejection, normalised: no
//    trigonometry, so it is bit-identical on every platform; 2D: a uniform angle), a velocity
//    with each component uniform in [-max_speed, max_speed] and an angular velocity with each
//    component uniform in [-max_spin, max_spin].
// Everything is drawn from one splitmix64 stream seeded with `seed`: same options, same scene,
// bit for bit, on any platform (only + - * / and sqrt on doubles, apart from the 2D angle's
// cos/sin which are not used to place anything).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace statsim::tools::scenes {

/// Deterministic random numbers for scenes: a splitmix64 stream; doubles from 53 random bits.
class SceneRng {
public:
  explicit SceneRng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();
  /// Uniform in [0, 1).
  double uniform();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform in [0, n), n > 0, unbiased (rejection).
  std::uint64_t below(std::uint64_t n);

private:
  std::uint64_t state_;
};

/// A uniformly random unit quaternion, the draw of every 3D scene: a uniform point of the unit
/// 4-ball by rejection, normalised (only + - * / and sqrt: the same bits on every platform).
Eigen::Quaterniond random_orientation(SceneRng& rng);

/// Initial state of a 3D body, SI units, world frame (z up).
struct BodyState3 {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();                ///< centre of mass, m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< body to world, unit
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();         ///< m/s
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();        ///< rad/s, world frame
  /// Starts asleep, held where it is without gravity until moved (a body waiting to be poured).
  bool asleep = false;
};

/// Initial state of a 2D body, SI units, world frame (y up).
struct BodyState2 {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();         ///< centre of mass, m
  double angle = 0.0;                                         ///< rad, counter-clockwise
  Eigen::Vector2d linear_velocity = Eigen::Vector2d::Zero();  ///< m/s
  double angular_velocity = 0.0;                              ///< rad/s, counter-clockwise
};

/// Parameters of a drop scene (see the file comment for the layout formula).
struct DropOptions {
  int count = 100;               ///< N, number of bodies, >= 1
  double bounding_radius = 0.1;  ///< R, m: farthest point of the body from its centre of mass, > 0
  std::uint64_t seed = 1;
  double spacing = 1.1;   ///< lattice cell side / (2 R), >= 1
  double fill = 0.6;      ///< fraction of the region's cells holding a body, in (0, 1]
  double aspect = 2.0;    ///< region height / radius (2D: / half width), > 0
  double max_speed = 0.5; ///< m/s, bound of each linear velocity component, >= 0
  double max_spin = 2.0;  ///< rad/s, bound of each angular velocity component, >= 0
};

/// Throws std::invalid_argument naming the first option out of range.
void validate(const DropOptions& options);

/// The 3D drop region: a cylinder with vertical axis through the origin.
struct Cylinder {
  double radius = 0.0;  ///< m
  double bottom = 0.0;  ///< z of the bottom face, m
  double height = 0.0;  ///< m
};

/// The 2D drop region: a rectangle centred on x = 0 above the ground line.
struct Rectangle {
  double half_width = 0.0;  ///< m
  double bottom = 0.0;      ///< y of the bottom edge, m
  double height = 0.0;      ///< m
};

/// A drop scene: the region (Cylinder or Rectangle), the lattice and the bodies' initial states.
template <class Region, class BodyState, int D>
struct DropScene {
  DropOptions options;
  Region region;
  double cell = 0.0;  ///< lattice cell side s, m
  std::vector<BodyState> bodies;
  /// A box that holds the scene while it runs, for broad phases that need world bounds (Bullet's
  /// btAxisSweep3): horizontally within +-(3 Rc + 1 m) (3D) or +-(3 W + 1 m) (2D), as the pile
  /// spreads beyond the region; vertically from -1 m to the region's top + 1 m.
  Eigen::Matrix<double, D, 1> bounds_lo = Eigen::Matrix<double, D, 1>::Zero();
  Eigen::Matrix<double, D, 1> bounds_hi = Eigen::Matrix<double, D, 1>::Zero();
};
using DropScene3 = DropScene<Cylinder, BodyState3, 3>;
using DropScene2 = DropScene<Rectangle, BodyState2, 2>;

/// The "bunny drop" scene (for any body of bounding radius `options.bounding_radius`).
DropScene3 drop_scene3(const DropOptions& options);
/// The 2D drop scene (squares above a ground line in the benchmark).
DropScene2 drop_scene2(const DropOptions& options);

/// One line describing a scene for reports: region, cell, velocities, seed.
std::string describe(const DropScene3& scene);
std::string describe(const DropScene2& scene);

/// Smallest distance between two body centres (grid hashing, O(N)); +infinity for N < 2.
double min_centre_distance(const std::vector<BodyState3>& bodies, double cell);
double min_centre_distance(const std::vector<BodyState2>& bodies, double cell);

}  // namespace statsim::tools::scenes
