// tools/ref3d: the Bullet reference, `statsim gather` and the committed 3D tables.
// Runs with the repository root as working directory (reads tools/meshes/*, tables/*).
#include "common/rest_families.hpp"
#include "common/table_writer.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/model.hpp"
#include "ref3d/ref3d.hpp"
#include "ref3d/reference.hpp"
#include "ref3d/sampling.hpp"
#include "ref3d/signature_json.hpp"

#include "statsim/signature.hpp"
#include "statsim/detail/checks.hpp"

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
#include <cstring>
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
  o.body_contacts = false;
  return o;
}

// The tiny configuration of the command-line tests.
std::vector<std::string> tiny_args()
{
  return {"--shape", "box", "--cos-theta", "0.5,1", "--cos-phi", "-1,1", "--spin-ratios", "0,1", "--height-ratios",
          "0,1,4", "--trials", "3", "--height-trials", "8", "--rest-drops", "24", "--pair-trials", "4",
          "--packing-piles", "1", "--packing-bins", "1", "--packing-count", "12", "--quiet"};
}

int gather_cli(std::vector<std::string> args, std::string* err_text = nullptr)
{
  std::ostringstream out, err;
  const int rc = run_gather_command(args, out, err);
  if (err_text) *err_text = err.str();
  return rc;
}

// The tiny configuration with `extra` must be refused before any trial with `message`, and
// write nothing.
void check_refused(const TempDir& dir, const std::vector<std::string>& extra, const std::string& message)
{
  std::vector<std::string> args = tiny_args();
  args.insert(args.end(), extra.begin(), extra.end());
  args.insert(args.end(), {"--out", dir.file("x.hpp")});
  std::string err;
  CHECK(gather_cli(args, &err) != 0);
  CHECK(err.find(message) != std::string::npos);
  CHECK_FALSE(fs::exists(dir.file("x.hpp")));
}

// Writes `source` into `dir` as add_shape.cpp, compiles it as a user of the runtime would, and
// runs it: it must exit with 0.
void check_program_runs(const TempDir& dir, const std::string& source)
{
  const std::string program = dir.write("add_shape.cpp", source);
  const std::string exe = dir.file("add_shape");
  const std::string compile = std::string(STATSIM_TEST_CXX) + " -std=c++17 -O0 -Wall -Wextra -Wmissing-braces -Werror -I" +
                              STATSIM_TEST_SOURCE_DIR + " -isystem " + STATSIM_TEST_EIGEN_INCLUDE + " " + program +
                              " -o " + exe;
  REQUIRE(std::system(compile.c_str()) == 0);
  CHECK(std::system(exe.c_str()) == 0);
}

// A program that includes `header` (written in `dir`) and exits with 0 when `condition` (C++
// over `v`, the view of table `table`) holds and add_shape accepts `v`, compiled and run.
void check_compiles_and_adds(const TempDir& dir, const std::string& header, const std::string& table,
                             const std::string& condition)
{
  check_program_runs(dir, "#include \"" + header + "\"\n"
                          "#include \"statsim/world3.hpp\"\n#include <memory>\n"
                          "int main()\n{\n"
                          "  auto w = std::make_unique<statsim::World3<4>>(statsim::WorldDef3{});\n"
                          "  const statsim::SignatureView<3> v = statsim::tables::" + table + ".view();\n"
                          "  return " + condition + " && w->add_shape(v).ok() ? 0 : 1;\n}\n");
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
  // A snapped pose stands exactly on its face: the height is the face's distance from the centre
  // (a half extent), not the mean of the drops, which stop tilted by the solver's tolerance. Faces
  // of one size are one family.
  for (const RestPose& p : r.rest) {
    REQUIRE(p.snapped);
    const Eigen::Vector3d along = (m.boxes[0].rotation.transpose() * p.normal).cwiseAbs();
    CHECK(std::fabs(p.height - along.dot(m.boxes[0].half_extents)) < 1e-12);
    CHECK(std::fabs(p.measured_height - p.height) < 0.01 * p.height);
    for (const RestPose& q : r.rest) CHECK((p.family == q.family) == (std::fabs(p.height - q.height) < 1e-9));
  }
}

TEST_CASE("gather3d: rest poses equivalent under the shape's symmetry are kept or dropped together")
{
  // A nut: two flat faces at 36.5 % each, six equivalent side faces at 4.5 % each (27 % together),
  // descriptors equal up to rounding; and one rare pose of its own kind.
  const std::vector<double> flat = {0.4, 0.1, 0.3, 6, 12}, side = {0.8, 0.2, 0.1, 4, 12};
  std::vector<RestCandidate> c;
  for (int k = 0; k < 2; ++k) c.push_back({0.365, 365, flat});
  for (int k = 0; k < 6; ++k) {
    std::vector<double> d = side;
    d[0] += 1e-9 * k;  // rounding
    c.push_back({0.045, 45, d});
  }
  RestSelectionOptions o;
  o.min_frequency = 0.05;
  o.max_dropped = 1.0;  // the family rule alone
  RestSelection s = select_rest_poses(c, o);
  CHECK(s.family == std::vector<int>{0, 0, 1, 1, 1, 1, 1, 1});
  CHECK(s.family_frequency[0] == doctest::Approx(0.73));
  CHECK(s.family_frequency[1] == doctest::Approx(0.27));
  // Every side is kept (the old rule, frequency > 0.05 pose by pose, kept only the two flats).
  CHECK(std::count(s.kept.begin(), s.kept.end(), 1) == 8);
  CHECK(s.dropped == 0.0);

  // Sides that differ beyond the tolerance are not one family: each is below the cut alone.
  std::vector<RestCandidate> unequal = c;
  for (int k = 0; k < 6; ++k) unequal[2 + static_cast<std::size_t>(k)].descriptor[1] += 0.01 * k;
  s = select_rest_poses(unequal, o);
  CHECK(std::count(s.kept.begin(), s.kept.end(), 1) == 2);
  CHECK(s.dropped == doctest::Approx(0.27));
  // Descriptors of different lengths, or none, are never equivalent.
  std::vector<RestCandidate> other = {{0.5, 50, {1, 2}}, {0.3, 30, {1, 2, 0}}, {0.1, 10, {}}, {0.1, 10, {}}};
  CHECK(rest_families(other, 1e-3) == std::vector<int>{0, 1, 2, 3});

  // The dropped-share rule: rare families, most frequent first, while more than max_dropped is
  // dropped, each seen in at least min_count drops.
  std::vector<RestCandidate> rare = {{0.60, 600, {1}}, {0.30, 300, {2}}, {0.04, 40, {3}}, {0.03, 30, {4}},
                                     {0.025, 25, {5}}, {0.005, 5, {6}}};
  o.max_dropped = 0.035;
  o.min_count = 10;
  s = select_rest_poses(rare, o);
  CHECK(s.kept == std::vector<char>{1, 1, 1, 1, 0, 0});  // dropped 0.10, 0.06, then 0.03: stop
  CHECK(s.dropped == doctest::Approx(0.03));
  o.max_dropped = 0.0;
  s = select_rest_poses(rare, o);
  CHECK(s.kept == std::vector<char>{1, 1, 1, 1, 1, 0});  // the 5-drop pose is below min_count
  // Never more poses than the runtime holds: a family that does not fit whole is not kept.
  o.max_poses = 5;
  s = select_rest_poses(c, o);
  CHECK(std::count(s.kept.begin(), s.kept.end(), 1) == 2);
}

