// tools/ref3d: the Bullet reference, `statsim gather` and the committed 3D tables.
// Runs with the repository root as working directory (reads tools/meshes/*, tables/*).
#include "common/table_writer.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/model.hpp"
#include "ref3d/ref3d.hpp"
#include "ref3d/reference.hpp"

#include "statsim/signature.hpp"

#include "support/table_header.hpp"
#include "support/temp_dir.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace statsim::tools;
using namespace statsim::tools::ref3d;

using namespace statsim::testing;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A gathering that measures only what a test needs: one response cell, two flights per ratio.
GatherOptions minimal_options()
{
  GatherOptions o;
  o.trials = 2;
  o.height_trials = 2;
  o.height_ratios = {0.0};
  o.cos_theta = {1.0};
  o.cos_phi = {0.0};
  o.spin_ratios = {0.0};
  o.threads = 2;
  return o;
}

// The tiny configuration of the command-line tests.
std::vector<std::string> tiny_args()
{
  return {"--shape", "box", "--cos-theta", "0.5,1", "--cos-phi", "-1,1", "--spin-ratios", "0,1", "--height-ratios",
          "0,1,4", "--trials", "3", "--height-trials", "8", "--rest-drops", "24", "--quiet"};
}

int gather_cli(std::vector<std::string> args, std::string* err_text = nullptr)
{
  std::ostringstream out, err;
  const int rc = run_gather_command(args, out, err);
  if (err_text) *err_text = err.str();
  return rc;
}

void append(std::vector<double>& v, const nlohmann::json& a)
{
  for (const auto& x : a) v.push_back(x.get<double>());
}

}  // namespace

TEST_CASE("gather3d: the box model matches the closed form")
{
  const ShapeModel m = load_shape_model("box", "", 1000.0);
  CHECK(m.kind == ShapeKind::box);
  CHECK(m.mass.mass == doctest::Approx(8.0).epsilon(1e-12));
  for (int k = 0; k < 3; ++k) CHECK(m.unit_inertia[k] == doctest::Approx(0.04 / 6.0).epsilon(1e-12));
  CHECK(m.bounding_radius == doctest::Approx(std::sqrt(3.0) * 0.1).epsilon(1e-12));
  CHECK(m.hull.size() == 8);
  CHECK(m.hull_planes.size() == 6);
  const ShapeModel l = load_shape_model("lshape", "", 1000.0);
  CHECK(l.kind == ShapeKind::compound);
  CHECK(l.boxes.size() == 2);
  CHECK(l.hull.size() == 10);  // the inner corner's two vertices are not on the hull
}

TEST_CASE("gather3d: h_coll of a box lies between half the smallest extent and half the diagonal")
{
  const ShapeModel m = load_shape_model("box", "", 1000.0);
  const double half_side = 0.1, half_diagonal = std::sqrt(3.0) * 0.1;
  std::vector<double> means;
  for (double s : {0.0, 8.0, 32.0, 128.0}) {
    double sum = 0.0;
    const int n = 1000;
    for (int k = 0; k < n; ++k) {
      const double h = height_trial(m, s, 7, static_cast<std::uint64_t>(k) + 100000u * static_cast<std::uint64_t>(s));
      REQUIRE(h >= half_side - 1e-9);
      REQUIRE(h <= half_diagonal + 1e-9);
      sum += h;
    }
    means.push_back(sum / n);
  }
  // Without spin the contact height is the support of a uniformly rotated cube: E = 0.15 m
  // (0.1 (|u_x| + |u_y| + |u_z|), each |u_i| of mean 1/2); the standard error is about 0.0005.
  CHECK(means[0] == doctest::Approx(0.15).epsilon(0.01));
  // With spin the mean rises toward half the diagonal.
  for (std::size_t i = 1; i < means.size(); ++i) CHECK(means[i] > means[i - 1] + 0.001);
  CHECK(means.back() < half_diagonal);
  CHECK(means.back() > 0.5 * (means[0] + half_diagonal));
}

