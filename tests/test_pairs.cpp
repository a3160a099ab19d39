// Body-body statistics (`statsim gather-pairs`, `gather-pairs2d`): the support map and its
// bound, the pair flights against closed forms and brute force.
#include "common/support_map.hpp"
#include "ref2d/pairs2d.hpp"
#include "ref3d/model.hpp"
#include "ref3d/pairs.hpp"

#include "support/temp_dir.hpp"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace statsim::tools;
using namespace statsim::tools::ref3d;

namespace {

// Uniform-ish unit directions: a Fibonacci sphere (deterministic, no generator).
std::vector<Eigen::Vector3d> directions(int n)
{
  std::vector<Eigen::Vector3d> out;
  const double golden = 2.399963229728653;
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt(1.0 - z * z);
    out.emplace_back(r * std::cos(golden * k), r * std::sin(golden * k), z);
  }
  return out;
}

// An icosphere of radius r (the icosahedron subdivided `levels` times), as OBJ text.
std::string icosphere_obj(double r, int levels)
{
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    const auto middle = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      return mid[key] = static_cast<int>(v.size() - 1);
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tri : f) {
      const int a = middle(tri[0], tri[1]), b = middle(tri[1], tri[2]), c = middle(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    f = next;
  }
  std::ostringstream s;
  s.precision(17);
  for (const auto& p : v) s << "v " << r * p.x() << " " << r * p.y() << " " << r * p.z() << "\n";
  for (const auto& tri : f) s << "f " << tri[0] + 1 << " " << tri[1] + 1 << " " << tri[2] + 1 << "\n";
  return s.str();
}

// Separation of two boxes (half extents h, poses) along their 15 SAT axes: the largest gap
// (negative: they overlap by at least that much along every axis).
double box_separation(const Eigen::Vector3d& h, const RigidState& a, const RigidState& b)
{
  const Eigen::Matrix3d ra = a.orientation.toRotationMatrix(), rb = b.orientation.toRotationMatrix();
  std::vector<Eigen::Vector3d> axes;
  for (int i = 0; i < 3; ++i) {
    axes.push_back(ra.col(i));
    axes.push_back(rb.col(i));
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d c = ra.col(i).cross(rb.col(j));
      if (c.norm() > 1e-9) axes.push_back(c.normalized());
    }
  }
  double gap = -1e300;
  const Eigen::Vector3d d = b.position - a.position;
  for (const auto& n : axes) {
    double pa = 0, pb = 0;
    for (int k = 0; k < 3; ++k) {
      pa += h[k] * std::fabs(n.dot(ra.col(k)));
      pb += h[k] * std::fabs(n.dot(rb.col(k)));
    }
    gap = std::max(gap, std::fabs(n.dot(d)) - pa - pb);
  }
  return gap;
}

}  // namespace

TEST_CASE("the support of a cube is the closed form, and so is its cube map")
{
  const ShapeModel cube = make_box_model(Eigen::Vector3d(0.2, 0.2, 0.2), 1000.0);
  const SupportMap3 map = SupportMap3::build(cube.hull, 9);
  for (const Eigen::Vector3d& u : directions(500)) {
    const double closed = 0.1 * (std::fabs(u.x()) + std::fabs(u.y()) + std::fabs(u.z()));
    CHECK(support(cube.hull, u) == doctest::Approx(closed).epsilon(1e-12));
    // h(p) on a face is 0.1 (1 + |a| + |b|): linear in every cell of an odd-sized grid.
    CHECK(map.lookup(u) == doctest::Approx(closed).epsilon(1e-12));
  }
  // An even grid has no node at a = 0: the cells across the kink interpolate above it.
  const SupportMap3 even = SupportMap3::build(cube.hull, 8);
  CHECK(even.lookup(Eigen::Vector3d(1, 0, 0)) > 0.1 + 1e-6);
}