TEST_CASE("gather3d: --rest-min-frequency and --rest-max-dropped are options of the command")
{
  TempDir dir("gather3d");
  // A 1 x 2 x 4 box: three families of two faces; the largest faces take most drops.
  const std::vector<std::string> base = {"--box-size", "0.05,0.1,0.2", "--cos-theta", "1", "--cos-phi", "0",
                                         "--spin-ratios", "0", "--height-ratios", "0", "--trials", "2",
                                         "--height-trials", "2", "--rest-drops", "60", "--quiet"};
  const auto run = [&](std::vector<std::string> extra, const std::string& stem) {
    std::vector<std::string> args = base;
    extra.insert(extra.end(), {"--out", dir.file(stem + ".hpp"), "--json", dir.file(stem + ".json")});
    args.insert(args.end(), extra.begin(), extra.end());
    std::string err;
    REQUIRE_MESSAGE(gather_cli(args, &err) == 0, err);
    return nlohmann::json::parse(read_file(dir.file(stem + ".json")));
  };
  const nlohmann::json all = run({}, "default");
  const nlohmann::json cut = run({"--rest-min-frequency", "0.4", "--rest-max-dropped", "1"}, "cut");
  // By default every pose is kept (each family is above the cut); the cut at 0.4 keeps the largest
  // faces' family alone, the same drops (the same seed) otherwise.
  CHECK(all["rest"].size() >= 4);
  CHECK(all["rest_rare"].empty());
  CHECK(all["rest_dropped"].get<double>() == 0.0);
  REQUIRE(cut["rest"].size() == 2);
  CHECK(cut["rest"].size() + cut["rest_rare"].size() == all["rest"].size());
  CHECK(cut["rest"][0]["family"] == 0);
  CHECK(cut["rest"][1]["family"] == 0);
  CHECK(cut["rest"][0]["family_frequency"].get<double>() > 0.4);
  CHECK(cut["rest_dropped"].get<double>() == doctest::Approx(1.0 - cut["rest"][0]["family_frequency"].get<double>()));
  const std::string header = read_file(dir.file("cut.hpp"));
  CHECK(header.find(" --rest-min-frequency 0.4 --rest-max-dropped 1 ") != std::string::npos);
  CHECK(header.find("kept above 0.4, rare families kept while more than 1 is dropped") != std::string::npos);
  CHECK(header.find("// Rest poses dropped: ") != std::string::npos);
  // The defaults leave the option line as it was.
  const std::string plain = read_file(dir.file("default.hpp"));
  CHECK(plain.find("kept above 0.05\n") != std::string::npos);
  CHECK(plain.find("--rest-min-frequency") == std::string::npos);
  std::string err;
  CHECK(gather_cli({"--shape", "box", "--rest-min-frequency", "1", "--out", dir.file("x.hpp"), "--quiet"}, &err) != 0);
  CHECK(err.find("--rest-min-frequency must be in [0, 1)") != std::string::npos);
  CHECK(gather_cli({"--shape", "box", "--rest-max-dropped", "-0.1", "--out", dir.file("x.hpp"), "--quiet"}, &err) != 0);
  CHECK(err.find("--rest-max-dropped") != std::string::npos);
  CHECK_FALSE(fs::exists(dir.file("x.hpp")));
}

TEST_CASE("gather3d: the same command and seed give the same bytes with 1 or 2 threads")
{
  TempDir dir("gather3d");
  const std::string out = dir.file("tiny.hpp"), json = dir.file("tiny.json");
  std::vector<std::string> args = tiny_args();
  args.insert(args.end(), {"--out", out, "--json", json, "--settle"});

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
  // The recorded command leaves out --threads, --json and --quiet, and names --out by its file
  // name: a table outside the repository's tables/ records no directory.
  const std::string command = header1.substr(0, header1.find('\n', header1.find("// command: ")));
  CHECK(command.find("// command: statsim gather --shape box ") != std::string::npos);
  CHECK(command.find(" --cos-theta 0.5,1 ") != std::string::npos);
  CHECK(command.find(" --out tiny.hpp") != std::string::npos);
  CHECK(header1.find(dir.file("")) == std::string::npos);
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
    append(expect, j["mesh_frame"]);
    const nlohmann::json& c = j["body_contacts"];
    for (const char* key : {"pair_mean", "pair_stddev", "support", "faces", "packing_mean", "packing_stddev"})
      append(expect, c[key]);
    const nlohmann::json& l = j["landing"];
    expect.push_back(l["hop"].get<double>());
    for (const char* key : {"cos_theta", "spin_ratio", "froude", "probability"}) append(expect, l[key]);
    append(expect, j["settle"]["time"]);
    const HeaderNumbers h = header_numbers(header1);
    REQUIRE(h.floats.size() == expect.size());
    for (std::size_t i = 0; i < expect.size(); ++i) CHECK(h.floats[i] == expect[i]);
    // Sizes: 3 response axes of 2 samples, 3 h_coll samples, 6 components per cell.
    CHECK(j["response"]["axes"].size() == 3);
    CHECK(j["response"]["mean"].size() == 8 * 6);
    CHECK(j["h_coll"]["mean"].size() == 3);
    CHECK(j["inertia"].size() == 3);
    CHECK(j["rest"].size() >= 1);
    CHECK(h.ints == std::vector<long>{3, 17});  // axis_count "3u", support map size "17u"
  }
}

