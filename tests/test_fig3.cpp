// Paper Figure 3 with Box2D (tools/ref2d/fig3.hpp) and the host-tool toolkit it uses.
// Checks properties of the experiment, not a hard-coded curve.
#include <doctest/doctest.h>

#include "common/parallel.hpp"
#include "common/plot.hpp"
#include "ref2d/fig3.hpp"
#include "support/temp_dir.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

using namespace statsim::tools;

using namespace statsim::testing;

namespace {

constexpr double kHalfDiagonal = 0.70710678118654752440;
constexpr double kPi = 3.14159265358979323846;

// Ratio 0 gets many drops so that its extremes reliably come close to 0.5 and sqrt(2)/2.
Fig3Options small_config(unsigned threads)
{
  Fig3Options o;
  o.ratios = {0.0, 0.5, 2.0, 8.0};
  o.trials_per_ratio = {1500, 300, 300, 300};
  o.seed = 7;
  o.threads = threads;
  return o;
}

const Fig3Result& small_run()
{
  static const Fig3Result result = run_fig3(small_config(2));
  return result;
}

// Brute force: first time the lowest vertex of the unit square reaches y = 0, by dense sampling.
double brute_force_height(const Fig3Drop& d, double speed)
{
  const double step = 2e-7;
  for (double t = 0.0; t < d.height / speed; t += step) {
    const double a = d.angle + d.spin * t;
    const double reach = 0.5 * (std::fabs(std::cos(a)) + std::fabs(std::sin(a)));
    if (d.height - speed * t - reach <= 0.0) {
      return d.height - speed * t;
    }
  }
  return -1.0;
}

}  // namespace

TEST_CASE("fig3: face-down and corner-down drops touch at 0.5 and sqrt(2)/2 despite the Box2D skin")
{
  Fig3Drop face;
  face.height = 0.83;
  face.angle = 0.0;
  const Fig3Trial f = simulate_fig3_drop(face, 1.0, 1.0 / 60.0);
  CHECK(f.height == doctest::Approx(0.5).epsilon(1e-6));
  // Box2D itself reported contact with the core still apart (its 2 x 0.01 m skin).
  CHECK(f.report_gap > 0.0);
  CHECK(f.report_gap <= 0.0201);
  CHECK(f.naive_height - f.height > 0.002);
  CHECK_FALSE(f.missed);

  Fig3Drop corner;
  corner.height = 0.9;
  corner.angle = kPi / 4.0;
  CHECK(simulate_fig3_drop(corner, 1.0, 1.0 / 60.0).height == doctest::Approx(kHalfDiagonal).epsilon(1e-6));
}

TEST_CASE("fig3: spinning drops match a brute-force search for the first contact")
{
  const Fig3Options o;
  int checked = 0;
  for (double ratio : {0.35, 3.0, 16.0}) {
    for (std::size_t k = 0; k < 2; ++k) {
      const Fig3Drop d = fig3_drop(o, ratio, 99, k);
      const Fig3Trial t = simulate_fig3_drop(d, o.speed, o.dt);
      const double expected = brute_force_height(d, o.speed);
      REQUIRE(expected > 0.0);
      // Sampling step 2e-7 s at 1 m/s, plus Box2D's float32 state (a few 1e-6 m).
      CHECK(std::fabs(t.height - expected) < 2e-5);
      CHECK_FALSE(t.missed);
      ++checked;
    }
  }
  CHECK(checked == 6);
}

