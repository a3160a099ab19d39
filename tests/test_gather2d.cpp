// `statsim gather2d` and `statsim compare2d` (tools/ref2d): polygons, reproducible tables, rest
// poses, the committed tables, and the comparison with Box2D. Small configurations only.
#include <doctest/doctest.h>

#include "common/commands.hpp"
#include "ref2d/compare2d.hpp"
#include "ref2d/gather2d.hpp"
#include "ref2d/polygon2d.hpp"
#include "support/temp_dir.hpp"

#include "statsim/world2.hpp"

#include "tables/lshape2d.hpp"
#include "tables/square2d.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

using namespace statsim::tools;

using namespace statsim::testing;

namespace {

constexpr double kHalfDiagonal = 0.70710678118654752440;

// A gather small enough for a sanitizer build: a few axis samples and trials.
Gather2dOptions tiny(unsigned threads)
{
  Gather2dOptions o;
  o.shape = "lshape";
  o.name = "tiny2d";
  o.seed = 11;
  o.height_ratios = {0.0, 1.0, 4.0};
  o.height_trials = 6;
  o.cos_thetas = {0.5, 1.0};
  o.signed_spins = {-1.5, 0.0, 1.5};
  o.speeds = {1.5, 4.0};
  o.trials = 3;
  o.rest_drops = 20;
  o.pair_trials = 6;
  o.packing_piles = 1;
  o.packing_count = 20;
  o.packing_steps = 300;
  o.threads = threads;
  return o;
}

// Runs `statsim ARGS...` through the real command registration; returns the exit code.
int run_command(std::vector<std::string> args)
{
  CLI::App app;
  app.require_subcommand(1);
  register_gather2d_commands(app);
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code();
  }
  return 0;
}

double polygon_area(const std::vector<Point2>& v)
{
  double a = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Point2 p = v[i], q = v[(i + 1) % v.size()];
    a += 0.5 * (p.x * q.y - q.x * p.y);
  }
  return a;
}

void check_convex_tiling(const Shape2& s)
{
  double sum = 0.0;
  for (const std::vector<Point2>& piece : s.pieces) {
    REQUIRE(piece.size() >= 3);
    REQUIRE(piece.size() <= 8);
    for (std::size_t i = 0; i < piece.size(); ++i) {
      const Point2 a = piece[i], b = piece[(i + 1) % piece.size()], c = piece[(i + 2) % piece.size()];
      CHECK((b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x) > 0.0);  // strictly convex, CCW
    }
    sum += polygon_area(piece);
  }
  CHECK(sum == doctest::Approx(s.area).epsilon(1e-12));
}

template <class Sig>
void check_committed_table(const Sig& table, double h_min, double h_max, std::size_t poses)
{
  const statsim::SignatureView<2> v = table.view();
  CHECK(v.layout == statsim::ResponseLayout::with_speed);
  REQUIRE(v.response.axis_count == 3);
  CHECK(v.response.components == 3);
  CHECK(v.restitution_threshold == doctest::Approx(1.0));
  CHECK(v.length == doctest::Approx(h_max).epsilon(1e-6));
  for (std::uint32_t a = 0; a < 3; ++a) {
    for (std::uint32_t i = 1; i < v.response.axes[a].size; ++i) {
      CHECK(v.response.axes[a].values[i] > v.response.axes[a].values[i - 1]);
    }
  }
  const statsim::AxisView& hs = v.height.spin_ratio;
  CHECK(hs.values[0] == 0.0f);
  for (std::uint32_t i = 0; i < hs.size; ++i) {
    if (i > 0) {
      CHECK(hs.values[i] > hs.values[i - 1]);
    }
    CHECK(v.height.mean[i] >= h_min);
    CHECK(v.height.mean[i] <= h_max * 1.0001);
    CHECK(v.height.stddev[i] >= 0.0f);
  }
  // The spread shrinks and the mean rises with spin (paper Figure 3).
  CHECK(v.height.mean[hs.size - 1] > v.height.mean[0]);
  CHECK(v.height.stddev[hs.size - 1] < v.height.stddev[0]);
  const std::uint32_t n = table.cells * 3;
  for (std::uint32_t i = 0; i < n; ++i) {
    CHECK(std::isfinite(v.response.mean[i]));
    CHECK(v.response.spread[i] >= 0.0f);
  }
  REQUIRE(v.rest.count == poses);
  double total = 0.0;
  for (std::uint32_t k = 0; k < v.rest.count; ++k) {
    const statsim::Vector2 u = v.rest.normal(k);
    CHECK(u.norm() == doctest::Approx(1.0).epsilon(1e-6));
    CHECK(v.rest.frequencies[k] > 0.05f);
    total += static_cast<double>(v.rest.frequencies[k]);
  }
  CHECK(total <= 1.0 + 1e-6);
  // The runtime accepts it.
  statsim::World2<4> world;
  CHECK(world.add_shape(v).status == statsim::Status::ok);
}

}  // namespace

