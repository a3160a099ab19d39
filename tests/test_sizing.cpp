// tools/ref3d/sizing: choosing the smallest table for a scene, on synthetic dense tables (no
// Bullet runs), and the held-out wedge mesh.
#include "mesh/mesh.hpp"
#include "mesh/mesh_commands.hpp"
#include "mesh/shapes.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/sizing.hpp"
#include "support/temp_dir.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

using namespace statsim::tools;
using namespace statsim::tools::ref3d;

namespace {

std::vector<double> linspace(double a, double b, std::size_t n)
{
  std::vector<double> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(a + (b - a) * static_cast<double>(i) / static_cast<double>(n - 1));
  return v;
}

// A dense table on (cos theta, cos phi, spin ratio) whose component c has mean f(x) + c and
// spread sigma everywhere; h_coll mean h(s), spread 0.01.
DenseTable synthetic(const std::function<double(double, double, double)>& f, const std::function<double(double)>& h,
                     double sigma = 0.2)
{
  DenseTable d;
  d.axes = {linspace(0.1, 1.0, 5), linspace(-1.0, 1.0, 6), linspace(0.0, 4.0, 9)};
  for (double ct : d.axes[0])
    for (double cp : d.axes[1])
      for (double s : d.axes[2])
        for (std::size_t c = 0; c < d.components; ++c) {
          d.mean.push_back(f(ct, cp, s) + static_cast<double>(c));
          d.stddev.push_back(sigma);
        }
  d.height_axis = linspace(0.0, 8.0, 12);
  for (double s : d.height_axis) {
    d.height_mean.push_back(h(s));
    d.height_stddev.push_back(0.01);
  }
  d.rest_poses = 3;
  return d;
}

}  // namespace

TEST_CASE("sizing: spread indices keep both ends and are increasing")
{
  CHECK(spread_indices(9, 2) == std::vector<std::size_t>{0, 8});
  CHECK(spread_indices(9, 3) == std::vector<std::size_t>{0, 4, 8});
  CHECK(spread_indices(1, 5) == std::vector<std::size_t>{0});
  for (std::size_t n = 2; n <= 30; ++n)
    for (std::size_t m = 2; m <= n; ++m) {
      const auto v = spread_indices(n, m);
      REQUIRE(v.size() == m);
      CHECK(v.front() == 0);
      CHECK(v.back() == n - 1);
      for (std::size_t i = 1; i < v.size(); ++i) CHECK(v[i] > v[i - 1]);
    }
  const auto counts = candidate_counts(26);
  CHECK(counts.front() == 2);
  CHECK(counts.back() == 26);
  CHECK(candidate_counts(1) == std::vector<std::size_t>{1});
}

TEST_CASE("sizing: a multilinear response needs only the end samples")
{
  const DenseTable d = synthetic([](double ct, double cp, double s) { return 0.5 * ct - 0.3 * cp + 0.25 * s + ct * s; },
                                 [](double s) { return 0.1 + 0.002 * s; });
  SizingOptions o;
  o.budget = 0.01;
  const SizingResult r = size_table(d, o);
  const Candidate& c = r.candidates[r.chosen];
  for (const auto& k : c.keep) CHECK(k.size() == 2);
  CHECK(r.height_candidates[r.height_chosen].keep.size() == 2);
  CHECK(c.error <= o.budget);
  CHECK(r.error <= o.budget);
  // i16 halves the response tables and its rounding (1e-4 of a range of about 10) is far below
  // the spread 0.2.
  CHECK(c.i16);
  CHECK(c.bytes == signature_bytes(2, {2, 2, 2}, 6, 3, true));
  // Interpolation between exact samples is exact up to float rounding.
  CHECK(response_error(d, c.keep, false, 0.05).error < 1e-5);
}

TEST_CASE("sizing: a curved response needs more samples, within the budget")
{
  // Curved along the spin ratio only: s^2 over [0, 4] in units of the spread 0.2.
  const DenseTable d = synthetic([](double ct, double, double s) { return ct + 0.5 * s * s; },
                                 [](double s) { return 0.1 + 0.01 * std::sqrt(s); });
  SizingOptions o;
  o.budget = 0.1;
  const SizingResult r = size_table(d, o);
  const Candidate& c = r.candidates[r.chosen];
  CHECK(c.error <= o.budget);
  CHECK(c.keep[2].size() > 2);  // the curved axis
  CHECK(c.keep[0].size() == 2);  // linear
  CHECK(c.keep[1].size() == 2);  // constant
  CHECK(r.height_candidates[r.height_chosen].keep.size() > 2);
  CHECK(r.height_candidates[r.height_chosen].error <= o.budget);
  // Every candidate within the budget has at least the chosen one's bytes.
  for (const Candidate& k : r.candidates)
    if (k.error <= o.budget) CHECK(k.bytes >= c.bytes);
  // The full dense table fits itself.
  CHECK(response_error(d, {spread_indices(5, 5), spread_indices(6, 6), spread_indices(9, 9)}, false, 0.05).error <
        1e-6);
}

