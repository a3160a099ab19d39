// The landing data of a signature (statsim/signature_landing.hpp): the share of impacts that stay
// on the ground follows the table, interpolated between its cells; a stay leaves no normal
// velocity or spin; a negative probability draws stays again; a table without the data, or a contact without gravity, takes no extra draw and
// gives the bits it gave before; malformed data is refused by add_shape with the world unchanged;
// a world with the data is deterministic.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/statistical.hpp"
#include "statsim/world3.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

using namespace statsim;

namespace {

// Axes: cos theta {0.1, 1}, spin ratio {0, 8}, Froude number {1, 16}; the probability 0.2 at
// F = 1 and 0.6 at F = 16 in every (cos theta, spin ratio).
const Scalar landing_test_cos_theta[] = {0.1f, 1.0f};
const Scalar landing_test_spin[] = {0.0f, 8.0f};
const Scalar landing_test_froude[] = {1.0f, 16.0f};
const Scalar landing_test_probability[] = {0.2f, 0.6f, 0.2f, 0.6f, 0.2f, 0.6f, 0.2f, 0.6f};
const Scalar landing_test_zero[] = {0, 0, 0, 0, 0, 0, 0, 0};

SignatureView<3> landing_test_view(SignatureView<3> v, Span<const Scalar> probability = Span<const Scalar>(landing_test_probability))
{
  v.landing.axes = {{AxisView(landing_test_cos_theta), AxisView(landing_test_spin), AxisView(landing_test_froude)}};
  v.landing.probability = probability;
  v.landing.hop = 0.05f;
  return v;
}

constexpr Scalar landing_test_g = 9.81f;

}  // namespace

TEST_CASE("landing: the share of stays is the table's probability, interpolated, and a stay has no normal velocity or spin")
{
  const SignatureView<3> sig = landing_test_view(testing::cube_synthetic.view());
  const Vector3 n(0, 0, 1);
  // Froude number 8.5, halfway between the samples: p = 0.4. Head-on, no spin.
  const Scalar speed = std::sqrt(Scalar(8.5) * landing_test_g * sig.length);
  Pcg32 rng(7, 3);
  const int draws = 20000;
  int stays = 0, flights_up = 0;
  for (int i = 0; i < draws; ++i) {
    Vector3 v(0, 0, -speed), w(0, 0, Scalar(0.5));
    const ResponseOutcome o = statistical_response<3>(sig, Quaternion::Identity(), n, v, w, rng, landing_test_g);
    REQUIRE(o.applied);
    if (o.stayed) {
      ++stays;
      CHECK(v.dot(n) == 0);
      CHECK(w == Vector3::Zero());
    } else if (v.dot(n) > 0) {
      ++flights_up;
    }
  }
  const double share = double(stays) / draws, se = std::sqrt(0.4 * 0.6 / draws);
  CHECK(std::fabs(share - 0.4) < 4 * se);
  CHECK(flights_up > draws / 2);  // the others rebound as the response table says

  // The probability at a table coordinate, and clamped beyond the axes.
  CHECK(landing_probability(sig.landing, 1, 0, 1) == doctest::Approx(0.2));
  CHECK(landing_probability(sig.landing, 1, 0, 16) == doctest::Approx(0.6));
  CHECK(landing_probability(sig.landing, 1, 0, 100) == doctest::Approx(0.6));
  CHECK(landing_probability(sig.landing, 0.5f, 3, 8.5f) == doctest::Approx(0.4));
}

TEST_CASE("landing: a negative probability draws a response that would stay again, with that probability")
{
  // Every cell -0.6: a draw that would rise less than hop L is drawn again in 6 of 10 cases, so
  // q stay of the draws becomes q (1 - 0.6 (1 - q)). Head-on at 1.18 m/s the cube's draws rise
  // about hop L (0.35 |v| against 0.41 m/s), q about one half.
  static const Scalar redraw[] = {-0.6f, -0.6f, -0.6f, -0.6f, -0.6f, -0.6f, -0.6f, -0.6f};
  const SignatureView<3> zero_p = landing_test_view(testing::cube_synthetic.view(), Span<const Scalar>(landing_test_zero));
  const SignatureView<3> negative_p = landing_test_view(testing::cube_synthetic.view(), Span<const Scalar>(redraw));
  const Vector3 n(0, 0, 1);
  const Scalar limit = 2 * landing_test_g * zero_p.landing.hop * zero_p.length;
  const int draws = 20000;
  double share[2];
  int redrawn = 0;
  for (int k = 0; k < 2; ++k) {
    Pcg32 rng(3, 9);
    int stays = 0;
    for (int i = 0; i < draws; ++i) {
      Vector3 v(0, 0, Scalar(-1.18)), w(0, 0, 0);
      const ResponseOutcome o = statistical_response<3>(k ? negative_p : zero_p, Quaternion::Identity(), n, v, w, rng,
                                                        landing_test_g);
      CHECK(!o.stayed);
      redrawn += o.redrawn;
      stays += v.dot(n) * v.dot(n) < limit;
    }
    share[k] = double(stays) / draws;
  }
  const double q = share[0], expected = q * (1 - 0.6 * (1 - q));
  CHECK(q > 0.2);
  CHECK(q < 0.8);
  CHECK(std::fabs(share[1] - expected) < 4 * std::sqrt(expected * (1 - expected) / draws));
  CHECK(std::fabs(double(redrawn) / draws - 0.6 * q) < 4 * std::sqrt(0.6 * q / draws));
}