TEST_CASE("gather3d: i16 tables dequantize within the reported error")
{
  TempDir dir("gather3d");
  const std::string out = dir.file("tiny16.hpp"), json = dir.file("tiny16.json");
  std::vector<std::string> args = tiny_args();
  args.insert(args.end(), {"--precision", "i16", "--no-body-contacts", "--out", out, "--json", json});
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
      // Rare poses are kept too (a family above the cut, or while the dropped share is large), but
      // each was seen in at least 5 of the 1000 drops.
      CHECK(v.rest.frequencies[i] >= 0.005f);
      CHECK(v.rest.heights[i] > 0.0f);
      CHECK(v.rest.heights[i] < v.bounding_radius);
      total += v.rest.frequencies[i];
    }
    CHECK(total <= 1.0f + 1e-6f);
    CHECK(v.height.mean[0] < v.bounding_radius);
  }
}

TEST_CASE("gather3d: a gathered box's body-body data is the closed form of a cube")
{
  GatherOptions o = minimal_options();
  o.rest_drops = 4;
  o.height_ratios = {0.0, 2.0};
  o.body_contacts = true;
  o.pair_trials = 8;
  o.packing_piles = 1;
  o.packing_bins = 0;
  o.packing_count = 12;
  const GatherResult r = gather(o);
  const BodyContactData& c = r.contact;
  constexpr int S = 17;
  REQUIRE(c.support_size == S);
  REQUIRE(c.support.size() == 6u * S * S);
  // A cube of half extent h = 0.1 m has s(u) = h (|u_x| + |u_y| + |u_z|), so every face of the
  // map holds h (1 + |a| + |b|) at its node (a, b).
  const auto node = [](int i) { return -1.0 + 2.0 * i / (S - 1); };
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < S; ++i)
      for (int j = 0; j < S; ++j)
        CHECK(c.support[static_cast<std::size_t>((f * S + i) * S + j)] ==
              doctest::Approx(0.1 * (1 + std::fabs(node(i)) + std::fabs(node(j)))).epsilon(1e-9));
  // Its six faces, each axis direction once, 0.1 m from the centre.
  REQUIRE(c.hull_faces == 6);
  REQUIRE(c.faces.size() == 6u * 5u);
  std::vector<int> seen(6, 0);
  for (std::size_t k = 0; k < 6; ++k) {
    const Eigen::Vector3d n(c.faces[5 * k], c.faces[5 * k + 1], c.faces[5 * k + 2]);
    CHECK(n.norm() == doctest::Approx(1.0));
    CHECK(n.cwiseAbs().maxCoeff() == doctest::Approx(1.0));
    Eigen::Index axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    ++seen[static_cast<std::size_t>(2 * axis + (n[axis] < 0 ? 1 : 0))];
    CHECK(c.faces[5 * k + 3] == doctest::Approx(0.1));
  }
  CHECK(seen == std::vector<int>(6, 1));
  // The box mesh is centred on its centre of mass, along its axes: the identity frame.
  const std::vector<double> identity = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  REQUIRE(c.mesh_frame.size() == identity.size());
  for (std::size_t k = 0; k < identity.size(); ++k) CHECK(c.mesh_frame[k] == doctest::Approx(identity[k]));
  // Two cubes first touch between face to face (2 h) and corner to corner (2 sqrt(3) h).
  REQUIRE(c.pair_mean.size() == 2);
  for (double d : c.pair_mean) {
    CHECK(d > 0.2);
    CHECK(d < 0.2 * std::sqrt(3.0));
  }
  // A convex shape's resting neighbours stand where their hulls touch: ratios near 1.
  for (std::size_t b = 0; b < 3; ++b) {
    CHECK(c.packing_mean[b] == doctest::Approx(1.0).epsilon(0.03));
    CHECK(c.packing_std[b] >= 0.0);
  }
}

TEST_CASE("gather3d: a header with body-body data compiles, and add_shape accepts it")
{
  TempDir dir("gather3d_contacts");
  for (const char* precision : {"f32", "i16"}) {
    std::vector<std::string> args = tiny_args();
    args.insert(args.end(), {"--precision", precision, "--no-landing", "--name", std::string("t_") + precision, "--out",
                             dir.file(std::string("t_") + precision + ".hpp")});
    REQUIRE(gather_cli(args) == 0);
    const std::string text = read_file(dir.file(std::string("t_") + precision + ".hpp"));
    CHECK(text.find(std::string(precision) == "i16" ? "ContactDataQ16<3, 3, 17, 6>>" : "ContactData<3, 3, 17, 6>>") !=
          std::string::npos);
    CHECK(text.find("#if !defined(STATSIM_TABLE_FORMAT_MINOR) || STATSIM_TABLE_FORMAT_MINOR < 1\n#error ") !=
          std::string::npos);
  }
  check_program_runs(dir, "#include \"t_f32.hpp\"\n#include \"t_i16.hpp\"\n"
                          "#include \"statsim/world3.hpp\"\n#include <memory>\n"
                          "int main()\n{\n"
                          "  auto w = std::make_unique<statsim::World3<4>>(statsim::WorldDef3{});\n"
                          "  int bad = 0;\n"
                          "  for (const statsim::SignatureView<3>& v : {statsim::tables::t_f32.view(), statsim::tables::t_i16.view()})\n"
                          "    bad += v.contact.present() && w->add_shape(v).ok() ? 0 : 1;\n"
                          "  return bad;\n}\n");
}