TEST_CASE("gather2d: polygons are validated and split into convex Box2D pieces")
{
  const Shape2 sq = square_shape();
  CHECK(sq.area == doctest::Approx(1.0));
  CHECK(sq.polar_inertia / sq.area == doctest::Approx(1.0 / 6.0));
  CHECK(sq.bounding_radius == doctest::Approx(kHalfDiagonal));
  CHECK(sq.pieces.size() == 1);
  CHECK(sq.support_height({0.0, 1.0}) == doctest::Approx(0.5));

  const Shape2 l = lshape_shape();
  CHECK(l.area == doctest::Approx(0.4375));
  CHECK(l.offset.x == doctest::Approx(0.1484375 / 0.4375));
  CHECK(l.offset.y == doctest::Approx(0.1484375 / 0.4375));
  check_convex_tiling(l);
  CHECK(l.hull.size() == 5);

  // A concave comb of 12 vertices, given clockwise: normalised and tiled.
  const Shape2 comb = make_shape(parse_polygon("0,0 0,1 0.3,1 0.3,0.4 0.5,0.4 0.5,1 0.8,1 0.8,0.4 1,0.4 1,1 1.3,1 1.3,0"),
                                 "polygon", "comb");
  CHECK(comb.area > 0.0);
  check_convex_tiling(comb);
  CHECK(comb.outline.size() == 12);

  const auto rejects = [](const std::string& spec, const std::string& why) {
    try {
      (void)make_shape(parse_polygon(spec), "polygon", "bad");
      FAIL("accepted a bad polygon: " << spec);
    } catch (const std::invalid_argument& e) {
      CHECK_MESSAGE(std::string(e.what()).find(why) != std::string::npos, e.what());
    }
  };
  rejects("0,0 1,0", "at least 3 vertices");
  rejects("0,0 1,0 2,0", "zero area");
  rejects("0,0 1,1 1,0 0,1", "self-intersecting");
  rejects("0,0 1,0 1,1 0,1 1.5,0.5", "self-intersecting");
  rejects("0,0 1,0 0,0 1,1", "coincide");
  rejects("0,0 x,1 1,1", "not a number");
  rejects("0,0 1;0 1,1", "not of the form x,y");
  rejects("0,0 1,0 1,inf", "finite");
  rejects("0,0 1,0 1,0.001 0,0.001", "too thin");
}

TEST_CASE("gather2d: a tiny gather gives byte-identical headers across runs and thread counts")
{
  const std::string command = "build/bin/statsim gather2d --shape lshape --out tables/tiny2d.hpp";
  const std::string one = gather2d_header(run_gather2d(tiny(1)), command);
  const Gather2dResult r2 = run_gather2d(tiny(2));
  const std::string two = gather2d_header(r2, command);
  const std::string again = gather2d_header(run_gather2d(tiny(2)), command);
  CHECK(one == two);
  CHECK(two == again);
  Gather2dOptions other = tiny(2);
  other.seed = 12;
  CHECK(gather2d_header(run_gather2d(other), command) != one);

  // The documented layout.
  CHECK(one.rfind("// generated by statsim gather2d \xE2\x80\x94 do not edit\n// command: " + command + "\n", 0) == 0);
  CHECK(one.find("#pragma once\n\n#include \"statsim/signature.hpp\"") != std::string::npos);
  CHECK(one.find("static_assert(STATSIM_TABLE_FORMAT_VERSION == 2") != std::string::npos);
  CHECK(one.find("inline constexpr Signature<2, 3, 2, 3, 2, 1, ") != std::string::npos);
  CHECK(one.find("> tiny2d = {") != std::string::npos);
  CHECK(one.find("nan") == std::string::npos);
  CHECK(one.find("inf") == std::string::npos);

  // A value that is not finite (or not finite as a float) is refused, not written.
  for (const double bad : {std::nan(""), HUGE_VAL, 1e39}) {
    Gather2dResult r = r2;
    r.cells[1].mean[2] = bad;
    CHECK_THROWS_WITH_AS(gather2d_header(r, command), doctest::Contains("a table holds finite values only"),
                         std::invalid_argument);
  }
}

