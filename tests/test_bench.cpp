// The shared drop scenes (tools/scenes) and `statsim bench` on a tiny configuration. Whole-scene
// timing is a benchmark, not a test: nothing here asserts a time beyond "finite and positive".
#include "bench/bench.hpp"
#include "bench/bench_internal.hpp"
#include "bullet/drop_world.hpp"
#include "scenes/piles.hpp"
#include "scenes/scenes.hpp"
#include "statsim/detail/state_hash.hpp"
#include "statsim/signature.hpp"

#include <doctest/doctest.h>

#include "support/csv.hpp"
#include "support/text_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace statsim::tools;

namespace {

scenes::DropOptions options(int n, std::uint64_t seed = 7)
{
  scenes::DropOptions o;
  o.count = n;
  o.bounding_radius = 0.1608;
  o.seed = seed;
  return o;
}

bool same(const scenes::BodyState3& a, const scenes::BodyState3& b)
{
  return a.position == b.position && a.orientation.coeffs() == b.orientation.coeffs() &&
         a.linear_velocity == b.linear_velocity && a.angular_velocity == b.angular_velocity;
}

using statsim::testing::csv_fields;

using statsim::testing::lines_of;
using statsim::testing::read_file;

void check_cells(const BenchResult& r)
{
  for (const BenchCell& c : r.cells) {
    INFO(c.method << "/" << c.broadphase << " N=" << c.n << ": " << c.note);
    REQUIRE_FALSE(c.skipped);
    CHECK(c.repeats == r.options.repeats);
    CHECK(std::isfinite(c.step_ms_median));
    CHECK(c.step_ms_median > 0);
    CHECK(c.step_ms_min > 0);
    CHECK(c.step_ms_min <= c.step_ms_median);
    CHECK(c.step_ms_median <= c.step_ms_max);
    CHECK(c.step_ms_envelope > 0);
    CHECK(c.step_ms_envelope <= c.step_ms_min * (1 + 1e-12));  // the envelope is below every repeat
    CHECK(std::isfinite(c.mean_height_end));
    CHECK(c.fall_steps >= 0);
    CHECK(c.fall_steps <= c.steps);
    CHECK(std::isfinite(c.cpu_ms));
    CHECK(c.cpu_ms >= 0);  // thread CPU time, read once per repeat
    if (c.engine == "statsim") {
      CHECK(c.collision_ms < 0);  // n/a
    } else {
      CHECK(c.collision_ms >= 0);
      CHECK(std::isfinite(c.response_ms));
    }
  }
}

void check_csv(const BenchResult& r)
{
  const std::vector<std::string> lines = lines_of(bench_csv(r));
  REQUIRE(lines.size() == r.cells.size() + 1);
  const std::vector<std::string> header = csv_fields(lines[0]);
  const char* required[] = {"method", "n", "broadphase", "step_ms_median", "step_ms_min",
                            "step_ms_max", "collision_ms", "response_ms"};
  REQUIRE(header.size() >= 8);
  for (std::size_t i = 0; i < 8; ++i) CHECK(header[i] == required[i]);
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const std::vector<std::string> f = csv_fields(lines[k]);
    REQUIRE(f.size() == header.size());
    CHECK(f[0] == r.cells[k - 1].method);
    CHECK(std::stoi(f[1]) == r.cells[k - 1].n);
    const double t = std::stod(f[3]);
    CHECK(std::isfinite(t));
    CHECK(t > 0);
  }
}

void check_markdown(const BenchResult& r)
{
  const std::string md = bench_markdown(r);
  CHECK(md.find("| N | type |") != std::string::npos);
  CHECK(md.find("one step") != std::string::npos);
  CHECK(md.find("collision") != std::string::npos);
  CHECK(md.find("response") != std::string::npos);
  CHECK(md.find("## Settings") != std::string::npos);
  // Every table row has as many cells as its header.
  std::size_t header_bars = 0;
  for (const std::string& line : lines_of(md)) {
    if (line.rfind("| N | type |", 0) == 0) header_bars = static_cast<std::size_t>(std::count(line.begin(), line.end(), '|'));
    if (line.empty()) header_bars = 0;
    if (header_bars && line.rfind("|", 0) == 0)
      CHECK(static_cast<std::size_t>(std::count(line.begin(), line.end(), '|')) == header_bars);
  }
}

}  // namespace