TEST_CASE("gather3d: a table outside the repository is the same bytes wherever its mesh and output are")
{
  // The same mesh from two directories, given once by an absolute and once by a relative path,
  // written into two directories: a table records file names only (statsim_add_tables writes
  // into build directories), and --namespace puts it in the caller's namespace.
  TempDir a("gather3d_where_a"), b("gather3d_where_b");
  const std::string mesh = read_file(std::string(STATSIM_TEST_SOURCE_DIR) + "/tests/meshes/block.obj");
  const std::string mesh_a = a.write("block.obj", mesh), mesh_b = b.write("block.obj", mesh);
  const std::vector<std::string> options = {"--cos-theta", "0.5,1", "--cos-phi", "-1,1", "--spin-ratios", "0,1",
                                            "--height-ratios", "0,1,4", "--trials", "3", "--height-trials", "8",
                                            "--rest-drops", "24", "--no-body-contacts", "--namespace", "game::parts",
                                            "--quiet"};
  std::vector<std::string> one = {"--mesh", mesh_a, "--out", a.file("block.hpp")};
  std::vector<std::string> two = {"--mesh", fs::relative(mesh_b).string(), "--out", fs::relative(b.file("block.hpp")).string()};
  one.insert(one.end(), options.begin(), options.end());
  two.insert(two.end(), options.begin(), options.end());
  std::string err;
  REQUIRE_MESSAGE(gather_cli(one, &err) == 0, err);
  REQUIRE_MESSAGE(gather_cli(two, &err) == 0, err);
  const std::string text = read_file(a.file("block.hpp"));
  CHECK(read_file(b.file("block.hpp")) == text);
  CHECK(text.find("// command: statsim gather --mesh block.obj ") != std::string::npos);
  CHECK(text.find(" --out block.hpp --namespace game::parts ") != std::string::npos);
  CHECK(text.find("// (paths as file names: run it where its input files are)") != std::string::npos);
  CHECK(text.find("// Input: block.obj ") != std::string::npos);
  CHECK(text.find("\"block.hpp was generated for table format") != std::string::npos);
  CHECK(text.find("namespace game::parts {") != std::string::npos);
  CHECK(text.find("inline constexpr ::statsim::Signature<3,") != std::string::npos);
  CHECK(text.find("}  // namespace game::parts") != std::string::npos);
  CHECK(text.find("tables/") == std::string::npos);
  CHECK(text.find(a.file("")) == std::string::npos);
  // Not a namespace: refused before gathering, nothing written.
  std::vector<std::string> bad = {"--mesh", mesh_a, "--out", a.file("bad.hpp"), "--namespace", "game::"};
  bad.insert(bad.end(), options.begin(), options.end() - 3);
  CHECK(gather_cli(bad, &err) != 0);
  CHECK(err.find("is not a C++ namespace name") != std::string::npos);
  CHECK_FALSE(fs::exists(a.file("bad.hpp")));
}

TEST_CASE("gather3d: --no-body-contacts, --no-landing and the default write tables of formats 2.0 to 2.2, byte for byte")
{
  // The box table as committed before body-body data (tests/support/format_2_0_box.hpp), before
  // landing data (format_2_1_box.hpp) and at format 2.2 (format_2_2_box.hpp), each from its own
  // command with the option that leaves the newer data out (none for 2.2: settling data is asked
  // for with --settle): every line but the command is the same.
  for (const auto& [input, option] : {std::pair<std::string, std::string>{"format_2_0_box.hpp", "--no-body-contacts"},
                                      {"format_2_1_box.hpp", "--no-landing"},
                                      {"format_2_2_box.hpp", ""}}) {
    CAPTURE(input);
    // The test input's own first lines and its renamed namespace are taken back out.
    std::string old = read_file(std::string(STATSIM_TEST_SOURCE_DIR) + "/tests/support/" + input);
    old = old.substr(old.find("// generated by statsim"));
    const std::string renamed = "statsim::tables_2_" + input.substr(std::strlen("format_2_"), 1);
    for (std::size_t at; (at = old.find(renamed)) != std::string::npos;)
      old.replace(at, renamed.size(), "statsim::tables");
    const std::string prefix = "// command: build/bin/statsim gather ";
    const std::size_t at = old.find(prefix);
    REQUIRE(at != std::string::npos);
    const std::string line = old.substr(at + prefix.size(), old.find('\n', at) - at - prefix.size());
    std::vector<std::string> args;
    std::istringstream words(line);
    for (std::string w; words >> w;) args.push_back(w);
    TempDir dir("gather3d_older");
    const auto out = std::find(args.begin(), args.end(), "--out");
    REQUIRE(out != args.end());
    *(out + 1) = dir.file("box.hpp");
    if (!option.empty()) args.push_back(option);
    args.push_back("--quiet");
    REQUIRE(gather_cli(args) == 0);
    const std::string now = read_file(dir.file("box.hpp"));
    // Written outside the repository's tables/, the table records file names (the command, the
    // line after it, the mesh, the file its format check names): those lines are compared apart.
    const auto without_paths = [](std::string t) {
      const std::size_t a = t.find("// command: "), b = t.find('\n', t.find('\n', a) + 1);
      t = t.substr(0, a) + t.substr(b);
      for (const char* path : {"tools/meshes/box.obj", "tables/box.hpp"})
        for (std::size_t i; (i = t.find(path)) != std::string::npos;) t.replace(i, std::strlen(path), "<path>");
      for (const char* name : {" box.obj", " box.hpp", "\"box.hpp"})
        for (std::size_t i; (i = t.find(name)) != std::string::npos;) t.replace(i + 1, std::strlen(name) - 1, "<path>");
      return t;
    };
    CHECK(now.find(option) != std::string::npos);
    CHECK(now.find("// (paths as file names") != std::string::npos);
    CHECK(without_paths(now) == without_paths(old));
  }
}