TEST_CASE("gather2d: the JSON summary parses and holds the run's statistics")
{
  const Gather2dResult r = run_gather2d(tiny(2));
  const std::string command = "build/bin/statsim gather2d --shape lshape --out tables/tiny2d.hpp";
  const nlohmann::json j = nlohmann::json::parse(gather2d_json(r, command));
  CHECK(j.at("command") == command);
  CHECK(j.at("name") == "tiny2d");
  REQUIRE(j.at("heights").size() == r.heights.size());
  CHECK(j.at("heights")[0].at("mean").get<double>() == r.heights[0].mean);
  REQUIRE(j.at("cells").size() == r.cells.size());
  CHECK(j.at("cells")[1].at("std")[2].get<double>() == r.cells[1].std[2]);
  REQUIRE(j.at("rest_clusters").size() == r.clusters.size());
  CHECK(j.at("rest_drops").get<int>() == r.rest_drops);
}

TEST_CASE("gather2d: the square rests on its 4 sides at height 0.5")
{
  Gather2dOptions o;
  o.shape = "square";
  o.rest_drops = 400;
  o.seed = 5;
  const Gather2dResult r = run_rest_poses(o);
  CHECK(r.rest_time_limited == 0);
  int kept = 0;
  for (const RestCluster& c : r.clusters) {
    if (!c.kept) {
      continue;
    }
    ++kept;
    CHECK(c.frequency == doctest::Approx(0.25).epsilon(0.28));  // 25% +- 7%
    CHECK(c.height == doctest::Approx(0.5).epsilon(0.01));
    CHECK(std::fabs(c.normal.x) + std::fabs(c.normal.y) == doctest::Approx(1.0).epsilon(1e-3));  // a side
  }
  CHECK(kept == 4);
}

TEST_CASE("gather2d: the L rests on its two arms and on its two tips")
{
  Gather2dOptions o;
  o.shape = "lshape";
  o.rest_drops = 200;
  const Gather2dResult r = run_rest_poses(o);
  std::vector<double> heights;
  for (const RestCluster& c : r.clusters) {
    if (c.kept) {
      heights.push_back(c.height);
    }
  }
  REQUIRE(heights.size() == 3);
  const double arm = 0.1484375 / 0.4375;                       // centroid to the outer face of an arm
  const double tips = (1.25 - 2.0 * arm) / std::sqrt(2.0);     // centroid to the line through both tips
  int arms = 0, diagonal = 0;
  for (double h : heights) {
    arms += std::fabs(h - arm) < 1e-6 ? 1 : 0;
    diagonal += std::fabs(h - tips) < 1e-6 ? 1 : 0;
  }
  CHECK(arms == 2);
  CHECK(diagonal == 1);
}