TEST_CASE("drop scene 3D is deterministic and differs between seeds")
{
  const scenes::DropScene3 a = scenes::drop_scene3(options(200));
  const scenes::DropScene3 b = scenes::drop_scene3(options(200));
  const scenes::DropScene3 c = scenes::drop_scene3(options(200, 8));
  REQUIRE(a.bodies.size() == 200);
  REQUIRE(b.bodies.size() == 200);
  bool all_same = true, any_differs = false;
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    all_same = all_same && same(a.bodies[i], b.bodies[i]);
    any_differs = any_differs || !same(a.bodies[i], c.bodies[i]);
  }
  CHECK(all_same);
  CHECK(any_differs);
  CHECK(a.region.radius == b.region.radius);
  CHECK(a.region.height == b.region.height);
}

TEST_CASE("drop scene 3D places bodies inside the cylinder without overlap")
{
  for (int n : {1, 10, 100, 1000}) {
    INFO("N = " << n);
    const scenes::DropScene3 s = scenes::drop_scene3(options(n));
    const double r = s.options.bounding_radius, tol = 1e-9;
    REQUIRE(s.bodies.size() == static_cast<std::size_t>(n));
    for (const scenes::BodyState3& b : s.bodies) {
      CHECK(std::hypot(b.position.x(), b.position.y()) + r <= s.region.radius + tol);
      CHECK(b.position.z() - r >= s.region.bottom - tol);
      CHECK(b.position.z() + r <= s.region.bottom + s.region.height + tol);
      CHECK(b.position.z() - r > 0);  // above the ground
      CHECK(std::fabs(b.orientation.norm() - 1) < 1e-12);
      CHECK(b.linear_velocity.cwiseAbs().maxCoeff() <= s.options.max_speed);
      CHECK(b.angular_velocity.cwiseAbs().maxCoeff() <= s.options.max_spin);
      for (int a = 0; a < 3; ++a) {
        CHECK(b.position[a] > s.bounds_lo[a]);
        CHECK(b.position[a] < s.bounds_hi[a]);
      }
    }
    // Bounding spheres do not overlap.
    CHECK(scenes::min_centre_distance(s.bodies, s.cell) >= 2 * r - tol);
  }
}

TEST_CASE("drop scene region grows with N")
{
  double last_radius = 0, last_height = 0;
  for (int n : {10, 100, 1000, 10000}) {
    const scenes::DropScene3 s = scenes::drop_scene3(options(n));
    CHECK(s.region.radius >= last_radius);
    CHECK(s.region.height >= last_height);
    last_radius = s.region.radius;
    last_height = s.region.height;
  }
  // N^(1/3) growth: 1000 times the bodies, about 10 times the radius (not 1000, not 30).
  const double ratio = scenes::drop_scene3(options(10000)).region.radius / scenes::drop_scene3(options(10)).region.radius;
  CHECK(ratio > 4);
  CHECK(ratio < 12);
}

TEST_CASE("drop scene 2D is deterministic and places bodies without overlap")
{
  scenes::DropOptions o = options(300);
  o.bounding_radius = 0.70710678118654752;
  const scenes::DropScene2 a = scenes::drop_scene2(o);
  const scenes::DropScene2 b = scenes::drop_scene2(o);
  REQUIRE(a.bodies.size() == 300);
  const double r = o.bounding_radius, tol = 1e-9;
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    const scenes::BodyState2& p = a.bodies[i];
    CHECK(p.position == b.bodies[i].position);
    CHECK(p.angle == b.bodies[i].angle);
    CHECK(std::fabs(p.position.x()) + r <= a.region.half_width + tol);
    CHECK(p.position.y() - r >= a.region.bottom - tol);
    CHECK(p.position.y() + r <= a.region.bottom + a.region.height + tol);
  }
  CHECK(scenes::min_centre_distance(a.bodies, a.cell) >= 2 * r - tol);
}