TEST_CASE("fig3: heights span 0.5 to sqrt(2)/2 without spin and approach sqrt(2)/2 with spin")
{
  const Fig3Result& r = small_run();
  REQUIRE(r.rows.size() == 4);
  CHECK(r.rows[0].trials == 1500);
  CHECK(r.rows[3].trials == 300);

  // Zero spin: the extremes of the range within 1%.
  CHECK(r.rows[0].min == doctest::Approx(0.5).epsilon(0.01));
  CHECK(r.rows[0].max == doctest::Approx(kHalfDiagonal).epsilon(0.01));
  // Without spin the height is 0.5 (|cos a| + |sin a|) for a uniform orientation: mean 2/pi.
  CHECK(r.rows[0].mean == doctest::Approx(2.0 / kPi).epsilon(0.01));

  for (const std::vector<double>& hs : r.heights) {
    for (double h : hs) {
      CHECK(h >= 0.5 * (1.0 - 0.01));
      CHECK(h <= kHalfDiagonal * (1.0 + 0.01));
    }
  }
  for (std::size_t i = 0; i + 1 < r.rows.size(); ++i) {
    const Fig3Row& a = r.rows[i];
    const Fig3Row& b = r.rows[i + 1];
    const double stderr_a = a.std / std::sqrt(static_cast<double>(a.trials));
    const double stderr_b = b.std / std::sqrt(static_cast<double>(b.trials));
    CHECK(b.mean >= a.mean - 3.0 * std::max(stderr_a, stderr_b));
    CHECK(a.min <= a.mean);
    CHECK(a.mean <= a.max);
  }
  CHECK(r.rows.back().std < r.rows.front().std);
  CHECK(r.rows.back().mean > r.rows.front().mean);

  CHECK(r.diagnostics.missed == 0);
  CHECK(r.diagnostics.max_free_flight_error < 1e-5);
  CHECK(r.diagnostics.max_float_drift < 1e-5);
}

TEST_CASE("fig3: the same seed gives the same results with 1 and 2 threads")
{
  Fig3Options one = small_config(1);
  one.trials_per_ratio = {60, 40, 40, 40};
  Fig3Options two = one;
  two.threads = 2;
  const Fig3Result a = run_fig3(one);
  const Fig3Result b = run_fig3(two);
  CHECK(a.heights == b.heights);
  CHECK(fig3_csv(a) == fig3_csv(b));

  Fig3Options other = one;
  other.seed = 8;
  CHECK(run_fig3(other).heights != a.heights);
}

TEST_CASE("fig3: bad options are rejected")
{
  Fig3Options o = small_config(1);
  o.trials_per_ratio.clear();
  o.trials = 4;
  auto rejects = [](Fig3Options bad) { CHECK_THROWS_AS(run_fig3(bad), std::invalid_argument); };
  Fig3Options bad = o;
  bad.speed = 0.0;
  rejects(bad);
  bad.speed = -1.0;
  rejects(bad);
  bad.speed = std::nan("");
  rejects(bad);
  bad = o;
  bad.trials = 1;
  rejects(bad);
  bad = o;
  bad.trials_per_ratio = {5, 5};  // wrong length
  rejects(bad);
  bad = o;
  bad.ratios = {0.0, -1.0};
  rejects(bad);
  bad = o;
  bad.dt = 0.0;
  rejects(bad);
  bad = o;
  bad.speed = 200.0;  // 3.3 m per step: beyond b2_maxTranslation
  rejects(bad);
}

namespace {

bool is_png(const std::string& bytes)
{
  return bytes.size() > 1000 && bytes.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) == 0;
}

bool contains(const std::string& text, const std::string& part)
{
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("fig3: writes the CSV and draws the PNG and the SVG from it")
{
  TempDir dir("fig3");
  Fig3Options o = small_config(2);
  o.trials_per_ratio = {20, 20, 20, 20};
  write_fig3_outputs(run_fig3(o), dir.path);
  CHECK(dir.entries() == std::vector<std::string>{"fig3.csv", "fig3.png", "fig3.svg"});
  const std::string csv = read_file(dir.path / "fig3.csv");
  CHECK(csv.rfind("ratio,min,mean,std,max,trials\n0,", 0) == 0);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 5);
  CHECK(is_png(read_file(dir.path / "fig3.png")));
  const std::string svg = read_file(dir.path / "fig3.svg");
  CHECK(contains(svg, "<svg"));
  CHECK(contains(svg, "height of centre at first contact (m)"));
  CHECK(contains(svg, "min .. max of 20 drops"));  // the trial count comes from the CSV
}