TEST_CASE("gather3d: the JSON of a table with body-body data loads with it")
{
  TempDir dir("gather3d_json");
  for (const char* precision : {"f32", "i16"}) {
    CAPTURE(precision);
    const std::string json = dir.file(std::string("t_") + precision + ".json");
    std::vector<std::string> args = tiny_args();
    args.insert(args.end(), {"--precision", precision, "--out", dir.file(std::string("t_") + precision + ".hpp"),
                             "--json", json});
    REQUIRE(gather_cli(args) == 0);
    const nlohmann::json j = nlohmann::json::parse(read_file(json));
    const LoadedSignature3 s = load_signature_json(json);
    const statsim::SignatureView<3> v = s.view();
    REQUIRE(v.contact.present());
    CHECK(v.contact.support_size == 17);
    CHECK(v.contact.face_count == 6);
    CHECK((v.contact.support.i16 != nullptr) == (std::string(precision) == "i16"));
    REQUIRE(v.mesh_frame != nullptr);
    CHECK(v.mesh_frame[0] == 1.0f);
    const nlohmann::json& c = j["body_contacts"];
    const double scale = std::string(precision) == "i16" ? static_cast<double>(v.contact.support.scale) : 0.0;
    for (std::uint32_t k = 0; k < v.contact.support_count(); k += 97)
      CHECK(std::fabs(v.contact.support[k] - c["support"][k].get<double>()) <= 0.5 * scale + 1e-9);
    CHECK(v.contact.pair_mean[1] == c["pair_mean"][1].get<float>());
    CHECK(v.contact.packing_mean[2] == c["packing_mean"][2].get<float>());
    CHECK(statsim::detail::check_signature(v) == statsim::Status::ok);
  }
}

TEST_CASE("gather3d: a table of format 2.2 with landing data whose header compiles and whose JSON loads with it")
{
  TempDir dir("gather3d_landing");
  std::vector<std::string> args = tiny_args();
  args.insert(args.end(), {"--precision", "i16", "--landing-trials", "3", "--landing-froude", "0,16",
                           "--name", "t_landing", "--out", dir.file("t_landing.hpp"), "--json", dir.file("t.json")});
  REQUIRE(gather_cli(args) == 0);
  const std::string text = read_file(dir.file("t_landing.hpp"));
  CHECK(text.find("ContactDataQ16<3, 3, 17, 6>, LandingData<2, 2, 2>>") != std::string::npos);
  CHECK(text.find("#if !defined(STATSIM_TABLE_FORMAT_MINOR) || STATSIM_TABLE_FORMAT_MINOR < 2\n#error ") !=
        std::string::npos);
  CHECK(text.find("// Landing: 12 impacts with gravity (3 per cell") != std::string::npos);  // none at F = 0

  // The JSON: every probability in [-1, 1], each the rule's of its cell's stays and draws.
  const nlohmann::json j = nlohmann::json::parse(read_file(dir.file("t.json")));
  const nlohmann::json& l = j["landing"];
  REQUIRE(l["probability"].size() == 8);
  for (std::size_t c = 0; c < 8; ++c) {
    const double p = l["probability"][c], s = l["stays"][c], q = l["draw_stays"][c];
    CAPTURE(c);
    CHECK(p >= -1);
    CHECK(p <= 1);
    if (c % 2 == 0) {  // F = 0: every impact stays, without trials, and p = 0
      CHECK(s == 1);
      CHECK(q == 1);
      CHECK(p == 0);
    }
    if (s >= q) CHECK(p == doctest::Approx(q < 1 ? (s - q) / (1 - q) : 0.0));
    else CHECK(p == doctest::Approx(-std::min(1.0, (q - s) / (q * (1 - q)))));
  }
  const LoadedSignature3 s = load_signature_json(dir.file("t.json"));
  const statsim::SignatureView<3> v = s.view();
  REQUIRE(v.landing.present());
  CHECK(v.landing.cells() == 8);
  CHECK(v.landing.axes[2].values[1] == 16.0f);
  CHECK(v.landing.probability[3] == l["probability"][3].get<float>());

  // With --no-landing the same command writes no landing data: a table of format 2.1.
  std::vector<std::string> plain = tiny_args();
  plain.insert(plain.end(), {"--precision", "i16", "--no-landing", "--name", "t_plain", "--out", dir.file("t_plain.hpp")});
  REQUIRE(gather_cli(plain) == 0);
  CHECK(read_file(dir.file("t_plain.hpp")).find("LandingData") == std::string::npos);

  check_compiles_and_adds(dir, "t_landing.hpp", "t_landing", "v.landing.present() && v.landing.cells() == 8");
}

TEST_CASE("gather3d: settling-time quantiles stand each order statistic at the middle of its share")
{
  // Four times: the order statistics at the probabilities 1/8, 3/8, 5/8, 7/8; between them linear.
  CHECK(settle_quantiles({0.4, 0.1, 0.3, 0.2}, 4) == std::vector<double>{0.1, 0.2, 0.3, 0.4});
  const std::vector<double> two = settle_quantiles({0.4, 0.1, 0.3, 0.2}, 2);  // at 1/4 and 3/4: h = 0.5, 2.5
  REQUIRE(two.size() == 2);
  CHECK(two[0] == doctest::Approx(0.15));
  CHECK(two[1] == doctest::Approx(0.35));
  // Beyond the first and last order statistics the ends are held; one time is every quantile.
  CHECK(settle_quantiles({0.1, 0.2}, 8).front() == 0.1);
  CHECK(settle_quantiles({0.1, 0.2}, 8).back() == 0.2);
  CHECK(settle_quantiles({0.7}, 3) == std::vector<double>{0.7, 0.7, 0.7});
  CHECK(settle_quantiles({}, 3).empty());
}

