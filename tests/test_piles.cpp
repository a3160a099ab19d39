// The pile scenes (tools/scenes/piles.hpp): builders deterministic and valid (no overlap at the
// start, stacks exactly touching), and the measurements on inputs with known answers.
#include "scenes/piles.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

using namespace statsim::tools::scenes;

namespace {

constexpr double kPi = 3.14159265358979323846;
// Touching, to the rounding of the placed coordinates (m).
constexpr double kRound = 1e-12;

bool same(const BodyState3& a, const BodyState3& b)
{
  return a.position == b.position && a.orientation.coeffs() == b.orientation.coeffs() &&
         a.linear_velocity == b.linear_velocity && a.angular_velocity == b.angular_velocity && a.asleep == b.asleep;
}

bool same(const std::vector<BodyState3>& a, const std::vector<BodyState3>& b)
{
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same(a[i], b[i])) return false;
  return true;
}

// The L-shape of tools/mesh/shapes.hpp about its centre of mass: a foot of 0.2 x 0.05 x 0.05 m
// and an upright of 0.05 x 0.1 x 0.05 m on its end (centre of mass at the origin).
std::vector<SceneBox> lshape_boxes()
{
  SceneBox foot, upright;
  foot.centre = Eigen::Vector3d(0.025, -0.025, 0);
  foot.half_extents = Eigen::Vector3d(0.1, 0.025, 0.025);
  upright.centre = Eigen::Vector3d(-0.05, 0.05, 0);
  upright.half_extents = Eigen::Vector3d(0.025, 0.05, 0.025);
  return {foot, upright};
}

std::vector<Eigen::Vector3d> corners(const std::vector<SceneBox>& boxes)
{
  std::vector<Eigen::Vector3d> out;
  for (const SceneBox& b : boxes)
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d s(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1);
      out.push_back(b.centre + b.rotation * b.half_extents.cwiseProduct(s));
    }
  return out;
}

std::vector<Eigen::Vector3d> centres_of(const std::vector<BodyState3>& bodies)
{
  std::vector<Eigen::Vector3d> c;
  for (const BodyState3& b : bodies) c.push_back(b.position);
  return c;
}

std::vector<Eigen::Quaterniond> orientations_of(const std::vector<BodyState3>& bodies)
{
  std::vector<Eigen::Quaterniond> q;
  for (const BodyState3& b : bodies) q.push_back(b.orientation);
  return q;
}

}  // namespace

TEST_CASE("piles: the heap is deterministic, and no two bodies overlap while waiting or as they are released")
{
  HeapOptions o;
  o.count = 37;
  o.bounding_radius = 0.16;
  o.seed = 5;
  const PileScene3 a = heap_scene(o), b = heap_scene(o);
  CHECK(same(a.bodies, b.bodies));
  CHECK(same(a.release, b.release));
  CHECK(a.release_time == b.release_time);
  o.seed = 6;
  CHECK_FALSE(same(heap_scene(o).release, a.release));

  REQUIRE(a.bodies.size() == 37);
  REQUIRE(a.release.size() == 37);
  REQUIRE(a.planes.size() == 1);
  CHECK(min_centre_distance(a.bodies, a.cell) >= 2 * o.bounding_radius);
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    CHECK(a.bodies[i].asleep);
    CHECK_FALSE(a.release[i].asleep);
    CHECK(a.release_time[i] == doctest::Approx(0.1 * static_cast<double>(i)));
    // Waiting bodies far above the nozzle; released ones above the ground, falling.
    CHECK(a.bodies[i].position.z() - o.bounding_radius > a.nozzle_height + 9 * a.cell);
    CHECK(a.release[i].position.z() - o.bounding_radius > 0);
    CHECK(a.release[i].linear_velocity.z() < 0);
    // Bodies released within four intervals of one another come from different points.
    for (std::size_t j = i + 1; j < a.release.size() && j < i + 4; ++j)
      CHECK((a.release[i].position - a.release[j].position).norm() >= 2 * o.bounding_radius);
    for (int k = 0; k < 3; ++k) {
      CHECK(a.bodies[i].position[k] > a.bounds_lo[k]);
      CHECK(a.bodies[i].position[k] < a.bounds_hi[k]);
    }
  }
}