TEST_CASE("toolkit: a plotting script draws the same PNG and SVG from the same data, and fails clearly")
{
  TempDir dir("plot");
  const std::string csv = "ratio,min,mean,std,max,trials\n"
                          "0,0.501,0.635,0.064,0.7071,400\n"
                          "8,0.59,0.66,0.03,0.7071,400\n"
                          "64,0.686,0.697,0.006,0.7071,400\n";
  plot::run_script_on("fig3.py", csv, ".csv", {"--out", (dir.path / "a.png").string()});
  plot::run_script_on("fig3.py", csv, ".csv", {"--out", (dir.path / "b.svg").string()});  // either name
  CHECK(dir.entries() == std::vector<std::string>{"a.png", "a.svg", "b.png", "b.svg"});
  const std::string png = read_file(dir.path / "a.png");
  const std::string svg = read_file(dir.path / "a.svg");
  CHECK(is_png(png));
  CHECK(contains(svg, "height of centre at first contact (m)"));
  // No date, version or random id in either file: reruns are byte-identical.
  CHECK(png == read_file(dir.path / "b.png"));
  CHECK(svg == read_file(dir.path / "b.svg"));
  CHECK(plot::svg_of(dir.path / "a.png") == dir.path / "a.svg");

  // A missing input, a file that is not the expected CSV, an unknown output kind: the script's
  // message, naming the problem, and nothing written.
  const auto error_of = [](const std::string& script, const std::vector<std::string>& args) {
    try {
      plot::run_script(script, args);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string out = (dir.path / "x.png").string();
  std::string e = error_of("fig3.py", {(dir.path / "missing.csv").string(), "--out", out});
  CHECK(contains(e, "missing.csv"));
  CHECK(contains(e, "No such file"));
  std::ofstream(dir.path / "other.csv") << "a,b\n1,2\n";
  e = error_of("fig3.py", {(dir.path / "other.csv").string(), "--out", out});
  CHECK(contains(e, "no column ratio"));
  e = error_of("fig3.py", {(dir.path / "other.csv").string(), "--out", (dir.path / "x.pdf").string()});
  CHECK(contains(e, ".png or .svg"));
  CHECK(contains(error_of("no-such-script.py", {}), "not found"));
  std::filesystem::remove(dir.path / "other.csv");
  CHECK(dir.entries() == std::vector<std::string>{"a.png", "a.svg", "b.png", "b.svg"});

  // No interpreter with matplotlib: the message says how to get one.
  ::setenv("STATSIM_PYTHON", "/nonexistent/python3", 1);
  e = error_of("fig3.py", {(dir.path / "missing.csv").string(), "--out", out});
  ::unsetenv("STATSIM_PYTHON");
  CHECK(contains(e, "/nonexistent/python3"));
  CHECK(contains(e, "tools/setup.sh"));
  CHECK_NOTHROW(plot::find_python());
}

TEST_CASE("toolkit: parallel_for visits every index once whatever the thread count")
{
  for (unsigned threads : {1u, 2u, 5u}) {
    std::vector<std::atomic<int>> seen(1000);
    parallel_for(seen.size(), [&](std::size_t i) { seen[i].fetch_add(1); }, threads);
    CHECK(std::all_of(seen.begin(), seen.end(), [](const std::atomic<int>& v) { return v.load() == 1; }));
    const std::vector<std::size_t> squares = parallel_map(
        50, [](std::size_t i) { return i * i; }, threads);
    CHECK(squares[49] == 49u * 49u);
  }
  CHECK_THROWS_AS(parallel_for(
                      100,
                      [](std::size_t i) {
                        if (i == 37) {
                          throw std::runtime_error("boom");
                        }
                      },
                      2),
                  std::runtime_error);
}
