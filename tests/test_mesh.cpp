// tools/mesh: OBJ validation, exact mass properties, the committed meshes, the `mesh` commands.
// Runs with the repository root as working directory (reads tools/meshes/*).
#include "mesh/decimate.hpp"
#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "mesh/mesh_commands.hpp"
#include "mesh/shapes.hpp"
#include "mesh/spheres.hpp"
#include "support/temp_dir.hpp"

#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace statsim::tools;

using namespace statsim::testing;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Closed-form inertia of a solid box of unit density about its centre.
Eigen::Vector3d box_inertia(const Eigen::Vector3d& size)
{
  const double m = size.prod();
  const Eigen::Vector3d s2 = size.cwiseProduct(size);
  return m / 12.0 * Eigen::Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
}

// Unit icosphere: the icosahedron subdivided `levels` times, vertices projected on the sphere.
TriMesh icosphere(int levels)
{
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriMesh m;
  for (const auto& v : {Eigen::Vector3d(-1, t, 0), Eigen::Vector3d(1, t, 0), Eigen::Vector3d(-1, -t, 0),
                        Eigen::Vector3d(1, -t, 0), Eigen::Vector3d(0, -1, t), Eigen::Vector3d(0, 1, t),
                        Eigen::Vector3d(0, -1, -t), Eigen::Vector3d(0, 1, -t), Eigen::Vector3d(t, 0, -1),
                        Eigen::Vector3d(t, 0, 1), Eigen::Vector3d(-t, 0, -1), Eigen::Vector3d(-t, 0, 1)}) {
    m.vertices.push_back(v.normalized());
  }
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
      const int i = static_cast<int>(m.vertices.size()) - 1;
      mid[key] = i;
      return i;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& f : m.triangles) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    m.triangles = next;
  }
  return m;
}

TriMesh transformed(const TriMesh& m, const Eigen::Matrix3d& r, const Eigen::Vector3d& t)
{
  TriMesh out = m;
  for (auto& v : out.vertices) v = r * v + t;
  return out;
}

