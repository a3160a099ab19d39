// The response models of statsim/signature.hpp, sampled by statsim::sample_response and
// statistical_response: each reproduces its cell's statistics, between cells too, in any contact
// frame, with the same bits for the same seed.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/statistical.hpp"
#include "statsim/world3.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <vector>

using namespace statsim;
using statsim::testing::cube_correlated_synthetic;
using statsim::testing::cube_empirical_synthetic;
using statsim::testing::cube_synthetic;

namespace {

using Sample = std::array<double, 6>;

std::vector<Sample> draws(const ResponseTableView& t, const Scalar* x, int n, std::uint64_t seed)
{
  Pcg32 rng(seed, 11);
  std::vector<Sample> out;
  for (int i = 0; i < n; ++i) {
    Scalar s[6];
    sample_response(t, x, rng, s);
    Sample d;
    for (int c = 0; c < 6; ++c) d[c] = s[c];
    out.push_back(d);
  }
  return out;
}

Sample mean_of(const std::vector<Sample>& v)
{
  Sample m{};
  for (const Sample& s : v)
    for (int c = 0; c < 6; ++c) m[c] += s[c] / double(v.size());
  return m;
}

double covariance(const std::vector<Sample>& v, int i, int j)
{
  const Sample m = mean_of(v);
  double sum = 0;
  for (const Sample& s : v) sum += (s[i] - m[i]) * (s[j] - m[j]);
  return sum / double(v.size() - 1);
}

// Interpolated table means at x, as the runtime computes them.
Sample table_mean(const ResponseTableView& t, const Scalar* x)
{
  Scalar m[6];
  t.lookup(x, m);
  Sample out;
  for (int c = 0; c < 6; ++c) out[c] = m[c];
  return out;
}

// Table coordinates: at the cube's first cell, and between cells (every axis a quarter of the way).
constexpr Scalar kNode[3] = {0.2f, -1.0f, 0.0f};
constexpr Scalar kBetween[3] = {0.4f, -0.5f, 1.0f};

constexpr int kDraws = 40000;

}  // namespace

TEST_CASE("response models: the paper's independent Gaussian keeps means and spreads, no correlation")
{
  const ResponseTableView t = cube_synthetic.view().response;
  for (const Scalar* x : {kNode, kBetween}) {
    const std::vector<Sample> v = draws(t, x, kDraws, 1);
    const Sample m = mean_of(v), want = table_mean(t, x);
    for (int c = 0; c < 6; ++c) {
      const double sd = c < 3 ? 0.5 : 0.05;
      CHECK(std::fabs(m[c] - want[c]) < 4 * sd / std::sqrt(double(kDraws)));
      CHECK(std::sqrt(covariance(v, c, c)) == doctest::Approx(sd).epsilon(0.03));
    }
    CHECK(std::fabs(covariance(v, 0, 5) / (0.5 * 0.05)) < 0.03);
  }
}

TEST_CASE("response models: the correlated Gaussian reproduces the cell's covariance")
{
  const ResponseTableView t = cube_correlated_synthetic.view().response;
  REQUIRE(t.model == ResponseModel::correlated_gaussian);
  REQUIRE(t.spread_per_cell == 21);
  for (const Scalar* x : {kNode, kBetween}) {
    const std::vector<Sample> v = draws(t, x, kDraws, 2);
    const Sample m = mean_of(v), want = table_mean(t, x);
    for (int c = 0; c < 6; ++c) {
      const double sd = c < 3 ? 0.5 : 0.05;
      CHECK(std::fabs(m[c] - want[c]) < 4 * sd / std::sqrt(double(kDraws)));
      CHECK(std::sqrt(covariance(v, c, c)) == doctest::Approx(sd).epsilon(0.03));
    }
    // The correlation of w_x and dv_z is the table's -0.6 (standard error about 0.004).
    const double r = covariance(v, 0, 5) / std::sqrt(covariance(v, 0, 0) * covariance(v, 5, 5));
    CHECK(r == doctest::Approx(-0.6).epsilon(0.03));
    CHECK(std::fabs(covariance(v, 1, 5)) / (0.5 * 0.05) < 0.03);
  }
}