TEST_CASE("gather3d: a drop's settling time runs from its last fast step to quiet for good")
{
  // A cube face down, still, its face h = 5 cm above the ground: it falls for sqrt(2 h / g) and
  // strikes faster than the settle speed, then rebounds at the restitution's share, below it.
  const ShapeModel m = load_shape_model("box", "", 1000.0);
  const ReferenceSettings settings;
  const Reference ref(m, settings);
  RigidState s;
  s.position = Eigen::Vector3d(0, 0, 0.15);
  const DropResult never_fast = ref.drop(s, 0.005, 0.25, 10.0, {100.0, 0.01});
  const DropResult fast = ref.drop(s, 0.005, 0.25, 10.0, {0.5, 0.01});
  REQUIRE(fast.settled);
  // The speeds measure the run, they do not change it.
  CHECK(fast.time == never_fast.time);
  CHECK(fast.rest.position == never_fast.rest.position);
  CHECK(fast.height == never_fast.height);
  // Never fast: from the start to quiet, which the bounce puts after the strike and long before
  // the stillness test (two windows of 0.25 s) ends the run. Fast until the strike: less that.
  const double strike = std::sqrt(2 * 0.05 / settings.gravity);
  CHECK(never_fast.settle_time > strike);
  CHECK(never_fast.settle_time < fast.time - 0.4);
  CHECK(never_fast.settle_time - fast.settle_time == doctest::Approx(strike).epsilon(0.03));
  // A quiet speed no step reaches below: the drop counts to the end of its run.
  CHECK(ref.drop(s, 0.005, 0.25, 10.0, {100.0, 1e-12}).settle_time == doctest::Approx(fast.time));
  // Not settled within the time limit: the time limit less the last fast step.
  const DropResult cut = ref.drop(s, 0.005, 0.25, 0.05, {100.0, 0.01});
  CHECK_FALSE(cut.settled);
  CHECK(cut.settle_time == doctest::Approx(0.05));
}

TEST_CASE("gather3d: a table of format 2.3 with settling data whose header compiles and whose JSON loads with it")
{
  TempDir dir("gather3d_settle");
  std::vector<std::string> args = tiny_args();
  args.insert(args.end(), {"--precision", "i16", "--landing-trials", "2", "--landing-froude", "0,16", "--settle",
                           "--settle-quantiles", "5", "--name", "t_settle", "--out", dir.file("t_settle.hpp"), "--json",
                           dir.file("t.json")});
  REQUIRE(gather_cli(args) == 0);
  const std::string text = read_file(dir.file("t_settle.hpp"));
  const nlohmann::json j = nlohmann::json::parse(read_file(dir.file("t.json")));
  const std::size_t poses = j["rest"].size();
  REQUIRE(poses >= 1);
  CHECK(text.find("LandingData<2, 2, 2>, SettleData<" + std::to_string(poses) + ", 5>>") != std::string::npos);
  CHECK(text.find("#if !defined(STATSIM_TABLE_FORMAT_MINOR) || STATSIM_TABLE_FORMAT_MINOR < 3\n#error ") !=
        std::string::npos);
  CHECK(text.find("needs table format 2.3 (settling data): update statsim, or regenerate the table without --settle") !=
        std::string::npos);
  CHECK(text.find("// Settling: the 24 rest drops (") != std::string::npos);

  // The JSON: 5 quantiles a pose, non-decreasing, within the runtime's range; every drop in a pose.
  const nlohmann::json& t = j["settle"];
  CHECK(t["quantiles"] == 5);
  CHECK(t["settle_speed"].get<double>() == static_cast<double>(statsim::WorldDef<3>{}.settle_speed));
  CHECK(t["quiet_speed"].get<double>() == 0.01);
  REQUIRE(t["time"].size() == 5 * poses);
  REQUIRE(t["drops"].size() == poses);
  int drops = 0;
  for (std::size_t p = 0; p < poses; ++p) {
    drops += t["drops"][p].get<int>();
    for (std::size_t k = 0; k < 5; ++k) {
      const double x = t["time"][p * 5 + k];
      CAPTURE(p);
      CAPTURE(k);
      CHECK(x >= 0);
      CHECK(x <= static_cast<double>(statsim::max_settle_time));
      if (k > 0) CHECK(x >= t["time"][p * 5 + k - 1].get<double>());
    }
  }
  CHECK(drops == 24);
  // The header's quantiles are the JSON's, the last numbers of its initialiser.
  const HeaderNumbers h = header_numbers(text);
  REQUIRE(h.floats.size() >= 5 * poses);
  for (std::size_t i = 0; i < 5 * poses; ++i)
    CHECK(h.floats[h.floats.size() - 5 * poses + i] == t["time"][i].get<double>());
  const LoadedSignature3 s = load_signature_json(dir.file("t.json"));
  const statsim::SignatureView<3> v = s.view();
  REQUIRE(v.settle.present());
  CHECK(v.settle.quantiles == 5);
  for (std::size_t i = 0; i < 5 * poses; ++i)
    CHECK(v.settle.time[static_cast<std::uint32_t>(i)] == t["time"][i].get<float>());
  // A JSON whose quantiles do not fill the poses is refused, by name.
  nlohmann::json bad = j;
  bad["settle"]["quantiles"] = 4;
  CHECK_THROWS_WITH_AS(parse_signature_json(bad.dump(), "x.json"), doctest::Contains("x.json: field 'settle.time' has"),
                       std::runtime_error);

  // Without --settle the same command writes no settling data: a table of format 2.2.
  std::vector<std::string> plain = tiny_args();
  plain.insert(plain.end(), {"--precision", "i16", "--landing-trials", "2", "--landing-froude", "0,16",
                             "--name", "t_plain", "--out", dir.file("t_plain.hpp"), "--json", dir.file("p.json")});
  REQUIRE(gather_cli(plain) == 0);
  const std::string plain_text = read_file(dir.file("t_plain.hpp"));
  CHECK(plain_text.find("SettleData") == std::string::npos);
  CHECK(plain_text.find("// Settling:") == std::string::npos);
  CHECK(plain_text.find("STATSIM_TABLE_FORMAT_MINOR < 2\n#error ") != std::string::npos);
  CHECK_FALSE(nlohmann::json::parse(read_file(dir.file("p.json"))).contains("settle"));

  // Speeds the measurement cannot use are refused before any trial, nothing written.
  check_refused(dir, {"--settle", "--quiet-speed", "0.5"}, "--quiet-speed must be positive and below --settle-speed (0.5 m/s)");
  check_refused(dir, {"--settle", "--settle-quantiles", "65"}, "--settle-quantiles must be in [1, 64]");

  check_compiles_and_adds(dir, "t_settle.hpp", "t_settle", "v.settle.present() && v.settle.quantiles == 5");
}