void check_frame(const MassProperties& mp)
{
  const Eigen::Matrix3d& r = mp.principal_axes;
  CHECK((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-12);
  CHECK(r.determinant() == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(mp.principal_moments[0] <= mp.principal_moments[1]);
  CHECK(mp.principal_moments[1] <= mp.principal_moments[2]);
  const Eigen::Matrix3d rebuilt = r * mp.principal_moments.asDiagonal() * r.transpose();
  CHECK((rebuilt - mp.inertia).norm() <= 1e-12 * mp.inertia.norm());
}

const char* kTet =
  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
  "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

}  // namespace

TEST_CASE("mass properties of a meshed box equal the closed form")
{
  for (const Eigen::Vector3d& size : {Eigen::Vector3d(0.2, 0.2, 0.2), Eigen::Vector3d(1, 2, 4)}) {
    CAPTURE(size.transpose());
    const TriMesh box = make_box(size);
    CHECK(box.vertices.size() == 8);
    CHECK(box.triangles.size() == 12);
    MeshError e;
    REQUIRE(validate_mesh(box, "box", e));
    const double density = 750.0;
    const MassProperties mp = compute_mass_properties(box, density);
    const double volume = size.prod();
    CHECK(mp.volume == doctest::Approx(volume).epsilon(1e-14));
    CHECK(mp.mass == doctest::Approx(density * volume).epsilon(1e-14));
    CHECK(mp.com.norm() < 1e-15);
    const Eigen::Vector3d expected = density * box_inertia(size);
    for (int i = 0; i < 3; ++i) {
      CHECK(mp.inertia(i, i) == doctest::Approx(expected[i]).epsilon(1e-13));
      for (int j = 0; j < 3; ++j) {
        if (i != j) CHECK(std::fabs(mp.inertia(i, j)) < 1e-14 * expected.maxCoeff());
      }
    }
    CHECK(mp.bounding_radius == doctest::Approx(0.5 * size.norm()).epsilon(1e-14));
    check_frame(mp);
  }

  // 1 x 2 x 4: moments ascending -> e1 along the 4 m axis (z), e2 along y, e3 = e1 x e2 = -x.
  const MassProperties mp = compute_mass_properties(make_box({1, 2, 4}));
  CHECK(mp.principal_moments[0] == doctest::Approx(8.0 * (1 + 4) / 12.0));
  CHECK(mp.principal_moments[1] == doctest::Approx(8.0 * (1 + 16) / 12.0));
  CHECK(mp.principal_moments[2] == doctest::Approx(8.0 * (4 + 16) / 12.0));
  CHECK((mp.principal_axes.col(0) - Eigen::Vector3d::UnitZ()).norm() < 1e-12);
  CHECK((mp.principal_axes.col(1) - Eigen::Vector3d::UnitY()).norm() < 1e-12);
  CHECK((mp.principal_axes.col(2) + Eigen::Vector3d::UnitX()).norm() < 1e-12);
  // A cube's moments are all equal: the body frame is the mesh frame.
  CHECK((compute_mass_properties(make_box({0.2, 0.2, 0.2})).principal_axes - Eigen::Matrix3d::Identity()).norm() == 0.0);
}

TEST_CASE("mass properties follow a moved and rotated mesh; the body frame undoes it")
{
  const TriMesh box = make_box({1, 2, 4});
  const Eigen::Matrix3d r =
    (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) * Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
  const Eigen::Vector3d t(10.0, -5.0, 3.0);
  const TriMesh moved = transformed(box, r, t);
  MeshError e;
  REQUIRE(validate_mesh(moved, "moved", e));
  const MassProperties a = compute_mass_properties(box);
  const MassProperties b = compute_mass_properties(moved);
  CHECK(b.volume == doctest::Approx(a.volume).epsilon(1e-12));
  CHECK((b.com - t).norm() < 1e-12);
  CHECK((b.inertia - r * a.inertia * r.transpose()).norm() < 1e-12 * a.inertia.norm());
  CHECK((b.principal_moments - a.principal_moments).norm() < 1e-12 * a.principal_moments.norm());
  CHECK(b.bounding_radius == doctest::Approx(a.bounding_radius).epsilon(1e-12));
  check_frame(b);
  // In the body frame the box is axis-aligned, centred, longest side along e1.
  const TriMesh body = to_body_frame(moved, b);
  Eigen::Vector3d lo, hi;
  bounding_box(body, lo, hi);
  CHECK((hi - lo - Eigen::Vector3d(4, 2, 1)).norm() < 1e-9);
  CHECK((hi + lo).norm() < 1e-9);
  REQUIRE(validate_mesh(body, "body", e));  // still outward
  const MassProperties c = compute_mass_properties(body);
  CHECK(c.com.norm() < 1e-12);
  CHECK((c.inertia - Eigen::Matrix3d(c.principal_moments.asDiagonal())).norm() < 1e-12);
}

TEST_CASE("a unit icosphere has the sphere's volume and inertia within the discretization bounds")
{
  double previous_error = 1.0;
  for (int levels = 2; levels <= 4; ++levels) {
    CAPTURE(levels);
    const TriMesh s = icosphere(levels);
    MeshError e;
    REQUIRE(validate_mesh(s, "icosphere", e));
    const MassProperties mp = compute_mass_properties(s);
    // The inscribed polyhedron lies between the ball of radius r_in (the smallest distance from
    // the centre to a face plane) and the unit ball, so volume and each diagonal inertia entry
    // (integrals of positive functions) lie between those of the two balls.
    double r_in = 1.0;
    for (const auto& f : s.triangles) {
      const Eigen::Vector3d n =
        (s.vertices[f[1]] - s.vertices[f[0]]).cross(s.vertices[f[2]] - s.vertices[f[0]]).normalized();
      r_in = std::min(r_in, std::fabs(n.dot(s.vertices[f[0]])));
    }
    auto ball_volume = [](double r) { return 4.0 / 3.0 * kPi * r * r * r; };
    auto ball_inertia = [&](double r) { return 0.4 * ball_volume(r) * r * r; };  // 2/5 m r^2
    CHECK(mp.volume >= ball_volume(r_in));
    CHECK(mp.volume <= ball_volume(1.0));
    CHECK(mp.com.norm() < 1e-14);
    for (int i = 0; i < 3; ++i) {
      CHECK(mp.inertia(i, i) >= ball_inertia(r_in));
      CHECK(mp.inertia(i, i) <= ball_inertia(1.0));
    }
    // Icosahedral symmetry makes the inertia isotropic; the body frame is then the mesh frame.
    CHECK(mp.principal_moments[2] - mp.principal_moments[0] < 1e-12 * mp.principal_moments[2]);
    CHECK((mp.principal_axes - Eigen::Matrix3d::Identity()).norm() == 0.0);
    CHECK(mp.bounding_radius == doctest::Approx(1.0).epsilon(1e-14));
    // 2/5 m r^2 with the polyhedron's own mass: within the same bounds, and converging.
    const double ratio = mp.principal_moments[0] / (0.4 * mp.mass);
    CHECK(ratio <= 1.0);
    CHECK(ratio >= r_in * r_in * ball_volume(r_in) / ball_volume(1.0));
    const double error = std::fabs(mp.volume / ball_volume(1.0) - 1.0);
    CHECK(error < previous_error / 3.0);
    previous_error = error;
  }
  CHECK(previous_error < 0.005);  // level 4: 2562 vertices
}

TEST_CASE("the committed meshes")
{
  MeshError e;
  TriMesh bunny;
  REQUIRE_MESSAGE(load_obj("tools/meshes/bunny.obj", bunny, e), e.message);
  CHECK(bunny.vertices.size() == 1839);
  CHECK(bunny.triangles.size() == 3674);
  const MassProperties b = compute_mass_properties(bunny);
  CHECK(b.volume > 0.0);
  CHECK(b.com.norm() < 1e-9);  // at the origin up to the 1 nm rounding of the coordinates
  Eigen::Vector3d lo, hi;
  bounding_box(bunny, lo, hi);
  CHECK((hi - lo).maxCoeff() == doctest::Approx(0.2).epsilon(1e-7));
  check_frame(b);

  TriMesh low;
  REQUIRE_MESSAGE(load_obj("tools/meshes/bunny_low.obj", low, e), e.message);  // closed, or it would not load
  CHECK(low.vertices.size() >= 90);
  CHECK(low.vertices.size() <= 110);
  const MassProperties l = compute_mass_properties(low);
  CHECK(l.volume > 0.85 * b.volume);
  CHECK(l.volume < 1.05 * b.volume);

  TriMesh box;
  REQUIRE_MESSAGE(load_obj("tools/meshes/box.obj", box, e), e.message);
  const MassProperties bx = compute_mass_properties(box);
  CHECK(bx.volume == doctest::Approx(0.008).epsilon(1e-12));
  CHECK(bx.principal_moments[0] == doctest::Approx(box_inertia({0.2, 0.2, 0.2})[0]).epsilon(1e-12));

  // The L-shape mesh and its two Bullet boxes describe the same solid.
  TriMesh lshape;
  REQUIRE_MESSAGE(load_obj("tools/meshes/lshape.obj", lshape, e), e.message);
  const MassProperties ls = compute_mass_properties(lshape);
  double volume = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (const BoxPart& part : lshape_boxes()) {
    const Eigen::Vector3d size = 2.0 * part.half_extents;
    const double m = size.prod();
    volume += m;
    moment += m * part.centre;
    const Eigen::Vector3d& c = part.centre;
    inertia += Eigen::Matrix3d(box_inertia(size).asDiagonal()) +
               m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  }
  CHECK(ls.volume == doctest::Approx(volume).epsilon(1e-12));
  CHECK(ls.volume == doctest::Approx(0.00075).epsilon(1e-12));
  CHECK(moment.norm() < 1e-15);  // the boxes are placed about the centre of mass
  CHECK(ls.com.norm() < 1e-15);
  CHECK((ls.inertia - inertia).norm() < 1e-12 * inertia.norm());

  // The nut: a hexagonal prism (area 3 sqrt(3)/2 R^2) less a 24-gon hole (area 12 r^2 sin 15 deg),
  // 0.05 thick; symmetric about its centre; equal moments about the two axes across the hole.
  TriMesh nut;
  REQUIRE_MESSAGE(load_obj("tools/meshes/nut.obj", nut, e), e.message);
  CHECK(nut.vertices.size() == 12 + 48);
  const MassProperties nm = compute_mass_properties(nut);
  const double hexagon = 1.5 * std::sqrt(3.0) * 0.06 * 0.06, hole = 12.0 * 0.03 * 0.03 * std::sin(3.14159265358979 / 12);
  CHECK(nm.volume == doctest::Approx((hexagon - hole) * 0.05).epsilon(1e-9));
  CHECK(nm.com.norm() < 1e-12);
  CHECK(nm.principal_moments[0] == doctest::Approx(nm.principal_moments[1]).epsilon(1e-9));
  CHECK(nm.principal_moments[2] > nm.principal_moments[1]);
  bounding_box(nut, lo, hi);
  CHECK((hi - lo).x() == doctest::Approx(0.12).epsilon(1e-12));
  CHECK((hi - lo).y() == doctest::Approx(0.12 * std::sqrt(3.0) / 2).epsilon(1e-9));
  CHECK((hi - lo).z() == doctest::Approx(0.05).epsilon(1e-12));
  std::ostringstream out, err;
  CHECK(mesh_nut(0.12, 0.05, 0.11, 24, "unused.obj", out, err) != 0);  // the hole would cut the flats
  CHECK(mesh_nut(0.12, 0.05, 0.06, 18, "unused.obj", out, err) != 0);
  CHECK_FALSE(fs::exists("unused.obj"));

  // 7 spheres: "x y z r" lines after the comments.
  std::istringstream spheres(read_file("tools/meshes/bunny_spheres7.txt"));
  std::string line;
  int count = 0;
  while (std::getline(spheres, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    double x, y, z, r;
    REQUIRE(static_cast<bool>(in >> x >> y >> z >> r));
    CHECK(r > 0.01);
    CHECK(r < 0.1);
    CHECK(Eigen::Vector3d(x, y, z).norm() < b.bounding_radius);
    ++count;
  }
  CHECK(count == 7);
}

TEST_CASE("bad meshes are rejected with a message naming the problem")
{
  TempDir dir("mesh");
  struct Case {
    const char* name;
    std::string text;
    std::string expect;  // substring of the message
  };
  const std::vector<Case> cases = {
    {"empty", "", "no faces"},
    {"comment-only", "# nothing\n", "no faces"},
    {"unknown-statement", std::string(kTet) + "bogus 1 2 3\n", ":9: unparsable line: unknown or unsupported statement 'bogus'"},
    {"bad-number", "v 0 0 0\nv 1 0 0\nv 0 1 zero\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
     ":3: unparsable 'v' line: 'zero' is not a number"},
    {"too-few-coordinates", "v 0 0\n" + std::string(kTet), ":1: unparsable 'v' line: expected"},
    {"binary", "v 0 0 0\n\x7f" "ELF\x01\x02\n", ":2: unparsable line: unknown or unsupported statement"},
    {"nul-byte", std::string("v 0 0 0\nv 1\0 0 0\n", 17), ":2: unparsable line: contains a NUL byte"},
    {"nan", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 nan\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
     ":4: vertex coordinate 'nan' is not finite"},
    {"inf", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 -inf\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n", ":4: vertex coordinate '-inf' is not finite"},
    {"overflow", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e999\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n", "is not finite"},
    {"index-too-large", std::string(kTet) + "f 1 2 5\n", ":9: face index out of range: vertex index 5"},
    {"index-zero", std::string(kTet) + "f 0 1 2\n", ":9: unparsable face vertex '0'"},
    {"negative-index-out-of-range", std::string(kTet) + "f -1 -2 -5\n", ":9: face index out of range: vertex index -5"},
    {"bad-face-token", std::string(kTet) + "f 1 2 x\n", ":9: unparsable face vertex 'x'"},
    {"two-vertex-face", std::string(kTet) + "f 1 2\n", ":9: face with 2 vertices"},
    {"texcoord-out-of-range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1/1 3/1 2/1\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
     ":5: face index out of range: texture coordinate index 1"},
    {"degenerate", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
     ":5: degenerate (zero-area) triangle"},
    {"repeated-vertex", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 1 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n", "degenerate (zero-area)"},
    {"open", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n", "open surface (has a hole)"},
    {"non-manifold",
     std::string(kTet) + "v 0 0 -1\nf 1 2 5\nf 2 3 5\nf 3 1 5\n", "non-manifold surface: edge between vertices"},
    {"inconsistent-winding", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
     ":5: inconsistently wound surface: edge between vertices 1 and 2"},
    {"negative-volume", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 2 4 3\nf 1 3 4\n",
     "negative volume -0.166667: the faces are wound clockwise seen from outside (inward normals)"},
    {"zero-volume", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n", "zero volume"},
    {"tinyobj-error", std::string(kTet) + "l 0 1\n", "tinyobjloader: Failed parse `l' line"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    const std::string path = dir.write(std::string(c.name) + ".obj", c.text);
    TriMesh m;
    MeshError e;
    CHECK_FALSE(load_obj(path, m, e));
    CAPTURE(e.message);
    CHECK(e.message.rfind(path, 0) == 0);  // names the file
    CHECK(e.message.find(c.expect) != std::string::npos);
  }

  TriMesh m;
  MeshError e;
  CHECK_FALSE(load_obj((dir.path / "missing.obj").string(), m, e));
  CHECK(e.message.find("cannot open mesh file: No such file or directory") != std::string::npos);
  CHECK_FALSE(load_obj(dir.path.string(), m, e));
  CHECK(e.message.find("is a directory") != std::string::npos);

  // In-memory meshes: the same checks, indices instead of lines.
  TriMesh bad = make_box({1, 1, 1});
  bad.vertices[3].x() = std::nan("");
  CHECK_FALSE(validate_mesh(bad, "mem", e));
  CHECK(e.message == "mem: vertex index 3 has a non-finite coordinate (NaN or infinite)");
  bad = make_box({1, 1, 1});
  bad.triangles[2][1] = 8;
  CHECK_FALSE(validate_mesh(bad, "mem", e));
  CHECK(e.message == "mem: face index out of range: triangle index 2 uses vertex index 8 (8 vertices)");
}

TEST_CASE("OBJ features: CRLF, quads, n-gons, negative indices, groups, materials, unused vertices")
{
  TempDir dir("mesh");
  const std::string cube =
    "# a cube of quads\r\nmtllib missing.mtl\r\nv -1 -1 -1\r\nv 1 -1 -1\r\nv 1 1 -1\r\nv -1 1 -1\r\n"
    "v -1 -1 1\r\nv 1 -1 1\r\nv 1 1 1\r\nv -1 1 1\r\nv 5 5 5\r\nvn 0 0 1\r\nvt 0 0\r\no cube\r\nusemtl red\r\n"
    "f 1 4 3 2\r\nf 5 6 7 8\r\ng side\r\ns 1\r\nf 1 2 6 5\r\nf 2/1 3/1 7/1 6/1\r\nf 3//1 4//1 8//1 7//1\r\n"
    "f -9 -5 -2 -6\r\n";
  TriMesh m;
  MeshError e;
  REQUIRE_MESSAGE(load_obj(dir.write("cube.obj", cube), m, e), e.message);
  CHECK(m.vertices.size() == 8);  // the unused vertex (5, 5, 5) is dropped
  CHECK(m.triangles.size() == 12);
  const MassProperties mp = compute_mass_properties(m);
  CHECK(mp.volume == doctest::Approx(8.0));
  CHECK(mp.bounding_radius == doctest::Approx(std::sqrt(3.0)));

  // A non-convex hexagon (an L) as one face per cap: ear clipping, not a fan.
  const std::string l =
    "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n"
    "v 0 0 1\nv 2 0 1\nv 2 1 1\nv 1 1 1\nv 1 2 1\nv 0 2 1\n"
    "f 6 5 4 3 2 1\nf 7 8 9 10 11 12\nf 1 2 8 7\nf 2 3 9 8\nf 3 4 10 9\nf 4 5 11 10\nf 5 6 12 11\nf 6 1 7 12\n";
  REQUIRE_MESSAGE(load_obj(dir.write("l.obj", l), m, e), e.message);
  CHECK(m.triangles.size() == 20);
  CHECK(compute_mass_properties(m).volume == doctest::Approx(3.0));
  CHECK((compute_mass_properties(m).com - Eigen::Vector3d(5.0 / 6.0, 5.0 / 6.0, 0.5)).norm() < 1e-12);

  // Written and read back unchanged.
  const TriMesh lshape = make_lshape();
  REQUIRE(write_file_atomic((dir.path / "w.obj").string(), obj_text(lshape, {"test"}), e));
  REQUIRE_MESSAGE(load_obj((dir.path / "w.obj").string(), m, e), e.message);
  CHECK(m.triangles == lshape.triangles);
  // tinyobjloader's number parser is not always correctly rounded: within a few ulps.
  for (std::size_t i = 0; i < m.vertices.size(); ++i) CHECK((m.vertices[i] - lshape.vertices[i]).norm() < 1e-16);
  CHECK(format_number(-0.0) == "0");
  CHECK(format_number(0.1) == "0.1");
  CHECK(format_number(-0.075) == "-0.075");
}

TEST_CASE("mesh commands: outputs, determinism, and no output file on failure")
{
  TempDir dir("mesh");
  std::ostringstream out, err;

  // Bad inputs: non-zero exit, the message, and nothing written (no output, no temporary).
  const std::string open = dir.write("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n");
  const std::string nan = dir.write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 NaN\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n");
  const auto before = dir.entries();
  const std::string target = (dir.path / "out.obj").string();
  for (const std::string& bad : {open, nan, (dir.path / "missing.obj").string()}) {
    CAPTURE(bad);
    err.str("");
    CHECK(mesh_info(bad, 1.0, out, err) != 0);
    CHECK(err.str().find(bad) != std::string::npos);
    err.str("");
    CHECK(mesh_decimate(bad, target, 100, out, err) != 0);
    CHECK(err.str().rfind("statsim mesh decimate: " + bad, 0) == 0);
    CHECK(mesh_spheres(bad, target, 7, 64, out, err) != 0);
    CHECK(dir.entries() == before);
  }
  CHECK(err.str().find("No such file or directory") != std::string::npos);
  // Bad options: same.
  CHECK(mesh_box({0.2, -1.0, 0.2}, target, out, err) != 0);
  CHECK(mesh_decimate("tools/meshes/box.obj", target, 100, out, err) != 0);  // 8 vertices: nothing to remove
  CHECK(mesh_spheres("tools/meshes/box.obj", target, 0, 64, out, err) != 0);
  CHECK(dir.entries() == before);
  // An output directory that does not exist: an error, nothing written.
  CHECK(mesh_lshape((dir.path / "no" / "such" / "l.obj").string(), out, err) != 0);
  CHECK(err.str().find("cannot create output file") != std::string::npos);
  CHECK(dir.entries() == before);
  // A failing command leaves an existing output untouched.
  const std::string existing = dir.write("existing.obj", "keep");
  CHECK(mesh_decimate(open, existing, 100, out, err) != 0);
  CHECK(read_file(existing) == "keep");

  // Good runs: the box and the L-shape load back with the right volumes.
  const std::string box = (dir.path / "box.obj").string();
  REQUIRE(mesh_box({1, 2, 4}, box, out, err) == 0);
  TriMesh m;
  MeshError e;
  REQUIRE(load_obj(box, m, e));
  CHECK(compute_mass_properties(m).volume == doctest::Approx(8.0));
  CHECK(read_file(box).find("# Regenerate: build/bin/statsim mesh box --size 1,2,4 --out " + box) != std::string::npos);

  // The committed derived meshes are what the current code generates (up to the output path in
  // the header): regenerate into the temporary directory and compare.
  auto strip = [](const std::string& text, const std::string& path) {
    std::istringstream in(text);
    std::string line, kept;
    while (std::getline(in, line)) {
      if (line.find(path) == std::string::npos && line.find(fs::path(path).filename().string()) == std::string::npos) {
        kept += line + "\n";
      }
    }
    return kept;
  };
  const std::vector<std::pair<std::string, std::function<int(const std::string&)>>> derived = {
    {"tools/meshes/box.obj", [&](const std::string& o) { return mesh_box({0.2, 0.2, 0.2}, o, out, err); }},
    {"tools/meshes/lshape.obj", [&](const std::string& o) { return mesh_lshape(o, out, err); }},
    {"tools/meshes/nut.obj", [&](const std::string& o) { return mesh_nut(0.12, 0.05, 0.06, 24, o, out, err); }},
    {"tools/meshes/bunny_low.obj",
     [&](const std::string& o) { return mesh_decimate("tools/meshes/bunny.obj", o, 100, out, err); }},
    {"tools/meshes/bunny_spheres7.txt",
     [&](const std::string& o) { return mesh_spheres("tools/meshes/bunny.obj", o, 7, 64, out, err); }},
  };
  for (const auto& [committed, generate] : derived) {
    CAPTURE(committed);
    const std::string fresh = (dir.path / fs::path(committed).filename()).string();
    REQUIRE(generate(fresh) == 0);
    const std::string a = strip(read_file(committed), committed);
    const std::string b = strip(read_file(fresh), fresh);
    CHECK(a.size() > 100);
    CHECK(a == b);
    // Twice gives the same bytes (the sphere fit, the slow one, is compared with the committed file only).
    if (committed.find("spheres") == std::string::npos) {
      const std::string first = read_file(fresh);
      REQUIRE(generate(fresh) == 0);
      CHECK(read_file(fresh) == first);
    }
  }
}