TEST_CASE("piles: the bin is deterministic, its bodies apart and inside the walls")
{
  BinOptions o;
  o.count = 45;
  o.bounding_radius = 0.1;
  o.cells = 4;
  o.seed = 3;
  const PileScene3 a = bin_scene(o);
  CHECK(same(a.bodies, bin_scene(o).bodies));
  o.seed = 4;
  CHECK_FALSE(same(a.bodies, bin_scene(o).bodies));
  REQUIRE(a.bodies.size() == 45);
  REQUIRE(a.planes.size() == 5);
  CHECK(a.bin_half_width == doctest::Approx(4 * 2 * 0.1 * 1.05 / 2));
  CHECK(min_centre_distance(a.bodies, a.cell) >= 2 * o.bounding_radius);
  for (const BodyState3& b : a.bodies) {
    CHECK_FALSE(b.asleep);
    // Every plane: the bounding sphere on the inner side.
    for (const ScenePlane& p : a.planes) CHECK(p.normal.dot(b.position) - p.offset >= o.bounding_radius);
  }
}

TEST_CASE("piles: a mixed heap or bin takes two shapes in turn, its bodies those of the one-shape scene")
{
  BinOptions o;
  o.count = 45;
  o.bounding_radius = 0.1;
  const PileScene3 one = bin_scene(o);
  CHECK(one.shapes.empty());
  o.shapes = 2;
  const PileScene3 two = bin_scene(o);
  CHECK(same(one.bodies, two.bodies));
  REQUIRE(two.shapes.size() == 45);
  for (std::size_t i = 0; i < two.shapes.size(); ++i) CHECK(two.shapes[i] == int(i % 2));
  HeapOptions h;
  h.count = 7;
  h.shapes = 2;
  const PileScene3 heap = heap_scene(h);
  REQUIRE(heap.shapes.size() == 7);
  CHECK(heap.shapes[6] == 0);
  CHECK(heap.shapes[5] == 1);
  o.shapes = 3;
  CHECK_THROWS_AS(bin_scene(o), std::invalid_argument);
  h.shapes = 0;
  CHECK_THROWS_AS(heap_scene(h), std::invalid_argument);
}

TEST_CASE("piles: a column and a wall of cubes touch exactly, face to face")
{
  const std::vector<SceneBox> cube{SceneBox{Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(),
                                            Eigen::Vector3d::Constant(0.1)}};
  StackOptions o;
  o.height = 10;
  rotated_extent(corners(cube), o.orientation, o.lo, o.hi);
  const PileScene3 column = stack_scene(o);
  REQUIRE(column.bodies.size() == 10);
  CHECK(column.kind == "column");
  CHECK(column.pitch == doctest::Approx(0.2));
  // The column: top centre at 1.90 m.
  CHECK(column.bodies.back().position.z() == doctest::Approx(1.9));
  CHECK(deepest_overlap(cube, centres_of(column.bodies), orientations_of(column.bodies)) < kRound);
  const StackHold held = stack_hold(column, cube, centres_of(column.bodies), orientations_of(column.bodies));
  CHECK(held.held == doctest::Approx(1.0));
  CHECK(held.overlap < kRound);

  // Touching, not apart: 1 mm down, the body overlaps the one below by 1 mm.
  std::vector<Eigen::Vector3d> moved = centres_of(column.bodies);
  moved[5].z() -= 0.001;
  CHECK(deepest_overlap(cube, moved, orientations_of(column.bodies)) == doctest::Approx(0.001));
  // Hanging apart (the 9 cm per cube): held measures it.
  std::vector<Eigen::Vector3d> apart = centres_of(column.bodies);
  for (std::size_t i = 0; i < apart.size(); ++i) apart[i].z() += 0.09 * static_cast<double>(i);
  CHECK(stack_hold(column, cube, apart, orientations_of(column.bodies)).held == doctest::Approx((1.9 + 0.81) / 1.9));

  o.height = 5;
  o.columns = 4;
  const PileScene3 wall = stack_scene(o);
  REQUIRE(wall.bodies.size() == 20);
  CHECK(wall.kind == "wall");
  CHECK(deepest_overlap(cube, centres_of(wall.bodies), orientations_of(wall.bodies)) < kRound);
  std::vector<Eigen::Vector3d> side = centres_of(wall.bodies);
  side[7].x() -= 0.002;  // column 1 into column 0
  CHECK(deepest_overlap(cube, side, orientations_of(wall.bodies)) == doctest::Approx(0.002));
  // The ground: every lowest body's face on z = 0.
  for (int j = 0; j < 4; ++j) CHECK(wall.bodies[static_cast<std::size_t>(5 * j)].position.z() == doctest::Approx(0.1));
}