TEST_CASE("gather2d: rest poses equivalent under the shape's symmetry are kept together; the cut is an option")
{
  // The square's four sides are one family.
  Gather2dOptions o;
  o.shape = "square";
  o.rest_drops = 200;
  const Gather2dResult sq = run_rest_poses(o);
  for (const RestCluster& c : sq.clusters) {
    CHECK(c.family == 0);
    CHECK(c.kept);
  }
  CHECK(sq.rest_dropped == 0.0);

  // A 2 x 1 rectangle: the long sides (h = 0.5) and the short sides (h = 1) are two families. The
  // default keeps both; a cut at 0.5 without the dropped-share rule keeps the long sides alone.
  TempDir dir("gather2d");
  const auto run = [&](std::vector<std::string> extra, const std::string& stem) {
    std::vector<std::string> args = {"gather2d", "--polygon", "0,0 2,0 2,1 0,1", "--trials", "2", "--height-trials", "2",
                                     "--rest-drops", "200", "--threads", "2", "--out", (dir.path / (stem + ".hpp")).string(),
                                     "--json", (dir.path / (stem + ".json")).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    REQUIRE(run_command(args) == 0);
    return nlohmann::json::parse(read_file((dir.path / (stem + ".json")).string()));
  };
  const auto kept = [](const nlohmann::json& j) {
    std::vector<double> h;
    for (const auto& c : j.at("rest_clusters"))
      if (c.at("kept").get<bool>()) h.push_back(c.at("height").get<double>());
    return h;
  };
  const nlohmann::json all = run({}, "all");
  const nlohmann::json cut = run({"--rest-min-frequency", "0.5", "--rest-max-dropped", "1"}, "cut");
  const std::vector<double> all_kept = kept(all), cut_kept = kept(cut);
  CHECK(all_kept.size() == 4);
  REQUIRE(cut_kept.size() == 2);
  for (double h : cut_kept) CHECK(h == doctest::Approx(0.5));
  CHECK(cut.at("rest_dropped").get<double>() > 0.0);
  const std::string header = read_file((dir.path / "cut.hpp").string());
  CHECK(header.find(" --rest-min-frequency 0.5 --rest-max-dropped 1") != std::string::npos);
  CHECK(run_command({"gather2d", "--shape", "square", "--rest-min-frequency", "1", "--out",
                     (dir.path / "x.hpp").string()}) != 0);
}

TEST_CASE("gather2d: the command rejects bad input with an error and writes nothing")
{
  TempDir dir("gather2d");
  const std::string out = (dir.path / "bad2d.hpp").string();
  CHECK(run_command({"gather2d", "--polygon", "0,0 1,1 1,0 0,1", "--out", out}) != 0);
  CHECK(run_command({"gather2d", "--polygon", "0,0 1,0", "--out", out}) != 0);
  CHECK(run_command({"gather2d", "--shape", "square", "--polygon", "0,0 1,0 1,1", "--out", out}) != 0);
  CHECK(run_command({"gather2d", "--shape", "square", "--out", out, "--name", "not an identifier"}) != 0);
  CHECK(run_command({"gather2d", "--shape", "square", "--out", (dir.path / "missing" / "x2d.hpp").string()}) != 0);
  CHECK(dir.entries().size() == 0);

  // A good polygon through the same path: the header records the command quoted for the shell,
  // the output outside the repository's tables/ by its file name, in the namespace asked for.
  CHECK(run_command({"gather2d", "--polygon", "0,0 1,0 1,1 0.5,0.3 0,1", "--out", out, "--namespace", "game",
                     "--trials", "2", "--height-trials", "2", "--rest-drops", "20", "--threads", "2"}) == 0);
  const std::string header = read_file(out);
  CHECK(header.find("// command: statsim gather2d --polygon '0,0 1,0 1,1 0.5,0.3 0,1' --out bad2d.hpp "
                    "--namespace game --trials 2 --height-trials 2 --rest-drops 20\n") != std::string::npos);
  CHECK(header.find(dir.path.string()) == std::string::npos);
  CHECK(header.find("\"bad2d.hpp was generated") != std::string::npos);
  CHECK(header.find("namespace game {") != std::string::npos);
  CHECK(header.find("inline constexpr ::statsim::Signature<2,") != std::string::npos);
  CHECK(dir.entries().size() == 1);  // no temporary file left behind
}

TEST_CASE("gather2d: the committed square table is sane")
{
  check_committed_table(statsim::tables::square2d, 0.5, kHalfDiagonal, 4);
  const statsim::SignatureView<2> v = statsim::tables::square2d.view();
  for (std::uint32_t k = 0; k < v.rest.count; ++k) {
    CHECK(v.rest.heights[k] == doctest::Approx(0.5).epsilon(0.01));
    CHECK(v.rest.frequencies[k] == doctest::Approx(0.25).epsilon(0.28));
  }
  // Sign convention of the canonical frame (normal +y, V- along +x): a body spinning backwards
  // (clockwise, negative) is pushed forwards by friction, and the other way round.
  const statsim::ResponseTableView& t = v.response;
  const std::uint32_t a1 = t.axes[1].size, a2 = t.axes[2].size;
  for (std::uint32_t i = 0; i < t.axes[0].size; ++i) {
    for (std::uint32_t l = 0; l < a2; ++l) {
      const std::uint32_t back = ((i * a1 + 0) * a2 + l) * 3, fwd = ((i * a1 + a1 - 1) * a2 + l) * 3;
      CHECK(t.mean[back + 1] > 0.0f);
      CHECK(t.mean[fwd + 1] < t.mean[back + 1]);
    }
  }
}

TEST_CASE("gather2d: the committed L table is sane")
{
  const Shape2 l = lshape_shape();
  check_committed_table(statsim::tables::lshape2d, l.inradius_min, l.bounding_radius, 3);
}

namespace {
// compare2d's options for `drops` drops, each run once (the square table is committed).
Compare2dOptions compare_options(int drops)
{
  REQUIRE(compare2d_has_table("square"));
  Compare2dOptions o;
  o.drops = drops;
  o.repeat = 1;
  return o;
}
}  // namespace

TEST_CASE("compare2d --sleep-islands: 100 squares come to rest together, none below the ground")
{
  // Seed 19 once left a square that a neighbour joined to its island while the pile pressed on it
  // sunk 1 cm into the ground: woken as a moving body, it kept only its sphere out of the plane.
  Compare2dOptions o = compare_options(1);
  o.seed = 19;
  o.sleep_islands = true;
  const Compare2dResult r = run_compare2d(o);
  CHECK(r.statsim.asleep == o.n);
  CHECK(r.statsim.lowest > -1e-3);
}

TEST_CASE("compare2d: a small drop runs in both simulations and gives finite distances")
{
  Compare2dOptions o = compare_options(2);
  o.n = 12;
  o.steps = 150;
  const Compare2dResult r = run_compare2d(o);
  // Two drops pooled: every body of both is in the final states.
  REQUIRE(r.box2d.final.size() == 24);
  REQUIRE(r.statsim.final.size() == 24);
  REQUIRE(r.box2d_b.final.size() == 24);
  CHECK(r.box2d.step_ms.size() == 150);
  // The second reference sample starts from other states (the next seeds), so its distance from
  // the first is a real sample of the noise, not zero by construction.
  CHECK(r.box2d_b.final[0].x != r.box2d.final[0].x);
  for (const MethodResult* m : {&r.box2d, &r.statsim, &r.box2d_b}) {
    CHECK(std::isfinite(m->median_ms));
    CHECK(std::isfinite(m->pile_height));
    CHECK(m->pile_height > 0.0);
    double total = 0.0;
    for (double f : m->histogram) {
      total += f;
    }
    CHECK(total == doctest::Approx(1.0));
  }
  CHECK(std::isfinite(r.statsim.rest_tvd));
  CHECK(r.statsim.rest_tvd >= 0.0);
  CHECK(r.statsim.rest_tvd <= 1.0);
  CHECK(std::isfinite(r.statsim.spread_w1));
  const std::string csv = compare2d_csv(r);
  CHECK(csv.rfind("method,n,steps,step_ms,", 0) == 0);
  CHECK(csv.find("\nbox2d,12,150,") != std::string::npos);
  CHECK(csv.find("\nbox2d_b,12,150,") != std::string::npos);
  CHECK(csv.find("\nstatsim,12,150,") != std::string::npos);
  CHECK(std::isfinite(r.box2d_b.rest_tvd));
  CHECK(r.box2d_b.rest_tvd <= 1.0);
  // Unit squares at rest cannot have centres much closer than 1 m (face to face), and in a pile
  // of 12 each has a neighbour within a few metres.
  for (const MethodResult* m : {&r.box2d, &r.statsim, &r.box2d_b}) {
    CHECK(m->neighbour_median > 0.95);
    CHECK(m->neighbour_median < 3.0);
  }
  CHECK(csv.find(",rest_tvd_single,neighbour_median,pile_height_sd\n") != std::string::npos);
}

TEST_CASE("compare2d: Box2D's substeps refine the reference alone, and the pile height's spread is over the drops")
{
  Compare2dOptions o = compare_options(2);
  o.n = 12;
  o.steps = 150;
  const Compare2dResult one = run_compare2d(o);
  o.box2d_substeps = 2;
  const Compare2dResult two = run_compare2d(o);
  // statsim steps dt either way: the same final states.
  REQUIRE(one.statsim.final.size() == two.statsim.final.size());
  for (std::size_t i = 0; i < one.statsim.final.size(); ++i) {
    CHECK(one.statsim.final[i].x == two.statsim.final[i].x);
    CHECK(one.statsim.final[i].y == two.statsim.final[i].y);
  }
  // Box2D at half the step ends elsewhere.
  bool moved = false;
  for (std::size_t i = 0; i < one.box2d.final.size(); ++i)
    moved = moved || one.box2d.final[i].x != two.box2d.final[i].x || one.box2d.final[i].y != two.box2d.final[i].y;
  CHECK(moved);
  // Two drops: the standard deviation of two values is |a - b| / sqrt(2), and it is not zero for
  // two different piles.
  CHECK(one.box2d.pile_height_sd > 0.0);
  CHECK(std::isfinite(one.box2d.pile_height_sd));
  o.box2d_substeps = 0;
  CHECK_THROWS_AS(run_compare2d(o), std::invalid_argument);
}

TEST_CASE("compare2d: the frame files hold the first drop's final states of both engines")
{
  Compare2dOptions o = compare_options(2);
  o.n = 6;
  o.steps = 200;
  const Compare2dResult r = run_compare2d(o);
  TempDir dir("compare2d");
  const std::string frames = dir.file("frames");
  write_compare2d_frames(r, frames);
  for (const MethodResult* m : {&r.box2d, &r.statsim}) {
    CAPTURE(m->method);
    std::ifstream in(frames + "/" + m->method + ".csv");
    REQUIRE(in.good());
    std::string line;
    std::getline(in, line);
    CHECK(line == "frame,time,body,shape,x,y,z,qw,qx,qy,qz,state,radius");
    int rows = 0;
    while (std::getline(in, line)) {
      // frame,time,body,shape,x,y,0,qw,0,0,qz,state,radius: the drop's body `rows`, not the second drop's.
      std::vector<std::string> f;
      std::size_t from = 0;
      for (std::size_t comma; (comma = line.find(',', from)) != std::string::npos; from = comma + 1)
        f.push_back(line.substr(from, comma - from));
      f.push_back(line.substr(from));
      REQUIRE(f.size() == 13);
      const Body2State& b = m->final[static_cast<std::size_t>(rows)];
      CHECK(std::stoi(f[0]) == o.steps - 1);
      CHECK(std::stoi(f[2]) == rows);
      CHECK(f[3] == "square2d");
      CHECK(std::stod(f[4]) == doctest::Approx(b.x).epsilon(1e-5));
      CHECK(std::stod(f[5]) == doctest::Approx(b.y).epsilon(1e-5));
      // The turn as a quaternion about z, (cos a/2, 0, 0, sin a/2): compare the turn it makes.
      const double qw = std::stod(f[7]), qz = std::stod(f[10]);
      CHECK(qw * qw - qz * qz == doctest::Approx(std::cos(b.angle)).epsilon(1e-5));
      CHECK(2.0 * qw * qz == doctest::Approx(std::sin(b.angle)).epsilon(1e-5));
      CHECK(std::stoi(f[11]) == (m->final_asleep[static_cast<std::size_t>(rows)] ? 2 : 0));
      ++rows;
    }
    CHECK(rows == o.n);
  }
}

TEST_CASE("compare2d: the history samples the highest centre and the bodies awake, pooled over the drops")
{
  Compare2dOptions o = compare_options(2);
  o.n = 8;
  o.steps = 120;
  o.history_every = 0.5;  // 30 steps of 1/60 s
  const Compare2dResult both = run_compare2d(o);
  o.drops = 1;
  const Compare2dResult first = run_compare2d(o);
  o.seed += 1;
  const Compare2dResult second = run_compare2d(o);
  for (const MethodResult* m : {&both.box2d, &both.statsim, &first.box2d, &first.statsim}) {
    REQUIRE(m->history.size() == 4);
    CHECK(m->history[0].time == doctest::Approx(0.5));
    CHECK(m->history[3].time == doctest::Approx(2.0));
  }
  // The last sample is taken after the last step: its highest centre is that of the final states.
  for (const MethodResult* m : {&first.box2d, &first.statsim}) {
    double highest = -1e9;
    int awake = 0;
    for (std::size_t i = 0; i < m->final.size(); ++i) {
      highest = std::max(highest, m->final[i].y);
      awake += m->final_asleep[i] ? 0 : 1;
    }
    CHECK(m->history[3].highest == doctest::Approx(highest));
    CHECK(m->history[3].awake == awake);
  }
  for (std::size_t t = 0; t < 4; ++t) {
    CHECK(both.statsim.history[t].highest == doctest::Approx(0.5 * (first.statsim.history[t].highest + second.statsim.history[t].highest)));
    CHECK(both.box2d.history[t].awake == doctest::Approx(0.5 * (first.box2d.history[t].awake + second.box2d.history[t].awake)));
  }
  o.history_every = 0.0;
  CHECK(run_compare2d(o).statsim.history.empty());
}

TEST_CASE("compare2d: pooled drops are the drops run one by one")
{
  Compare2dOptions o = compare_options(2);
  o.n = 8;
  o.steps = 120;
  const Compare2dResult both = run_compare2d(o);
  o.drops = 1;
  const Compare2dResult first = run_compare2d(o);
  o.seed += 1;
  const Compare2dResult second = run_compare2d(o);
  // The pooled histogram is the mean of the two drops' histograms, and the pooled final states
  // are the first drop's followed by the second's.
  for (std::size_t k = 0; k < both.statsim.histogram.size(); ++k) {
    CHECK(both.statsim.histogram[k] == doctest::Approx(0.5 * (first.statsim.histogram[k] + second.statsim.histogram[k])));
    CHECK(both.box2d.histogram[k] == doctest::Approx(0.5 * (first.box2d.histogram[k] + second.box2d.histogram[k])));
  }
  CHECK(both.statsim.neighbour_median == doctest::Approx(0.5 * (first.statsim.neighbour_median + second.statsim.neighbour_median)));
  CHECK(both.box2d.neighbour_median == doctest::Approx(0.5 * (first.box2d.neighbour_median + second.box2d.neighbour_median)));
  REQUIRE(both.statsim.final.size() == 16);
  CHECK(both.statsim.final[0].x == first.statsim.final[0].x);
  CHECK(both.statsim.final[8].x == second.statsim.final[0].x);
  CHECK(both.box2d.final[15].y == second.box2d.final[7].y);
  // With one drop the pooled distance is the per-drop one.
  CHECK(first.statsim.rest_tvd == doctest::Approx(first.statsim.rest_tvd_single));
  // The second reference sample of seed s is Box2D's drop of seed s + drops: the same simulation
  // as `second`'s own Box2D run, so the same final states and histogram.
  REQUIRE(first.box2d_b.final.size() == second.box2d.final.size());
  for (std::size_t i = 0; i < second.box2d.final.size(); ++i) {
    CHECK(first.box2d_b.final[i].x == second.box2d.final[i].x);
  }
  CHECK(first.box2d_b.histogram == second.box2d.histogram);
}

TEST_CASE("compare2d: squares wedged between sleeping ones fall asleep")
{
  // Seed 2 wedges squares between two sleepers, where the contact passes leave a velocity that
  // the overlap correction undoes every step: judged by |v| alone, 2 of the 100 never slept.
  Compare2dOptions o = compare_options(1);
  o.seed = 2;
  const Compare2dResult r = run_compare2d(o);
  CHECK(r.statsim.asleep == o.n);
}

TEST_CASE("gather2d: a gathered square's body-body data is the closed form of a square")
{
  Gather2dOptions o = tiny(2);
  o.shape = "square";
  o.packing_count = 40;
  o.packing_steps = 600;
  const Gather2dResult r = run_gather2d(o);
  const BodyContactData& c = r.contact;
  constexpr int S = 9;
  REQUIRE(c.support_size == S);
  REQUIRE(c.support.size() == 4u * S);
  // A square of half side h = 0.5 m has s(u) = h (|u_x| + |u_y|): h (1 + |a|) at side node a.
  for (int f = 0; f < 4; ++f)
    for (int i = 0; i < S; ++i)
      CHECK(c.support[static_cast<std::size_t>(f * S + i)] ==
            doctest::Approx(0.5 * (1 + std::fabs(-1.0 + 2.0 * i / (S - 1)))).epsilon(1e-9));
  // Its four edges, each axis direction once, 0.5 m from the centre.
  REQUIRE(c.hull_faces == 4);
  REQUIRE(c.faces.size() == 4u * 4u);
  std::vector<int> seen(4, 0);
  for (std::size_t k = 0; k < 4; ++k) {
    const double x = c.faces[4 * k], y = c.faces[4 * k + 1];
    CHECK(std::hypot(x, y) == doctest::Approx(1.0));
    const int axis = std::fabs(y) > std::fabs(x) ? 1 : 0;
    CHECK(std::fabs(axis ? y : x) == doctest::Approx(1.0));
    ++seen[static_cast<std::size_t>(2 * axis + ((axis ? y : x) < 0 ? 1 : 0))];
    CHECK(c.faces[4 * k + 2] == doctest::Approx(0.5));
  }
  CHECK(seen == std::vector<int>(4, 1));
  REQUIRE(c.mesh_frame.size() == 6);
  CHECK(c.mesh_frame[0] == 1.0);
  CHECK(c.mesh_frame[3] == 1.0);
  CHECK(c.mesh_frame[1] == 0.0);
  CHECK(c.mesh_frame[2] == 0.0);
  // Two unit squares first touch between side to side (1 m) and corner to corner (sqrt 2 m).
  for (double d : c.pair_mean) {
    CHECK(d > 1.0);
    CHECK(d < std::sqrt(2.0));
  }
  // Resting squares stand where their hulls touch, plus Box2D's polygon skins (2 x 0.01 m).
  REQUIRE(c.total_pairs > 0);
  for (std::size_t b = 0; b < 3; ++b) {
    CHECK(c.packing_mean[b] > 0.99);
    CHECK(c.packing_mean[b] < 1.04);
  }
}

TEST_CASE("gather2d: body-body data adds its parts and changes no other byte; the runtime accepts it")
{
  const std::string command = "build/bin/statsim gather2d --shape lshape --out tables/tiny2d.hpp";
  const Gather2dResult with = run_gather2d(tiny(2));
  Gather2dOptions o = tiny(2);
  o.body_contacts = false;
  const std::string without = gather2d_header(run_gather2d(o), command);
  Gather2dResult stripped = with;
  stripped.options.body_contacts = false;
  CHECK(gather2d_header(stripped, command) == without);
  CHECK(without.find("ContactData") == std::string::npos);
  CHECK(without.find("STATSIM_TABLE_FORMAT_MINOR") == std::string::npos);
  const std::string text = gather2d_header(with, command);
  CHECK(text.find(", ContactData<2, 3, 9, 5>> tiny2d = {") != std::string::npos);
  CHECK(text.find("#if !defined(STATSIM_TABLE_FORMAT_MINOR) || STATSIM_TABLE_FORMAT_MINOR < 1\n#error ") !=
        std::string::npos);
}

TEST_CASE("gather2d: the committed tables carry body-body data the runtime accepts")
{
  for (const statsim::SignatureView<2>& v : {statsim::tables::square2d.view(), statsim::tables::lshape2d.view()}) {
    CAPTURE(v.name);
    REQUIRE(v.contact.present());
    CHECK(v.contact.support_size == 9);
    CHECK(v.contact.face_count >= 4);
    CHECK(v.mesh_frame != nullptr);
    statsim::World2<4> world;
    CHECK(world.add_shape(v).status == statsim::Status::ok);
  }
}