TEST_CASE("gather3d: a face-down cube at normal incidence rebounds at the restitution")
{
  const ShapeModel m = load_shape_model("box", "", 1000.0);
  const ReferenceSettings settings;
  const Reference ref(m, settings);
  for (double u : {0.5, 2.0, 8.0}) {
    RigidState s;
    s.position = Eigen::Vector3d(0, 0, 0.1 - 1e-7);
    s.velocity = Eigen::Vector3d(0, 0, -u);
    const ImpactResult r = ref.impact(s, 1.0);
    CHECK_FALSE(r.time_limited);
    CHECK(r.after.velocity.z() / u == doctest::Approx(settings.restitution).epsilon(1e-3));
    CHECK(r.after.velocity.head<2>().norm() < 1e-6 * u);
    CHECK(r.after.spin.norm() * m.bounding_radius < 1e-6 * u);
  }
}

TEST_CASE("gather3d: a cube rests on its 6 faces equally often")
{
  GatherOptions o = minimal_options();
  o.shape = "box";
  o.rest_drops = 600;
  const GatherResult r = gather(o);
  CHECK(r.unsettled == 0);
  REQUIRE(r.rest.size() == 6);
  CHECK(r.rest_rare.empty());
  for (const RestPose& p : r.rest) {
    CHECK(std::fabs(p.frequency - 1.0 / 6.0) <= 0.05);
    const double largest = p.normal.cwiseAbs().maxCoeff();
    CHECK(std::acos(std::min(1.0, largest)) < 5.0 * kPi / 180.0);
    CHECK(p.height == doctest::Approx(0.1).epsilon(0.01));
    CHECK(p.measured_height == doctest::Approx(0.1).epsilon(0.01));
  }
}

TEST_CASE("gather3d: a 1x2x4 box rests most often on a largest face")
{
  GatherOptions o = minimal_options();
  o.box_size = {0.05, 0.1, 0.2};
  o.rest_drops = 200;
  const GatherResult r = gather(o);
  REQUIRE_FALSE(r.rest.empty());
  // Lying on a 0.1 x 0.2 face, the centre is 0.025 m up and the up vector is the short axis.
  const RestPose& top = r.rest.front();
  CHECK(top.height == doctest::Approx(0.025).epsilon(0.01));
  const ShapeModel& m = r.model;
  const Eigen::Vector3d short_axis = m.boxes[0].rotation * Eigen::Vector3d::UnitX();  // mesh x in the body frame
  CHECK(std::fabs(top.normal.dot(short_axis)) > 0.999);
  double largest_faces = 0.0;
  for (const RestPose& p : r.rest)
    if (std::fabs(p.height - 0.025) < 1e-4) largest_faces += p.frequency;
  CHECK(largest_faces > 0.5);
}