TEST_CASE("landing: without the data, or without gravity onto the plane, the response is the one before, bit for bit")
{
  const SignatureView<3> plain = testing::cube_synthetic.view();
  const SignatureView<3> landing = landing_test_view(plain);
  const Vector3 n(0, 0, 1);
  for (int i = 0; i < 200; ++i) {
    const Vector3 v0(Scalar(0.3) * Scalar(i % 7) - 1, Scalar(0.1) * Scalar(i % 3), -Scalar(0.5) - Scalar(0.02) * Scalar(i));
    const Vector3 w0(Scalar(i % 5) - 2, Scalar(1), Scalar(i % 2));
    // The response as it was: no landing data, no gravity argument.
    Vector3 v_ref = v0, w_ref = w0;
    Pcg32 rng_ref(11, std::uint64_t(i));
    statistical_response<3>(plain, Quaternion::Identity(), n, v_ref, w_ref, rng_ref);
    // No landing data, with gravity; landing data, without gravity (a wall, a body).
    for (const auto& [view, gravity] : {std::pair<const SignatureView<3>*, Scalar>{&plain, landing_test_g}, {&landing, Scalar(0)}}) {
      Vector3 v = v0, w = w0;
      Pcg32 rng(11, std::uint64_t(i));
      const ResponseOutcome o = statistical_response<3>(*view, Quaternion::Identity(), n, v, w, rng, gravity);
      CHECK(!o.stayed);
      CHECK(v == v_ref);
      CHECK(w == w_ref);
      CHECK(rng.state() == rng_ref.state());
    }
  }
}

TEST_CASE("landing: add_shape refuses malformed landing data and leaves the world unchanged")
{
  const SignatureView<3> valid = landing_test_view(testing::cube_synthetic.view());
  static Scalar bad_values[8];
  static const Scalar decreasing[] = {1.0f, 0.5f};
  static const Scalar negative[] = {-1.0f, 8.0f};
  const Scalar nan = std::numeric_limits<Scalar>::quiet_NaN();
  std::vector<std::pair<std::string, std::function<void(SignatureView<3>&)>>> mutations = {
      {"probability above 1", [](SignatureView<3>& v) { v.landing.probability = Span<const Scalar>(bad_values); }},
      {"one probability short", [](SignatureView<3>& v) { v.landing.probability.size = 7; }},
      {"one probability too many", [](SignatureView<3>& v) { v.landing.probability.size = 9; }},
      {"an axis missing", [](SignatureView<3>& v) { v.landing.axes[1] = AxisView(); }},
      {"an axis decreasing", [](SignatureView<3>& v) { v.landing.axes[0] = AxisView(decreasing); }},
      {"a negative Froude number", [](SignatureView<3>& v) { v.landing.axes[2] = AxisView(negative); }},
      {"a negative spin ratio", [](SignatureView<3>& v) { v.landing.axes[1] = AxisView(negative); }},
      {"hop not a number", [nan](SignatureView<3>& v) { v.landing.hop = nan; }},
      {"hop negative", [](SignatureView<3>& v) { v.landing.hop = -0.1f; }},
  };
  for (Scalar p : {Scalar(1.5), Scalar(-1.5), nan}) {
    for (int i = 0; i < 8; ++i) bad_values[i] = landing_test_probability[i];
    bad_values[5] = p;
    auto w = std::make_unique<World3<4>>();
    for (const auto& [what, mutate] : mutations) {
      CAPTURE(what);
      CAPTURE(p);
      SignatureView<3> v = valid;
      mutate(v);
      const std::uint32_t shapes = w->shape_count();
      CHECK(w->add_shape(v).status == Status::invalid_shape);
      CHECK(w->shape_count() == shapes);
    }
    CHECK(w->add_shape(valid).ok());
  }
}

TEST_CASE("landing: a world with landing data is deterministic, and the data changes its drops")
{
  const auto run = [](const SignatureView<3>& view) {
    auto w = std::make_unique<World3<30>>();
    const auto shape = w->add_shape(view);
    REQUIRE(shape.ok());
    REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
    Pcg32 rng(5, 1);
    for (int i = 0; i < 30; ++i) {
      BodyDef3 b;
      b.shape = shape.id;
      b.position = Vector3(Scalar(0.6) * Scalar(i % 6), Scalar(0.6) * Scalar(i / 6), rng.uniform(0.4f, 1.2f));
      b.orientation = random_orientation<3>(rng);
      b.linear_velocity = Vector3(rng.uniform(-0.5f, 0.5f), rng.uniform(-0.5f, 0.5f), 0);
      b.angular_velocity = Vector3(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
      REQUIRE(w->add_body(b).ok());
    }
    for (int s = 0; s < 120; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
    return w->state_hash();
  };
  const SignatureView<3> landing = landing_test_view(testing::cube_synthetic.view());
  const std::uint64_t a = run(landing), b = run(landing);
  CHECK(a == b);
  CHECK(a != run(testing::cube_synthetic.view()));
}