TEST_CASE("response models: the empirical model draws the stored outcomes, each as often")
{
  const SignatureView<3> sig = cube_empirical_synthetic.view();
  const ResponseTableView& t = sig.response;
  REQUIRE(t.model == ResponseModel::empirical);
  REQUIRE(t.spread_per_cell == 24);
  // At a node: the mean plus one of the cell's 4 outcomes, exactly, each a quarter of the time;
  // none near the mean (two modes in dv_z, none in between).
  const std::vector<Sample> v = draws(t, kNode, kDraws, 3);
  const Sample want = table_mean(t, kNode);
  std::map<int, int> seen;
  for (const Sample& s : v) {
    int which = -1;
    for (int k = 0; k < 4; ++k) {
      bool same = true;
      for (int c = 0; c < 6; ++c)
        same = same && float(s[c]) == float(want[c]) + cube_empirical_synthetic.response_spread[std::size_t(k * 6 + c)];
      if (same) which = k;
    }
    REQUIRE(which >= 0);
    ++seen[which];
  }
  for (int k = 0; k < 4; ++k) CHECK(seen[k] / double(kDraws) == doctest::Approx(0.25).epsilon(0.04));

  // Between cells: each corner's outcomes as often as its interpolation weight, about the
  // interpolated mean (its mean is the table's: the outcomes of a cell sum to zero).
  CellWeight cw[16];
  const std::uint32_t corners = t.corners(kBetween, cw);
  REQUIRE(corners == 8);
  const std::vector<Sample> u = draws(t, kBetween, kDraws, 4);
  const Sample mid = table_mean(t, kBetween);
  std::map<std::uint32_t, int> from;
  for (const Sample& s : u) {
    // The outcomes of cell k are the base ones times 1 + k / 8: |w_x| + |w_y| = 0.6 (1 + k / 8).
    const double size = (std::fabs(s[0] - mid[0]) + std::fabs(s[1] - mid[1])) / 0.6;
    ++from[std::uint32_t(std::lround((size - 1) * 8))];
  }
  for (std::uint32_t k = 0; k < corners; ++k)
    CHECK(from[cw[k].cell] / double(kDraws) == doctest::Approx(cw[k].weight).epsilon(0.05));
  const Sample m = mean_of(u);
  for (int c = 0; c < 6; ++c) CHECK(std::fabs(m[c] - mid[c]) < 0.02);
}

TEST_CASE("response models: the same seed gives the same bits")
{
  for (const SignatureView<3>& sig :
       {cube_synthetic.view(), cube_correlated_synthetic.view(), cube_empirical_synthetic.view()}) {
    const std::vector<Sample> a = draws(sig.response, kBetween, 500, 9), b = draws(sig.response, kBetween, 500, 9);
    const std::vector<Sample> c = draws(sig.response, kBetween, 500, 10);
    CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(Sample)) == 0);
    CHECK(std::memcmp(a.data(), c.data(), a.size() * sizeof(Sample)) != 0);
  }
}

TEST_CASE("response models: the statistics hold in every contact frame")
{
  // Impacts along several normals at 60 degrees of incidence without spin (cos phi and the spin
  // ratio read 0): the spin after the impact, taken back to the canonical frame and normalised,
  // has the table's means and the correlated model's covariance, whatever the frame.
  const SignatureView<3> sig = cube_correlated_synthetic.view();
  const Scalar x[3] = {0.5f, 0.0f, 0.0f};
  const Sample want = table_mean(sig.response, x);
  const Vector3 normals[] = {Vector3(0, 0, 1), Vector3(1, 0, 0), Vector3(0.48f, -0.6f, 0.64f)};
  for (const Vector3& n : normals) {
    CAPTURE(n.transpose());
    const Vector3 t = detail::any_perpendicular(n);
    const Scalar speed = 2;
    std::vector<Sample> v;
    int clamped = 0;
    Pcg32 rng(5, 6);
    for (int i = 0; i < 20000; ++i) {
      Vector3 vel = (t * std::sqrt(Scalar(0.75)) - n * Scalar(0.5)) * speed;
      Vector3 w = Vector3::Zero();
      const ContactFrame<3> frame = contact_frame(n, vel, w);
      const ResponseOutcome o = statistical_response<3>(sig, Quaternion::Identity(), n, vel, w, rng);
      REQUIRE(o.applied);
      clamped += o.energy_clamped;  // a far tail of the spin draws, scaled down by the guard
      const Vector3 wc = frame.basis.transpose() * w * (sig.length / speed);
      v.push_back({wc.x(), wc.y(), wc.z(), 0, 0, 0});
    }
    CHECK(clamped < 20000 / 50);
    const Sample m = mean_of(v);
    for (int c = 0; c < 3; ++c) {
      CHECK(std::fabs(m[c] - want[c]) < 4 * 0.5 / std::sqrt(20000.0));
      CHECK(std::sqrt(covariance(v, c, c)) == doctest::Approx(0.5).epsilon(0.03));
    }
  }
}

TEST_CASE("response models: worlds of every model step, and the energy guard is counted")
{
  for (const SignatureView<3>& sig :
       {cube_synthetic.view(), cube_correlated_synthetic.view(), cube_empirical_synthetic.view()}) {
    World3<64> w;
    const Added<ShapeId> shape = w.add_shape(sig);
    REQUIRE(shape.ok());
    REQUIRE(w.add_plane(Vector3(0, 0, 1), 0).ok());
    Pcg32 g(1, 2);
    for (int i = 0; i < 40; ++i) {
      BodyDef3 b;
      b.shape = shape.id;
      b.position = Vector3(g.uniform(-2, 2), g.uniform(-2, 2), g.uniform(0.3f, 2));
      b.angular_velocity = Vector3(g.uniform(-5, 5), 0, g.uniform(-5, 5));
      REQUIRE(w.add_body(b).ok());
    }
    for (int i = 0; i < 300; ++i) REQUIRE(w.step(1.0f / 60).ok());
    CHECK(w.statistical_response_count() >= 40);
    CHECK(w.energy_clamp_count() <= w.statistical_response_count());
    CHECK(w.count(MotionState::asleep) + w.count(MotionState::settling) > 0);
  }
}