TEST_CASE("the support map never falls below the hull and stays within its bound")
{
  for (const ShapeModel& m : {load_shape_model("lshape", "", 1000.0), load_shape_model("bunny", "", 1000.0),
                              make_box_model(Eigen::Vector3d(0.3, 0.03, 0.03), 1000.0)}) {
    CAPTURE(m.name);
    for (int size : {5, 9}) {
      CAPTURE(size);
      const SupportMap3 map = SupportMap3::build(m.hull, size);
      const double bound = map.error_bound(m.hull, 8);
      const SupportError e = measure_support_error(map, m.hull, 20000);
      CHECK(e.min >= -1e-12 * m.bounding_radius);
      CHECK(e.max <= bound);
      CHECK(e.mean >= 0);
    }
  }
  // 2D: the square's map is exact, the L-shape's within its bound.
  const std::vector<Eigen::Vector2d> square = {{0.5, 0.5}, {-0.5, 0.5}, {-0.5, -0.5}, {0.5, -0.5}};
  const SupportMap2 sq = SupportMap2::build(square, 9);
  for (int k = 0; k < 360; ++k) {
    const Eigen::Vector2d u(std::cos(k * 0.01745329), std::sin(k * 0.01745329));
    CHECK(sq.lookup(u) == doctest::Approx(0.5 * (std::fabs(u.x()) + std::fabs(u.y()))).epsilon(1e-12));
  }
  const std::vector<Eigen::Vector2d> tri = {{0.0, 0.0}, {1.0, 0.1}, {0.3, 0.9}};
  const SupportMap2 t = SupportMap2::build(tri, 6);
  const SupportError e = measure_support_error(t, tri, 20000);
  CHECK(e.min >= -1e-12);
  CHECK(e.max > 0);
  CHECK(e.max <= t.error_bound(tri));
}

TEST_CASE("the candidate-normal estimate is the closed form for aligned cubes and bounds rotated ones")
{
  const ShapeModel cube = make_box_model(Eigen::Vector3d(0.2, 0.2, 0.2), 1000.0);
  const std::vector<Eigen::Vector3d> faces = faces_by_area(cube);
  REQUIRE(faces.size() == 6);
  const auto exact = [&](const Eigen::Vector3d& u) { return support(cube.hull, u); };
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (const Eigen::Vector3d& e : directions(200)) {
    // Aligned cubes touch when the centre offset reaches the side along its largest component.
    const double closed = 0.2 / e.cwiseAbs().maxCoeff();
    CHECK(radial_estimate(exact, I, I, e, faces, 6) == doctest::Approx(closed).epsilon(1e-12));
    // Along e alone the support sum only bounds it from above.
    CHECK(radial_estimate(exact, I, I, e, faces, 0) >= closed - 1e-12);
  }
}

TEST_CASE("pair flights of cubes end exactly in contact, and face to face at the side")
{
  const ShapeModel cube = make_box_model(Eigen::Vector3d(0.2, 0.2, 0.2), 1000.0);
  const Eigen::Vector3d h(0.1, 0.1, 0.1);
  const std::vector<Eigen::Vector3d> faces = faces_by_area(cube);
  const auto exact = [&](const Eigen::Vector3d& u) { return support(cube.hull, u); };
  for (double spin : {0.0, 2.0}) {
    for (std::uint64_t i = 0; i < 20; ++i) {
      std::pair<RigidState, RigidState> c;
      const double d = pair_trial(cube, spin, 3, i, false, 0.0005, nullptr, &c);
      CHECK(d == doctest::Approx((c.second.position - c.first.position).norm()));
      // Brute force (separating axes): touching, neither apart nor overlapping.
      CHECK(std::fabs(box_separation(h, c.first, c.second)) < 1e-6 * cube.bounding_radius);
      // The hull bound from all face normals is never below the contact distance.
      const Eigen::Vector3d e = (c.second.position - c.first.position).normalized();
      CHECK(radial_estimate(exact, c.first.orientation.toRotationMatrix(), c.second.orientation.toRotationMatrix(), e,
                            faces, 6) >= d - 1e-6 * cube.bounding_radius);
      CHECK(d >= 0.2 - 1e-6);
      CHECK(d <= 0.2 * std::sqrt(3.0) + 1e-6);
    }
  }
}