TEST_CASE("gather3d: the same command and seed give the same bytes with 1 or 2 threads")
{
  TempDir dir("gather3d");
  const std::string out = dir.file("tiny.hpp"), json = dir.file("tiny.json");
  std::vector<std::string> args = tiny_args();
  args.insert(args.end(), {"--out", out, "--json", json});

  std::vector<std::string> one = args, two = args;
  one.insert(one.end(), {"--threads", "1"});
  two.insert(two.end(), {"--threads", "2"});
  std::string err;
  REQUIRE(gather_cli(one, &err) == 0);
  const std::string header1 = read_file(out), json1 = read_file(json);
  REQUIRE(gather_cli(two, &err) == 0);
  CHECK(read_file(out) == header1);
  CHECK(read_file(json) == json1);
  CHECK(header1.rfind("// generated by statsim gather", 0) == 0);
  // The recorded command leaves out --threads, --json and --quiet, and names --out.
  const std::string command = header1.substr(0, header1.find('\n', header1.find("// command: ")));
  CHECK(command.find("// command: build/bin/statsim gather --shape box ") != std::string::npos);
  CHECK(command.find(" --cos-theta 0.5,1 ") != std::string::npos);
  CHECK(command.find(" --out " + out) != std::string::npos);
  CHECK(command.find("--threads") == std::string::npos);
  CHECK(command.find("--json") == std::string::npos);
  CHECK(command.find("--quiet") == std::string::npos);
  CHECK(dir.entries() == std::vector<std::string>{"tiny.hpp", "tiny.json"});

  SUBCASE("the header's values equal the JSON dump")
  {
    const nlohmann::json j = nlohmann::json::parse(json1);
    std::vector<double> expect;
    expect.push_back(j["length"].get<double>());
    expect.push_back(j["bounding_radius"].get<double>());
    expect.push_back(j["mass"].get<double>());
    append(expect, j["unit_inertia"]);
    expect.push_back(j["material"]["restitution"].get<double>());
    expect.push_back(j["material"]["friction"].get<double>());
    expect.push_back(j["material"]["rolling_resistance"].get<double>());
    expect.push_back(j["restitution_threshold"].get<double>());
    append(expect, j["h_coll"]["ratio"]);
    append(expect, j["h_coll"]["mean"]);
    append(expect, j["h_coll"]["std"]);
    for (const auto& axis : j["response"]["axes"]) append(expect, axis["values"]);
    expect.push_back(0.0);  // the unused fourth axis
    append(expect, j["response"]["mean"]);
    append(expect, j["response"]["std"]);
    for (const auto& p : j["rest"]) append(expect, p["normal"]);
    for (const auto& p : j["rest"]) expect.push_back(p["height"].get<double>());
    for (const auto& p : j["rest"]) expect.push_back(p["frequency"].get<double>());
    const HeaderNumbers h = header_numbers(header1);
    REQUIRE(h.floats.size() == expect.size());
    for (std::size_t i = 0; i < expect.size(); ++i) CHECK(h.floats[i] == expect[i]);
    // Sizes: 3 response axes of 2 samples, 3 h_coll samples, 6 components per cell.
    CHECK(j["response"]["axes"].size() == 3);
    CHECK(j["response"]["mean"].size() == 8 * 6);
    CHECK(j["h_coll"]["mean"].size() == 3);
    CHECK(j["inertia"].size() == 3);
    CHECK(j["rest"].size() >= 1);
    CHECK(h.ints == std::vector<long>{3});  // axis_count "3u"
  }
}