TEST_CASE("drop scene rejects bad options")
{
  scenes::DropOptions o = options(0);
  CHECK_THROWS_AS(scenes::drop_scene3(o), std::invalid_argument);
  o = options(10);
  o.bounding_radius = -1;
  CHECK_THROWS_AS(scenes::drop_scene3(o), std::invalid_argument);
  o = options(10);
  o.fill = 0;
  CHECK_THROWS_AS(scenes::drop_scene2(o), std::invalid_argument);
}

TEST_CASE("bench 3D tiny configuration runs every method")
{
  BenchOptions o;
  o.dim = 3;
  o.counts = {10};
  o.methods = {"full", "low", "hull", "spheres7", "sphere", "statistical"};
  o.broadphases = {"sap", "dbvt"};
  o.steps = 4;
  o.warmup = 1;
  o.repeats = 2;
  o.progress = false;
  const BenchResult r = run_bench(o);
  CHECK(r.cells.size() == 5 * 2 + 1);
  check_cells(r);
  check_csv(r);
  check_markdown(r);

  // The chart, drawn from bench_csv() by tools/plot/bench.py: one line per method and broad
  // phase, read back from the CSV.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "statsim_test_bench";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::filesystem::path png = dir / "bench.png";
  write_bench_chart(r, png);
  CHECK(read_file(png).compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) == 0);
  CHECK(std::filesystem::file_size(png) > 1000);
  const std::string svg = read_file(dir / "bench.svg");
  CHECK(svg.find("ms per step (median of repeats)") != std::string::npos);
  CHECK(svg.find("thread CPU") == std::string::npos);
  for (const char* name : {"full (sap)", "full (dbvt)", "low (dbvt)", "sphere (sap)", "statistical (statsim)"}) {
    CAPTURE(name);
    CHECK(svg.find(name) != std::string::npos);
  }
  // The CPU-time chart (what --chart-cpu draws).
  BenchResult cpu = r;
  cpu.options.chart_cpu = true;
  write_bench_chart(cpu, dir / "bench_cpu.png");
  CHECK(read_file(dir / "bench_cpu.svg").find("thread CPU ms per step") != std::string::npos);
  // Nothing to draw when every cell was skipped: an error naming the problem.
  BenchResult skipped = r;
  for (BenchCell& c : skipped.cells) c.skipped = true;
  std::string message;
  try {
    write_bench_chart(skipped, dir / "none.png");
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  CHECK(message.find("all skipped") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "none.png"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("bench 2D tiny configuration runs every method")
{
  BenchOptions o;
  o.dim = 2;
  o.shape = "square";
  o.counts = {10};
  o.steps = 4;
  o.warmup = 1;
  o.repeats = 1;
  o.progress = false;
  const BenchResult r = run_bench(o);
  // polygon, circle, statistical (the automatic broad phase), statistical-grid, statistical-sap.
  CHECK(r.cells.size() == 5);
  check_cells(r);
  check_csv(r);
  check_markdown(r);
}

TEST_CASE("bench skips a cell over the step limit and says why")
{
  BenchOptions o;
  o.counts = {10, 20};
  o.methods = {"full"};
  o.broadphases = {"sap"};
  o.steps = 12;
  o.warmup = 1;
  o.repeats = 1;
  o.limit_ms = 1e-6;  // every step is over it
  o.progress = false;
  const BenchResult r = run_bench(o);
  REQUIRE(r.cells.size() == 2);
  for (const BenchCell& c : r.cells) {
    CHECK(c.skipped);
    CHECK(c.note.find("limit") != std::string::npos);
  }
  CHECK(bench_markdown(r).find("skipped") != std::string::npos);
}

TEST_CASE("bench rejects bad options")
{
  BenchOptions o;
  o.methods = {"nonsense"};
  CHECK_THROWS_AS(validate_bench_options(o), std::invalid_argument);
  o = BenchOptions{};
  o.broadphases = {"octree"};
  CHECK_THROWS_AS(validate_bench_options(o), std::invalid_argument);
  o = BenchOptions{};
  o.counts = {0};
  CHECK_THROWS_AS(validate_bench_options(o), std::invalid_argument);
  o = BenchOptions{};
  o.dt = -1;
  CHECK_THROWS_AS(validate_bench_options(o), std::invalid_argument);
}

TEST_CASE("Bullet drop world: spheres fall onto the planes, come to rest and deactivate")
{
  bullet::Shapes shapes;
  bullet::DropBody body;
  const double r = 0.1;
  body.shape = shapes.sphere(r);
  body.mass = 1.0;
  body.inertia = Eigen::Vector3d::Constant(0.4 * r * r);
  body.bounding_radius = r;
  std::vector<scenes::BodyState3> states(2);
  states[0].position = Eigen::Vector3d(0, 0, 1);
  states[1].position = Eigen::Vector3d(1, 0, 0.5);
  bullet::DropSettings settings;
  settings.restitution = 0.0;
  // A second plane, tilted, far away: planes are added as given.
  settings.planes.push_back({Eigen::Vector3d(1, 0, 1).normalized(), -10.0});
  bullet::DropWorld world(body, states, settings);
  REQUIRE(world.size() == 2);
  CHECK(world.state(0).position == states[0].position);
  world.step(1.0 / 60);
  CHECK(world.state(0).linear_velocity.z() < 0);  // gravity pulls down
  for (int k = 0; k < 600; ++k) world.step(1.0 / 60);
  for (std::size_t i = 0; i < world.size(); ++i) {
    CHECK(world.state(i).position.z() == doctest::Approx(r).epsilon(0.02));
    CHECK(world.asleep(i));
  }
  CHECK(world.asleep_count() == 2);
  CHECK(world.touching_pairs() == 2);
  CHECK(world.deepest_penetration() < 0.01 * r);

  // Without deactivation nothing sleeps; four substeps of dt / 4 reach the same rest.
  settings.sleeping = false;
  bullet::DropWorld awake(body, states, settings);
  for (int k = 0; k < 300; ++k) awake.step(1.0 / 60, 4);
  CHECK(awake.asleep_count() == 0);
  CHECK(awake.state(0).position.z() == doctest::Approx(r).epsilon(0.02));
}

TEST_CASE("bench: a heap's waiting bodies stay put, asleep, until placed; a placed body falls (statsim and Bullet)")
{
  const bench::Body3 body = bench::load_body3("box", "");
  scenes::HeapOptions o;
  o.count = 3;
  o.bounding_radius = body.bounding_radius;
  const scenes::PileScene3 sc = scenes::heap_scene(o);
  statsim::SignatureView<3> sig{};
  REQUIRE(bench::statsim_table3("box", sig));
  std::vector<std::unique_ptr<bench::Sim>> sims;
  sims.push_back(bench::make_statsim3_table(sig, body.mass, sc.as_drop_scene(), 1, 1.0 / 60.0, "", {}));
  const bullet::DropSettings settings = bench::bullet_drop_settings(body, "full", "dbvt", sc.as_drop_scene());
  sims.push_back(bench::make_bullet(bench::make_bullet_shapes(body), "full", settings, sc.bodies, 1.0 / 60.0));
  for (const auto& sim : sims) {
    sim->place_body(0, sc.release[0]);
    CHECK_FALSE(sim->body_asleep(0));
    for (int k = 0; k < 30; ++k) sim->step();
    // Released at 1 m/s downwards from the nozzle (0.94 m for 3 boxes): on the ground within half a
    // second, its centre below half the nozzle's height.
    CHECK(sim->body_state(0).position.z() < 0.5 * sc.release[0].position.z());
    for (std::size_t i = 1; i < 3; ++i) {
      CHECK(sim->body_asleep(i));
      // Unmoved, to statsim's single precision.
      CHECK((sim->body_state(i).position - sc.bodies[i].position).norm() < 1e-5);
    }
  }
}

TEST_CASE("bench: in a mixed world each body has its own shape (statsim and Bullet, box and bunny)")
{
  const bench::Body3 box = bench::load_body3("box", "");
  const bench::Body3 bunny = bench::load_body3("bunny", "");
  statsim::SignatureView<3> box_sig{}, bunny_sig{};
  REQUIRE(bench::statsim_table3("box", box_sig));
  REQUIRE(bench::statsim_table3("bunny", bunny_sig));
  // A box and a bunny side by side, apart, dropped from rest from 0.3 m; the box lands on a face.
  scenes::DropScene3 scene;
  scene.bodies.resize(2);
  scene.bodies[0].position = Eigen::Vector3d(0, 0, 0.3);
  scene.bodies[1].position = Eigen::Vector3d(1, 0, 0.3);
  scene.bounds_lo = Eigen::Vector3d(-3, -3, -1);
  scene.bounds_hi = Eigen::Vector3d(3, 3, 3);
  const std::vector<int> of_body{0, 1};
  std::vector<std::unique_ptr<bench::Sim>> sims;
  sims.push_back(bench::make_statsim3_mixed({box_sig, bunny_sig}, {box.mass, bunny.mass}, of_body, scene, 1,
                                            1.0 / 60.0, {}));
  const bullet::DropSettings settings = bench::bullet_drop_settings(box, "full", "dbvt", scene);
  sims.push_back(bench::make_bullet_mixed({bench::make_bullet_shapes(box), bench::make_bullet_shapes(bunny)}, of_body,
                                          "full", settings, scene.bodies, 1.0 / 240.0));
  for (std::size_t k = 0; k < sims.size(); ++k) {
    CAPTURE(k);
    for (int s = 0; s < (k == 0 ? 180 : 720); ++s) sims[k]->step();
    // Resting: the box's centre half its side up, the bunny's at one of its poses (0.058 to 0.072 m).
    CHECK(sims[k]->body_state(0).position.z() == doctest::Approx(0.1).epsilon(0.05));
    CHECK(sims[k]->body_state(1).position.z() > 0.05);
    CHECK(sims[k]->body_state(1).position.z() < 0.08);
  }
  // One shape index per body, and in range.
  CHECK_THROWS(bench::make_statsim3_mixed({box_sig, bunny_sig}, {box.mass, bunny.mass}, {0}, scene, 1, 1.0 / 60.0, {}));
  CHECK_THROWS(bench::make_bullet_mixed({bench::make_bullet_shapes(box)}, {0, 1}, "full", settings, scene.bodies,
                                        1.0 / 240.0));
}

TEST_CASE("bench: statsim's worlds run the library's default model, and --body-contacts spheres the paper's")
{
  // One default everywhere (tools/fidelity/README.md, "One default"): the bench's and the
  // fidelity tool's worlds take `WorldDef`'s defaults but for the seed, so a default changed in
  // the runtime is the default they measure. Compared through the hash of every parameter.
  const auto def_hash = [](const auto& def) {
    statsim::detail::Fnv1a h;
    statsim::detail::hash_def(h, def);
    return h.value;
  };
  const bench::StatsimVariant by_default;
  statsim::WorldDef<3> library3;
  library3.seed = 11;
  statsim::WorldDef<2> library2;
  library2.seed = 11;
  CHECK(def_hash(bench::statsim_world_def<3>(11, "", by_default)) == def_hash(library3));
  CHECK(def_hash(bench::statsim_world_def<2>(11, "", by_default)) == def_hash(library2));
  bench::StatsimVariant spheres;
  spheres.hull_contacts = false;
  const statsim::WorldDef<3> paper = bench::statsim_world_def<3>(11, "", spheres);
  CHECK(paper.body_contacts == statsim::BodyContacts::collision_spheres);
  CHECK(def_hash(paper) != def_hash(library3));
}