TEST_CASE("sizing: a tighter budget never gives fewer bytes")
{
  const DenseTable d = synthetic(
      [](double ct, double cp, double s) { return std::sin(3 * ct) + 0.4 * cp * cp + 0.3 * s * s - ct * s; },
      [](double s) { return 0.1 + 0.01 * std::log1p(s); });
  std::size_t last_bytes = 0;
  std::size_t last_height = 0;
  for (double budget : {2.0, 1.0, 0.5, 0.25, 0.1, 0.05, 0.01, 0.001}) {
    SizingOptions o;
    o.budget = budget;
    const SizingResult r = size_table(d, o);
    const Candidate& c = r.candidates[r.chosen];
    CAPTURE(budget);
    CHECK(c.error <= budget);
    CHECK(r.error <= budget);
    const std::size_t nh = r.height_candidates[r.height_chosen].keep.size();
    // Compare response bytes at one h_coll size so that the two choices are separate.
    const std::size_t bytes = c.bytes - 12 * nh;
    CHECK(bytes >= last_bytes);
    CHECK(nh >= last_height);
    last_bytes = bytes;
    last_height = nh;
  }
}

TEST_CASE("sizing: the sampling noise of the dense gathering is not counted as a miss")
{
  // A multilinear response sampled with T trials a cell: each mean off by a normal deviate of
  // sigma / sqrt(T) (a fixed LCG with Box-Muller, so the test is the same every run).
  const double sigma = 0.2, T = 30;
  DenseTable d = synthetic([](double ct, double cp, double s) { return ct - cp + 0.1 * s; }, [](double s) { return 0.1 + 0.001 * s; },
                           sigma);
  std::uint64_t state = 12345;
  auto uniform = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (static_cast<double>(state >> 11) + 0.5) / 9007199254740992.0;
  };
  auto normal = [&] { return std::sqrt(-2 * std::log(uniform())) * std::cos(6.283185307179586 * uniform()); };
  for (double& m : d.mean) m += sigma / std::sqrt(T) * normal();
  const std::vector<std::vector<std::size_t>> coarsest = {spread_indices(5, 2), spread_indices(6, 2), spread_indices(9, 2)};
  const double raw = response_error(d, coarsest, false, 0.05).raw_error;
  d.cell_trials.assign(d.mean.size() / d.components, T);
  const Candidate corrected = response_error(d, coarsest, false, 0.05);
  CHECK(corrected.raw_error == raw);
  // Without the correction the noise alone costs about 0.8 sqrt(2 / T) ~ 0.2; with it, far less.
  CHECK(raw > 0.1);
  CHECK(corrected.error < 0.5 * raw);
  SizingOptions o;
  o.budget = 0.1;
  const SizingResult r = size_table(d, o);
  const Candidate& c = r.candidates[r.chosen];
  CHECK(c.keep[0].size() * c.keep[1].size() * c.keep[2].size() < 5 * 6 * 9 / 4);
}

