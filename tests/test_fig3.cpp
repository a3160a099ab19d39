// Paper Figure 3 with Box2D (tools/ref2d/fig3.hpp) and the host-tool toolkit it uses.
// Checks properties of the experiment, not a hard-coded curve.
#include <doctest/doctest.h>

#include "common/chart.hpp"
#include "common/parallel.hpp"
#include "ref2d/fig3.hpp"
#include "support/temp_dir.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
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

TEST_CASE("fig3: writes the CSV and the PNG")
{
  TempDir dir("fig3");
  Fig3Options o = small_config(2);
  o.trials_per_ratio = {20, 20, 20, 20};
  write_fig3_outputs(run_fig3(o), dir.path);
  CHECK(dir.entries() == std::vector<std::string>{"fig3.csv", "fig3.png"});
  const std::string csv = read_file(dir.path / "fig3.csv");
  CHECK(csv.rfind("ratio,min,mean,std,max,trials\n0,", 0) == 0);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 5);
  CHECK(read_file(dir.path / "fig3.png").substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
}

TEST_CASE("toolkit: charts render and encode and fail cleanly")
{
  TempDir dir("fig3");
  chart::Chart c;
  c.title = "log-log";
  c.x = {"N", chart::Scale::log10, {}, {}};
  c.y = {"seconds", chart::Scale::log10, {}, {}};
  chart::Series s;
  s.name = "a";
  s.x = {10, 100, 1000, 0.0};  // 0 cannot be shown on a log axis: skipped
  s.y = {1e-5, 1e-4, 1e-3, 1.0};
  s.marker = chart::Marker::circle;
  s.labels = {"p", "q", "r", "s"};
  c.series = {s};
  const chart::Image img = chart::render(c);
  CHECK(img.width == c.width);
  CHECK(img.rgb.size() == static_cast<std::size_t>(c.width * c.height * 3));
  chart::write_png(c, dir.path / "ok.png");
  CHECK(read_file(dir.path / "ok.png").substr(1, 3) == "PNG");

  c.series[0].y.pop_back();  // mismatched lengths
  CHECK_THROWS_AS(chart::write_png(c, dir.path / "bad.png"), std::invalid_argument);
  // Unwritable target: an error, and no temporary file left behind.
  c.series[0].y.push_back(1.0);
  CHECK_THROWS_AS(chart::write_png(c, dir.path / "missing-dir" / "x.png"), std::runtime_error);
  CHECK(dir.entries() == std::vector<std::string>{"ok.png"});
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