TEST_CASE("piles: L-shapes lying flat stack and stand side by side exactly touching")
{
  const std::vector<SceneBox> l = lshape_boxes();
  StackOptions o;
  o.height = 6;
  o.columns = 3;
  rotated_extent(corners(l), o.orientation, o.lo, o.hi);
  const PileScene3 wall = stack_scene(o);
  CHECK(wall.pitch == doctest::Approx(0.05));
  CHECK(wall.width == doctest::Approx(0.2));
  CHECK(deepest_overlap(l, centres_of(wall.bodies), orientations_of(wall.bodies)) < kRound);
  std::vector<Eigen::Vector3d> down = centres_of(wall.bodies);
  down[3].z() -= 0.001;
  CHECK(deepest_overlap(l, down, orientations_of(wall.bodies)) == doctest::Approx(0.001));
  std::vector<Eigen::Vector3d> left = centres_of(wall.bodies);
  left[6].x() -= 0.001;  // column 1's lowest into column 0's
  CHECK(deepest_overlap(l, left, orientations_of(wall.bodies)) == doctest::Approx(0.001));
}

TEST_CASE("piles: box penetration along faces, across a turn, and apart")
{
  const SceneBox a{Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.5, 0.5, 0.5)};
  SceneBox b = a;
  b.centre = Eigen::Vector3d(0.9, 0.2, 0);
  CHECK(box_penetration(a, b) == doctest::Approx(0.1));
  b.centre = Eigen::Vector3d(1.01, 0, 0);
  CHECK(box_penetration(a, b) == 0.0);
  // Turned 45 degrees about z: its edge reaches sqrt(2)/2 from its centre along x.
  b.rotation = Eigen::AngleAxisd(kPi / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.centre = Eigen::Vector3d(1.2, 0, 0);
  CHECK(box_penetration(a, b) == doctest::Approx(0.5 + std::sqrt(0.5) - 1.2));
  b.centre = Eigen::Vector3d(1.25, 0, 0);
  CHECK(box_penetration(a, b) == 0.0);
}

TEST_CASE("piles: the heap profile of a cone gives its angle and height")
{
  for (double degrees : {25.0, 33.0, 40.0}) {
    const double t = std::tan(degrees * kPi / 180.0);
    const double h = 1.2;
    std::vector<Eigen::Vector3d> pts;
    // The cone's surface and points inside it, on rings about (0.3, -0.2); then bodies lying
    // on the ground around it (at the height of the lowest surface point, 0).
    for (int ring = 0; ring <= 60; ++ring) {
      const double r = h / t * ring / 60.0;
      for (int k = 0; k < 24; ++k) {
        const double a = 2 * kPi * k / 24.0;
        const Eigen::Vector3d p(0.3 + r * std::cos(a), -0.2 + r * std::sin(a), h - r * t);
        pts.push_back(p);
        pts.push_back(Eigen::Vector3d(p.x(), p.y(), 0.5 * p.z()));
      }
    }
    const HeapProfile prof = heap_profile(pts, 0.05, 0.08);
    CHECK(prof.angle_deg == doctest::Approx(degrees).epsilon(1e-3));
    CHECK(prof.height == doctest::Approx(h));
    CHECK(prof.flank_bins >= 10);
  }
  // One layer: no flank, no slope.
  std::vector<Eigen::Vector3d> layer;
  for (int i = 0; i < 10; ++i) layer.push_back(Eigen::Vector3d(0.2 * i, 0, 0.1));
  CHECK(heap_profile(layer, 0.2, 0.1).angle_deg == 0.0);
}

TEST_CASE("piles: the fill height and packing fraction of known packings")
{
  // Cubes of side a filling a bin 4 a wide in 3 whole layers: H = 3 a, fraction 1.
  const double a = 0.2;
  std::vector<double> cubes, spheres;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 16; ++i) cubes.push_back((k + 0.5) * a);
  BinFill f = bin_fill(cubes, a * a * a, 16 * a * a);
  CHECK(f.fill_height == doctest::Approx(0.6));
  CHECK(f.packing == doctest::Approx(1.0));
  // Spheres of diameter a on the same simple cubic lattice: pi / 6.
  f = bin_fill(cubes, kPi / 6 * a * a * a, 16 * a * a);
  CHECK(f.packing == doctest::Approx(kPi / 6));
  // Half as many bodies in the same height: half the fraction.
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 8; ++i) spheres.push_back((k + 0.5) * a);
  CHECK(bin_fill(spheres, a * a * a, 16 * a * a).packing == doctest::Approx(0.5));
}