TEST_CASE("sizing: the scene's range cuts the spin ratio axes")
{
  CHECK(cut_axis({0, 1, 2, 4, 8}, 3) == std::vector<double>{0, 1, 2, 3});
  CHECK(cut_axis({0, 1, 2, 4, 8}, 4) == std::vector<double>{0, 1, 2, 4});
  CHECK(cut_axis({0, 1, 2, 4, 8}, 20) == std::vector<double>{0, 1, 2, 4, 8});
  CHECK(cut_axis({0, 1, 2}, 0) == std::vector<double>{0});

  GatherOptions o;
  SceneRange scene;
  scene.max_speed = std::sqrt(2 * 9.81 * 1.0);  // a 1 m drop
  scene.min_speed = 0.3 * scene.max_speed;
  scene.max_spin = 10.0;
  const double L = 0.16;
  const double s_max = scene_max_spin_ratio(scene, L);
  CHECK(s_max == doctest::Approx(10.0 * 0.16 / (0.3 * std::sqrt(2 * 9.81))));
  const GatherOptions d = scene_dense_options(o, scene, L);
  CHECK(d.spin_ratios.back() == s_max);
  CHECK(d.height_ratios.back() == s_max);
  CHECK(d.spin_ratios.size() < o.spin_ratios.size());
  CHECK(d.cos_theta == o.cos_theta);
  CHECK(d.cos_phi == o.cos_phi);

  GatherOptions p = o;
  p.with_speed = true;
  p.speeds = {0.5, 1, 2, 4, 8};
  const GatherOptions dp = scene_dense_options(p, scene, L);
  CHECK(dp.speeds.front() == scene.min_speed);
  CHECK(dp.speeds.back() == scene.max_speed);
  CHECK(dp.speeds.size() == 4);  // 1.33, 2, 4, 4.43

  SceneRange bad = scene;
  bad.min_speed = 2 * scene.max_speed;
  CHECK_THROWS(scene_dense_options(o, bad, L));
}

TEST_CASE("sizing: the sized table is the chosen subset, and says so in its header")
{
  GatherResult dense;
  dense.options.name = "synthetic";
  dense.model.name = "synthetic";
  const DenseTable d = synthetic([](double ct, double, double s) { return ct + 0.5 * s * s; },
                                 [](double s) { return 0.1 + 0.01 * std::sqrt(s); });
  dense.axes = d.axes;
  dense.options.cos_theta = d.axes[0];
  dense.options.cos_phi = d.axes[1];
  dense.options.spin_ratios = d.axes[2];
  dense.options.height_ratios = d.height_axis;
  dense.response_mean = d.mean;
  dense.response_std = d.stddev;
  dense.height_mean = d.height_mean;
  dense.height_std = d.height_stddev;
  SizingOptions o;
  o.budget = 0.1;
  const SizingResult s = size_table(dense_table(dense), o);
  const GatherResult r = sized_result(dense, s, {"a note"});
  const Candidate& c = s.candidates[s.chosen];
  REQUIRE(r.axes.size() == 3);
  for (std::size_t a = 0; a < 3; ++a) CHECK(r.axes[a].size() == c.keep[a].size());
  CHECK(r.options.spin_ratios == r.axes[2]);
  CHECK(r.response_mean.size() == c.keep[0].size() * c.keep[1].size() * c.keep[2].size() * 6);
  // The last cell is the dense table's last cell (both ends are kept).
  CHECK(r.response_mean.back() == dense.response_mean.back());
  CHECK(r.options.i16 == c.i16);
  CHECK(r.height_mean.size() == s.height_candidates[s.height_chosen].keep.size());
  const std::string header = header_text(r, "build/bin/statsim gather --size-for-scene ...");
  CHECK(header.find("// Sized: a note\n") != std::string::npos);
  const std::string report = sizing_report(dense_table(dense), s, false);
  CHECK(report.find("<- chosen") != std::string::npos);
}

TEST_CASE("held-out wedge: the committed OBJ is what its command writes, closed and outward")
{
  const statsim::testing::TempDir dir("wedge");
  std::ostringstream out, err;
  const std::string path = dir.file("wedge.obj");
  REQUIRE(mesh_wedge(0.2, 0.1, 0.08, path, out, err) == 0);
  std::string want = statsim::testing::read_file("tools/meshes/wedge.obj"), got = statsim::testing::read_file(path);
  // The command names its output file; the committed one was written to tools/meshes/wedge.obj.
  const std::string needle = path;
  for (std::size_t at = got.find(needle); at != std::string::npos; at = got.find(needle))
    got.replace(at, needle.size(), "tools/meshes/wedge.obj");
  CHECK(got == want);
  CHECK(mesh_wedge(0.2, -0.1, 0.08, dir.file("bad.obj"), out, err) != 0);

  const TriMesh m = make_wedge(0.2, 0.1, 0.08);
  CHECK(m.vertices.size() == 6);
  CHECK(m.triangles.size() == 8);
  // Signed volume by the divergence theorem: positive (outward) and legs x depth / 2.
  double volume = 0.0;
  for (const auto& t : m.triangles)
    volume += m.vertices[static_cast<std::size_t>(t[0])].dot(
                  m.vertices[static_cast<std::size_t>(t[1])].cross(m.vertices[static_cast<std::size_t>(t[2])])) /
              6.0;
  CHECK(volume == doctest::Approx(0.2 * 0.1 / 2 * 0.08));
}