TEST_CASE("gather3d: i16 tables dequantize within the reported error")
{
  TempDir dir("gather3d");
  const std::string out = dir.file("tiny16.hpp"), json = dir.file("tiny16.json");
  std::vector<std::string> args = tiny_args();
  args.insert(args.end(), {"--precision", "i16", "--out", out, "--json", json});
  REQUIRE(gather_cli(args) == 0);
  const std::string text = read_file(out);
  CHECK(text.find("SignatureQ16<3, 3, 2, 2, 2, 1,") != std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(read_file(json));
  const double worst = j["response"]["i16"]["worst_error"].get<double>();
  const float mean_scale = j["response"]["i16"]["mean_scale"].get<float>();
  const float mean_offset = j["response"]["i16"]["mean_offset"].get<float>();
  const float std_scale = j["response"]["i16"]["spread_scale"].get<float>();
  const float std_offset = j["response"]["i16"]["spread_offset"].get<float>();
  CHECK(text.find("i16 dequantization error") != std::string::npos);
  const HeaderNumbers h = header_numbers(text);
  // Integers: axis_count 3u, then the two tables of 8 cells x 6.
  REQUIRE(h.ints.size() == 1 + 2 * 48);
  std::vector<double> mean, stddev;
  append(mean, j["response"]["mean"]);
  append(stddev, j["response"]["std"]);
  double seen = 0.0;
  for (std::size_t i = 0; i < 48; ++i) {
    // As statsim::ValuesView dequantises: offset + scale * q, in float.
    const float m = mean_offset + mean_scale * static_cast<float>(h.ints[1 + i]);
    const float s = std_offset + std_scale * static_cast<float>(h.ints[1 + 48 + i]);
    seen = std::max({seen, std::fabs(m - mean[i]), std::fabs(s - stddev[i])});
  }
  CHECK(seen <= worst);
  CHECK(worst <= 0.5 * std::max(mean_scale, std_scale) * 1.01 + 1e-7);
  // The integers are statsim::quantize16 of the float tables, the rule the firmware uses.
  std::vector<float> mean_f(mean.begin(), mean.end());
  std::vector<std::int16_t> q(mean_f.size());
  float scale = 0, offset = 0;
  statsim::quantize16(mean_f.data(), mean_f.size(), scale, offset, q.data());
  CHECK(scale == mean_scale);
  CHECK(offset == mean_offset);
  CHECK(std::equal(q.begin(), q.end(), h.ints.begin() + 1));

  // The header compiles as a SignatureQ16 whose view reads the 16-bit responses, and its
  // initialiser is fully braced.
  const std::string check = dir.write("check.cpp", "#include \"tiny16.hpp\"\n"
                                                   "static_assert(statsim::tables::box.response_mean.q.size() == 48);\n");
  const std::string use = dir.write("use.cpp", "#include \"tiny16.hpp\"\n"
                                               "constexpr statsim::SignatureView<3> v = statsim::tables::box.view();\n"
                                               "static_assert(!v.response.mean.f32 && !v.response.spread.f32);\n"
                                               "static_assert(v.response.mean.scale > 0 && v.rest.count >= 1);\n");
  const std::string compile = std::string(STATSIM_TEST_CXX) + " -std=c++17 -fsyntax-only -Wall -Wextra -Wpedantic -Wshadow " +
                              "-Wconversion -Werror -I" + STATSIM_TEST_SOURCE_DIR + " -isystem " +
                              STATSIM_TEST_EIGEN_INCLUDE + " ";
  CHECK(std::system((compile + "-Wmissing-braces " + check).c_str()) == 0);
  CHECK(std::system((compile + use).c_str()) == 0);
}

TEST_CASE("gather3d: a table never holds a value that is not finite")
{
  CHECK(hex_float(0.75) == "0x1.8p-1f");
  CHECK(hex_float(-0.0) == "0x0p+0f");
  CHECK(hex_float(0.1) == "0x1.99999ap-4f");  // the float nearest 0.1
  for (const double bad : {std::nan(""), -HUGE_VAL, 1e39})
    CHECK_THROWS_WITH_AS(hex_float(bad, "mass"), doctest::Contains("mass is"), std::invalid_argument);
  // The generator refuses to write such a table rather than write one the runtime rejects.
  GatherOptions o = minimal_options();
  o.rest_drops = 24;
  GatherResult r = gather(o);
  REQUIRE_NOTHROW(header_text(r, "statsim gather"));
  r.response_std[3] = std::nan("");
  CHECK_THROWS_WITH_AS(header_text(r, "statsim gather"), doctest::Contains("a table holds finite values only"),
                       std::invalid_argument);
}

TEST_CASE("gather3d: bad meshes are rejected with a message and leave no file")
{
  TempDir dir("gather3d");
  const std::string cube_v = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
  const std::string cube_f = "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n"
                             "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  struct Case {
    const char* name;
    std::string content;  // empty: the file is missing
    const char* message;
  };
  const std::vector<Case> cases = {
      {"missing.obj", "", "cannot open mesh file"},
      {"garbage.obj", "v 0 0 0\nhello world\n" + cube_v + cube_f, "unparsable line"},
      {"nan.obj", "v 0 0 nan\n" + cube_v.substr(8) + cube_f, "not finite"},
      {"flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n", "zero volume"},
      {"open.obj", cube_v + cube_f.substr(0, cube_f.size() - 8), "open surface"},
      {"flipped.obj", cube_v + "f 1 2 3\n" + cube_f.substr(8), "inconsistently wound"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    const std::string mesh = c.content.empty() ? dir.file(c.name) : dir.write(c.name, c.content);
    const std::string out = dir.file("out.hpp");
    std::string err;
    const int rc = gather_cli({"--mesh", mesh, "--out", out, "--json", dir.file("out.json"), "--quiet"}, &err);
    CHECK(rc != 0);
    CHECK(err.find("statsim gather: error: ") != std::string::npos);
    CHECK(err.find(c.message) != std::string::npos);
    CHECK_FALSE(fs::exists(out));
    CHECK_FALSE(fs::exists(dir.file("out.json")));
  }
  // Nothing but the meshes the test wrote is left in the directory.
  for (const std::string& name : dir.entries()) CHECK(name.find(".obj") != std::string::npos);
}

TEST_CASE("gather3d: bad options are rejected before any work")
{
  TempDir dir("gather3d");
  std::string err;
  CHECK(gather_cli({"--shape", "box", "--trials", "1", "--out", dir.file("x.hpp"), "--quiet"}, &err) != 0);
  CHECK(err.find("--trials") != std::string::npos);
  CHECK(gather_cli({"--shape", "box", "--cos-theta", "1,0.5", "--out", dir.file("x.hpp"), "--quiet"}, &err) != 0);
  CHECK(err.find("increasing") != std::string::npos);
  CHECK(gather_cli({"--shape", "box", "--name", "not-an-identifier", "--out", dir.file("x.hpp"), "--quiet"}, &err) != 0);
  CHECK(gather_cli({"--shape", "box", "--quiet"}, &err) != 0);  // no --out
  CHECK(dir.entries().empty());
}

TEST_CASE("gather3d: the committed box table")
{
  const statsim::SignatureView<3> v = statsim::tables::box.view();
  CHECK(std::string(v.name) == "box");
  CHECK(v.layout == statsim::ResponseLayout::scaled);
  CHECK(v.response.axis_count == 3);
  CHECK(v.bounding_radius == doctest::Approx(0.173205).epsilon(1e-5));
  REQUIRE(v.rest.count == 6);
  for (std::uint32_t i = 0; i < v.rest.count; ++i) {
    CHECK(v.rest.heights[i] == doctest::Approx(0.1).epsilon(1e-5));
    CHECK(std::fabs(v.rest.frequencies[i] - 1.0f / 6.0f) < 0.05f);
    CHECK(v.rest.normal(i).cwiseAbs().maxCoeff() == doctest::Approx(1.0));
  }
  for (std::uint32_t i = 0; i < v.height.spin_ratio.size; ++i) {
    CHECK(v.height.mean[i] > 0.1f);
    CHECK(v.height.mean[i] < 0.17321f);
  }
  // Head-on, without spin: the rigid box leaves slower than a particle would (energy goes into spin).
  float x[3] = {1.0f, 0.0f, 0.0f}, mean[6], stddev[6];
  v.response.lookup(x, mean, stddev);
  CHECK(mean[5] < 0.0f);
  CHECK(stddev[5] > 0.0f);
}

TEST_CASE("gather3d: the committed lshape and bunny tables")
{
  for (const statsim::SignatureView<3>& v : {statsim::tables::lshape.view(), statsim::tables::bunny.view()}) {
    CAPTURE(v.name);
    REQUIRE(v.rest.count >= 1);
    float total = 0.0f;
    for (std::uint32_t i = 0; i < v.rest.count; ++i) {
      CHECK(v.rest.normal(i).norm() == doctest::Approx(1.0).epsilon(1e-5));
      CHECK(v.rest.frequencies[i] > 0.05f);
      CHECK(v.rest.heights[i] > 0.0f);
      CHECK(v.rest.heights[i] < v.bounding_radius);
      total += v.rest.frequencies[i];
    }
    CHECK(total <= 1.0f + 1e-6f);
    CHECK(v.height.mean[0] < v.bounding_radius);
  }
}