TEST_CASE("gather3d: a response trial's spin by gyration carries its rotational energy")
{
  // A 1 x 2 x 4 box: three different moments, so the two measures differ with the orientation.
  GatherOptions o;
  o.box_size = {0.05, 0.1, 0.2};
  const ShapeModel m = build_model(o);
  const Reference ref(m, o.reference);
  const double L = m.bounding_radius, speed = 2.0;
  for (std::uint64_t i = 0; i < 6; ++i) {
    CAPTURE(i);
    const ResponseTrial t = response_trial(ref, o, 0.7, 0.5, speed, 2.0, kResponseStream, i, false);
    const Eigen::Vector3d w = Eigen::Vector3d(t.value[0], t.value[1], t.value[2]) * (speed / L);
    const Eigen::Vector3d b = t.departure.orientation.conjugate() * w;
    const double energy = 0.5 * (m.unit_inertia.x() * b.x() * b.x() + m.unit_inertia.y() * b.y() * b.y() +
                                 m.unit_inertia.z() * b.z() * b.z());
    const Eigen::Vector3d k(t.gyration[0], t.gyration[1], t.gyration[2]);
    CHECK(0.5 * k.squaredNorm() * speed * speed == doctest::Approx(energy).epsilon(1e-9));
    for (int c = 3; c < 6; ++c) CHECK(t.gyration[c] == t.value[c]);
    CHECK((t.contact.velocity - speed * Eigen::Vector3d(std::sqrt(1 - 0.49), 0, -0.7)).norm() < 1e-9);
  }
}

TEST_CASE("gather3d: with --response-flight a response trial ends at the first flight that rises landing_hop L")
{
  GatherOptions plain;
  plain.box_size = {0.2, 0.2, 0.2};
  GatherOptions flight = plain;
  flight.response_flight = true;
  const ShapeModel m = build_model(plain);
  const Reference ref(m, plain.reference);
  const double L = m.bounding_radius, speed = 3.5, g = plain.reference.gravity, hop = flight.landing_hop * L;
  int flown = 0, plain_low = 0;
  for (std::uint64_t i = 0; i < 24; ++i) {
    CAPTURE(i);
    const ResponseTrial f = response_trial(ref, flight, 1.0, 0.5, speed, 0.25, kResponseStream, i, false);
    const ResponseTrial p = response_trial(ref, plain, 1.0, 0.5, speed, 0.25, kResponseStream, i, false);
    CHECK(f.contact.velocity == p.contact.velocity);  // the same start
    CHECK_FALSE(p.no_flight);
    const double vz = p.departure.velocity.z();
    if (vz * vz / (2 * g) < hop) ++plain_low;  // a separation the drop would not count as a flight
    if (f.no_flight) {
      CHECK(f.value == p.value);  // the gravity-free outcome kept
      continue;
    }
    ++flown;
    // Left for a flight under gravity whose centre rises at least hop: v_z^2 / (2 g) >= hop.
    const double fz = f.departure.velocity.z();
    CHECK(fz > 0);
    CHECK(fz * fz / (2 * g) >= hop);
    CHECK(f.value[5] * speed == doctest::Approx(fz - p.contact.velocity.z() * -flight.reference.restitution).epsilon(1e-6));
  }
  // Both kinds occur here, so the checks above tell the two trials apart.
  CHECK(flown > 0);
  CHECK(plain_low > 0);

  TempDir dir("gather3d_flight");
  check_refused(dir, {"--response-flight", "--no-landing"}, "--response-flight needs the landing data");
}

TEST_CASE("gather3d: a response trial by energy meets the ground at its cell's spin ratio by energy")
{
  GatherOptions o;
  o.box_size = {0.05, 0.1, 0.2};
  const ShapeModel m = build_model(o);
  const Reference ref(m, o.reference);
  const double L = m.bounding_radius, speed = 2.0, ratio = 2.0, k = std::sqrt(m.unit_inertia.sum() / 3);
  // |K W| L / (k |V-|), K at the body's orientation: a free flight keeps the rotational energy,
  // so it is the same at the first contact as at the start.
  const auto by_energy = [&](const RigidState& s) {
    const Eigen::Vector3d b = s.orientation.conjugate() * s.spin;
    return std::sqrt(m.unit_inertia.dot(b.cwiseProduct(b))) * L / (k * speed);
  };
  for (std::uint64_t i = 0; i < 6; ++i) {
    CAPTURE(i);
    const ResponseTrial e = response_trial(ref, o, 0.7, 0.5, speed, ratio, kResponseStream, i, true);
    const ResponseTrial l = response_trial(ref, o, 0.7, 0.5, speed, ratio, kResponseStream, i, false);
    CHECK(by_energy(e.contact) == doctest::Approx(ratio).epsilon(1e-9));
    CHECK(e.contact.velocity.isApprox(l.contact.velocity, 1e-12));
  }
  // The spin itself: by length |W| L / |V-| is the ratio about any axis; by energy the same axis,
  // longer about the body's long axis (the least moment) than about its shortest (the largest), by
  // sqrt(I_max / I_min) = sqrt((0.1^2 + 0.2^2) / (0.05^2 + 0.1^2)) = 2.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  Eigen::Index least = 0, largest = 0;
  m.unit_inertia.minCoeff(&least);
  m.unit_inertia.maxCoeff(&largest);
  const Eigen::Vector3d long_axis = q * Eigen::Vector3d::Unit(least), short_axis = q * Eigen::Vector3d::Unit(largest);
  for (const Eigen::Vector3d& axis : {long_axis, short_axis}) {
    const Eigen::Vector3d wl = trial_spin(m, q, axis, ratio, speed, false), we = trial_spin(m, q, axis, ratio, speed, true);
    CHECK(wl.norm() * L / speed == doctest::Approx(ratio).epsilon(1e-12));
    CHECK(wl.normalized().isApprox(axis, 1e-12));
    CHECK(we.normalized().isApprox(axis, 1e-12));
    RigidState s;
    s.orientation = q;
    s.spin = we;
    CHECK(by_energy(s) == doctest::Approx(ratio).epsilon(1e-12));
  }
  CHECK(trial_spin(m, q, long_axis, ratio, speed, true).norm() ==
        doctest::Approx(2 * trial_spin(m, q, short_axis, ratio, speed, true).norm()).epsilon(1e-12));
}