TEST_CASE("two spheres touch at the sum of their radii")
{
  statsim::testing::TempDir dir("pairs");
  const std::string path = dir.write("sphere.obj", icosphere_obj(0.1, 3));
  const ShapeModel sphere = load_shape_model("", path, 1000.0);
  // The icosphere's vertices lie on the sphere; its faces 0.32% inside it (level 3).
  double sum = 0.0;
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double d = pair_trial(sphere, i % 2 ? 4.0 : 0.0, 5, static_cast<std::uint64_t>(i), false, 0.0005);
    CHECK(d <= 0.2 * (1 + 1e-6) + 2 * 0.0005);
    CHECK(d >= 0.2 * (1 - 0.0064));
    sum += d;
  }
  CHECK(sum / n == doctest::Approx(0.2).epsilon(0.005));
  // The pair distance `statsim gather` writes into a table (pair_distances) is the same: 2 r.
  const PairDistances table = pair_distances(sphere, {0.0, 4.0}, 6, 2.0, 0.0005, 5, 2, false);
  REQUIRE(table.mean.size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    CHECK(table.mean[k] == doctest::Approx(0.2).epsilon(0.005));
    CHECK(table.std[k] < 0.002);
  }
  CHECK(table.flights == 12);
  // Its support is the radius in every direction, so the support estimate is 2 r too.
  const auto exact = [&](const Eigen::Vector3d& u) { return support(sphere.hull, u); };
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (const Eigen::Vector3d& e : directions(50))
    CHECK(radial_estimate(exact, I, I, e, {}, 0) == doctest::Approx(0.2).epsilon(0.0064));
}

TEST_CASE("2D pair flights: squares between face and corner contact, nested L-shapes closer than their hulls")
{
  int nested = 0;
  for (std::uint64_t i = 0; i < 100; ++i) {
    const double d = pair_trial2d("square", 1.0, 7, i, false);
    CHECK(d >= 1.0 - 1e-9);
    CHECK(d <= std::sqrt(2.0) + 1e-9);
    CHECK(d == doctest::Approx(pair_trial2d("square", 1.0, 7, i, true)).epsilon(1e-9));
    const double l = pair_trial2d("lshape", 0.0, 7, i, false), hull = pair_trial2d("lshape", 0.0, 7, i, true);
    CHECK(l <= hull + 1e-9);
    nested += l < hull - 1e-3;
  }
  CHECK(nested > 10);
}

TEST_CASE("gather-pairs writes the same JSON whatever the thread count, with the proposed fields")
{
  PairOptions o;
  o.shape.shape = "box";
  o.spin_ratios = {0, 2};
  o.trials = 8;
  o.height_trials = 50;
  o.support_sizes = {3};
  o.support_size = 5;
  o.support_directions = 1000;
  o.piles = 2;
  o.pile_count = 6;
  o.pile_time = 3;
  o.bin = 1.1;  // one cell wide: a column
  o.response_trials = 6;
  o.shape.threads = 1;
  const std::string one = pairs_json(gather_pairs(o), "cmd");
  o.shape.threads = 2;
  const PairResult r = gather_pairs(o);
  CHECK(pairs_json(r, "cmd") == one);
  const nlohmann::json j = nlohmann::json::parse(one);
  CHECK(j["table"]["support"].size() == 6u * 5 * 5);
  CHECK(j["table"]["face_normals"].size() == 6u);
  CHECK(j["table"]["pair_mean"].size() == 2u);
  CHECK(j["table"]["packing_mean"].size() == 3u);
  CHECK(r.response_trials == 6);
  // The column in its narrow bin: boxes on boxes, where the estimate from the faces is exact
  // and 2 h_coll is far off.
  int upright = 0;
  for (const PilePair& p : r.pile_pairs) {
    if (p.angle_deg > 30) continue;
    ++upright;
    CHECK(p.distance == doctest::Approx(p.radial_map).epsilon(0.01));
    CHECK(p.distance < 0.8 * 2 * r.h_coll);
  }
  CHECK(upright >= 6);
}