TEST_CASE("gather3d: a table of format 2.4 with the spin by gyration whose header compiles and whose JSON loads with it")
{
  TempDir dir("gather3d_spin");
  // The tiny configuration on a 1 x 2 x 4 box instead of the cube (--box-size excludes --shape).
  const auto thin_box = []() {
    std::vector<std::string> a = tiny_args();
    a.erase(a.begin(), a.begin() + 2);
    a.insert(a.end(), {"--box-size", "0.05,0.1,0.2"});
    return a;
  };
  std::vector<std::string> args = thin_box();
  args.insert(args.end(), { "--landing-trials", "2", "--landing-froude", "0,16",
                           "--response-spin", "gyration", "--name", "t_spin", "--out", dir.file("t_spin.hpp"), "--json",
                           dir.file("t.json")});
  REQUIRE(gather_cli(args) == 0);
  const std::string text = read_file(dir.file("t_spin.hpp"));
  const nlohmann::json j = nlohmann::json::parse(read_file(dir.file("t.json")));
  CHECK(text.find("#if !defined(STATSIM_TABLE_FORMAT_MINOR) || STATSIM_TABLE_FORMAT_MINOR < 4\n#error ") !=
        std::string::npos);
  CHECK(text.find("needs table format 2.4 (spin by gyration): update statsim, or regenerate the table with "
                  "--response-spin length") != std::string::npos);
  CHECK(text.find("// Response spin: by gyration, K W+ / |V-| (statsim::ResponseSpin::gyration); test: ") != std::string::npos);
  CHECK(text.find("    {},  // no settling data\n    statsim::ResponseSpin::gyration,") != std::string::npos);
  CHECK(j["response"]["spin"] == "gyration");
  // Given, the test is still run and reported, for the header and the JSON.
  REQUIRE(j["response"].contains("spin_test"));
  CHECK(text.find("; test: KS of |V+| and |W+| against the trials by gyration ") != std::string::npos);
  const LoadedSignature3 s = load_signature_json(dir.file("t.json"));
  CHECK(s.view().spin == statsim::ResponseSpin::gyration);
  // A JSON naming another measure is refused, by name.
  nlohmann::json bad = j;
  bad["response"]["spin"] = "momentum";
  CHECK_THROWS_WITH_AS(parse_signature_json(bad.dump(), "x.json"),
                       doctest::Contains("x.json: field 'response.spin' is not"), std::runtime_error);

  // The default chooses, and reports its test: gyration only below length's distance by the margin.
  std::vector<std::string> chosen = thin_box();
  chosen.insert(chosen.end(), {"--landing-trials", "2", "--landing-froude", "0,16",
                               "--name", "t_auto", "--out", dir.file("t_auto.hpp"), "--json", dir.file("a.json")});
  REQUIRE(gather_cli(chosen) == 0);
  const nlohmann::json a = nlohmann::json::parse(read_file(dir.file("a.json")));
  REQUIRE(a["response"].contains("spin_test"));
  const nlohmann::json& test = a["response"]["spin_test"];
  const double n = test["draws"].get<double>();
  CHECK(n == a["response"]["trials"].get<double>());
  CHECK(test["critical"].get<double>() == doctest::Approx(1.358 * std::sqrt(2.0 / n)));
  const bool gyration = test["ks_gyration"].get<double>() < test["ks_length"].get<double>() - test["critical"].get<double>();
  CHECK(a["response"].contains("spin") == gyration);
  if (gyration) CHECK(a["response"]["spin"] == "energy");  // where gyration wins, auto takes energy
  // --response-spin length neither tests nor names the measure: the table of format 2.2.
  std::vector<std::string> plain = tiny_args();
  plain.insert(plain.end(), {"--landing-trials", "2", "--landing-froude", "0,16", "--response-spin", "length",
                             "--name", "t_plain", "--out", dir.file("t_plain.hpp"), "--json", dir.file("p.json")});
  REQUIRE(gather_cli(plain) == 0);
  const nlohmann::json p = nlohmann::json::parse(read_file(dir.file("p.json")));
  CHECK_FALSE(p["response"].contains("spin"));
  CHECK_FALSE(p["response"].contains("spin_test"));
  CHECK(read_file(dir.file("t_plain.hpp")).find("STATSIM_TABLE_FORMAT_MINOR < 2\n#error ") != std::string::npos);

  // Gyration without the landing data it follows in a table is refused before any work.
  check_refused(dir, {"--response-spin", "gyration", "--no-landing"}, "--response-spin gyration needs the landing data");
  check_refused(dir, {"--response-spin", "energy", "--no-landing"}, "--response-spin energy needs the landing data");

  // By energy (format 2.5): the trials made at ratios by energy, so the means differ from the
  // table by gyration of the same seed; no test is run.
  std::vector<std::string> energy = thin_box();
  energy.insert(energy.end(), {"--landing-trials", "2", "--landing-froude", "0,16", "--response-spin", "energy",
                               "--name", "t_energy", "--out", dir.file("t_energy.hpp"), "--json", dir.file("e.json")});
  REQUIRE(gather_cli(energy) == 0);
  const std::string etext = read_file(dir.file("t_energy.hpp"));
  const nlohmann::json e = nlohmann::json::parse(read_file(dir.file("e.json")));
  CHECK(etext.find("#if !defined(STATSIM_TABLE_FORMAT_MINOR) || STATSIM_TABLE_FORMAT_MINOR < 5\n#error ") !=
        std::string::npos);
  CHECK(etext.find("needs table format 2.5 (spin by energy): update statsim, or regenerate the table with "
                   "--response-spin gyration") != std::string::npos);
  CHECK(etext.find("    {},  // no settling data\n    statsim::ResponseSpin::energy,") != std::string::npos);
  CHECK(e["response"]["spin"] == "energy");
  CHECK_FALSE(e["response"].contains("spin_test"));
  CHECK(e["response"]["mean"] != j["response"]["mean"]);
  CHECK(load_signature_json(dir.file("e.json")).view().spin == statsim::ResponseSpin::energy);

  check_compiles_and_adds(dir, "t_spin.hpp", "t_spin", "v.spin == statsim::ResponseSpin::gyration");
  check_compiles_and_adds(dir, "t_energy.hpp", "t_energy", "v.spin == statsim::ResponseSpin::energy");
}
