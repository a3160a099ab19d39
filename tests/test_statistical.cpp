#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/statistical.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/bunny.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

using namespace statsim;

namespace {
// A small 3D signature (scaled layout: cos theta, cos phi, spin ratio) whose response means are
// a known linear function of the coordinates, so interpolation can be checked exactly.
using Sig3 = Signature<3, 3, 3, 2, 3, 1, 1>;
using Sig2 = Signature<2, 3, 3, 3, 1, 1, 2>;

Scalar linear(std::uint32_t c, Scalar x0, Scalar x1, Scalar x2) { return Scalar(0.01) * Scalar(c + 1) + Scalar(0.02) * x0 - Scalar(0.03) * x1 + Scalar(0.01) * x2; }

Sig3 make_sig3()
{
  Sig3 s{};
  s.name = "test3";
  s.length = 0.5f;
  s.bounding_radius = 0.5f;
  s.mass = 1;
  s.unit_inertia = {0.1f, 0.1f, 0.1f};
  s.material = Material{0.3f, 0.2f, 0};
  s.restitution_threshold = 0.1f;
  s.layout = ResponseLayout::scaled;
  s.axis_count = 3;
  s.height_axis = {0, 1, 4};
  s.height_mean = {0.3f, 0.4f, 0.45f};
  s.height_stddev = {0.05f, 0.02f, 0.01f};
  s.axis0 = {0.1f, 0.5f, 1.0f};
  s.axis1 = {-1, 1};
  s.axis2 = {0, 1, 3};
  s.axis3 = {0};
  std::uint32_t k = 0;
  for (Scalar x0 : s.axis0)
    for (Scalar x1 : s.axis1)
      for (Scalar x2 : s.axis2)
        for (std::uint32_t c = 0; c < 6; ++c, ++k) {
          s.response_mean[k] = linear(c, x0, x1, x2);
          s.response_spread[k] = Scalar(0.02) + Scalar(0.005) * Scalar(c);
        }
  s.rest_normals = {0, 0, 1};
  s.rest_heights = {0.25f};
  s.rest_frequencies = {1};
  return s;
}
}  // namespace

TEST_CASE("axis lookup: interior fractions and clamping at both ends")
{
  const Scalar v[] = {0, 1, 4};
  const AxisView a{v, 3};
  CHECK(locate(a, -5).index == 0);
  CHECK(locate(a, -5).t == 0);
  CHECK(locate(a, 0.25f).index == 0);
  CHECK(locate(a, 0.25f).t == doctest::Approx(0.25));
  CHECK(locate(a, 1).index == 1);
  CHECK(locate(a, 1).t == 0);
  CHECK(locate(a, 2.5f).t == doctest::Approx(0.5));
  CHECK(locate(a, 9).index == 1);
  CHECK(locate(a, 9).t == 1);
  CHECK(locate(a, std::nanf("")).index == 0);
}

TEST_CASE("multilinear lookup reproduces a linear function inside the grid and clamps outside")
{
  const Sig3 sig = make_sig3();
  const SignatureView<3> view = sig.view();
  Scalar mean[6], sd[6];
  const Scalar x[] = {0.3f, 0.2f, 2.0f};
  view.response.lookup(x, mean, sd);
  for (std::uint32_t c = 0; c < 6; ++c) CHECK(mean[c] == doctest::Approx(linear(c, 0.3f, 0.2f, 2.0f)));
  const Scalar outside[] = {5, -3, 10};
  view.response.lookup(outside, mean, sd);
  for (std::uint32_t c = 0; c < 6; ++c) CHECK(mean[c] == doctest::Approx(linear(c, 1, -1, 3)));
  CHECK(view.height.mean_at(0.5f) == doctest::Approx(0.35));
  CHECK(view.height.mean_at(100) == doctest::Approx(0.45));
  CHECK(view.height.nearest_at(0.6f) == doctest::Approx(0.4));
}

TEST_CASE("spin ratio never divides by a vanishing speed")
{
  CHECK(spin_ratio<3>(Vector3::Zero(), Vector3(0, 0, 1), 0.5f, 8) == 8);
  CHECK(spin_ratio<3>(Vector3::Zero(), Vector3::Zero(), 0.5f, 8) == 0);
  CHECK(spin_ratio<3>(Vector3(2, 0, 0), Vector3(0, 0, 1), 0.5f, 8) == doctest::Approx(0.25));
  CHECK(spin_ratio<2>(Vector2(1e-30f, 0), 3.0f, 0.5f, 8) == 8);
  const Sig3 sig = make_sig3();
  CHECK(collision_radius<3>(sig.view(), Vector3::Zero(), Vector3::Zero()) == doctest::Approx(0.3));
  CHECK(collision_radius<3>(sig.view(), Vector3::Zero(), Vector3(1, 0, 0)) == doctest::Approx(0.45));
}

TEST_CASE("3D frame transforms: sampled responses rotated back match the table cell")
{
  const Sig3 sig = make_sig3();
  const SignatureView<3> view = sig.view();
  Pcg32 g(123, 0);
  for (int frame_trial = 0; frame_trial < 4; ++frame_trial) {
    // A random working frame: random normal, incidence cos 0.5, spin at a chosen angle to v.
    Vector3 n(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1));
    n.normalize();
    const Vector3 x = detail::any_perpendicular(n);
    const Vector3 y = n.cross(x);
    const Scalar speed = 2.0f, cos_t = 0.5f, sin_t = std::sqrt(1 - cos_t * cos_t);
    const Vector3 v = (x * sin_t - n * cos_t) * speed;
    const Vector3 w = (v.normalized() * 0.6f + y * 0.8f) * (1.0f * speed / view.length);  // cos phi 0.6, s = 1
    Scalar coords[4];
    const ContactFrame<3> f = contact_frame(n, v, w);
    REQUIRE(response_coordinates<3>(view, f, Quaternion::Identity(), n, v, w, coords) == 3);
    CHECK(coords[0] == doctest::Approx(0.5));
    CHECK(coords[1] == doctest::Approx(0.6));
    CHECK(coords[2] == doctest::Approx(1.0));
    Scalar mean[6], sd[6];
    view.response.lookup(coords, mean, sd);

    const Eigen::Matrix3f basis = (Eigen::Matrix3f() << x, y, n).finished();
    const Vector3 vp = point_particle_velocity<3>(v, n, view.material, view.restitution_threshold);
    const int samples = 20000;
    double s1[6] = {}, s2[6] = {};
    int clamped = 0;
    for (int i = 0; i < samples; ++i) {
      Vector3 vv = v, ww = w;
      const ResponseOutcome o = statistical_response<3>(view, Quaternion::Identity(), n, vv, ww, g);
      REQUIRE(o.applied);
      clamped += o.energy_clamped;
      const Vector3 wc = basis.transpose() * ww * (view.length / speed);
      const Vector3 dc = basis.transpose() * (vv - vp) / speed;
      const double c[6] = {wc.x(), wc.y(), wc.z(), dc.x(), dc.y(), dc.z()};
      for (int k = 0; k < 6; ++k) {
        s1[k] += c[k];
        s2[k] += c[k] * c[k];
      }
    }
    CHECK(clamped == 0);
    for (int k = 0; k < 6; ++k) {
      const double m = s1[k] / samples, sdev = std::sqrt(s2[k] / samples - m * m);
      // Standard error of the mean sd/sqrt(n) < 3.2e-4; of the sd about sd/sqrt(2n) < 2.3e-4.
      CHECK(std::fabs(m - mean[k]) < 5 * sd[k] / std::sqrt(double(samples)));
      CHECK(std::fabs(sdev - sd[k]) < 5 * sd[k] / std::sqrt(2.0 * samples));
    }
  }
}

TEST_CASE("spin by gyration: a draw's rotational energy does not depend on how the body is turned")
{
  // A thin body (moments 0.002, 0.1, 0.1 m^2) and a table without spread: each draw is the
  // cell's mean, so the spin the runtime makes of it can be checked exactly.
  Sig3 sig = make_sig3();
  sig.unit_inertia = {0.002f, 0.1f, 0.1f};
  for (Scalar& x : sig.response_spread) x = 0;
  Sig3 by_length = sig;
  sig.spin = ResponseSpin::gyration;
  const SignatureView<3> view = sig.view(), length_view = by_length.view();
  REQUIRE(view.spin == ResponseSpin::gyration);
  REQUIRE(length_view.spin == ResponseSpin::length);
  const Vector3 n(0, 0, 1), v0(1, 0, -std::sqrt(3.0f)), w0(0, 4, 0);  // cos theta 0.866, |V-| = 2 m/s
  const Scalar speed = v0.norm();
  Scalar coords[4];
  const ContactFrame<3> frame = contact_frame(n, v0, w0);
  response_coordinates<3>(view, frame, Quaternion::Identity(), n, v0, w0, coords);
  Scalar mean[6], sd[6];
  view.response.lookup(coords, mean, sd);
  const Vector3 drawn = frame.basis * Vector3(mean[0], mean[1], mean[2]);
  const Scalar expected = Scalar(0.5) * drawn.squaredNorm() * speed * speed;
  const auto rotational = [&](const Quaternion& q, const Vector3& w) {
    const Vector3 b = q.conjugate() * w;
    return Scalar(0.5) * (sig.unit_inertia[0] * b.x() * b.x() + sig.unit_inertia[1] * b.y() * b.y() +
                          sig.unit_inertia[2] * b.z() * b.z());
  };
  Pcg32 g(9, 1);
  Scalar low = 1e30f, high = 0;
  for (int k = 0; k < 32; ++k) {
    const Quaternion q = Quaternion(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1)).normalized();
    CAPTURE(k);
    Vector3 v = v0, w = w0;
    Pcg32 r(1, 1);
    const ResponseOutcome o = statistical_response<3>(view, q, n, v, w, r);
    REQUIRE(o.applied);
    REQUIRE_FALSE(o.energy_clamped);
    CHECK(rotational(q, w) == doctest::Approx(expected).epsilon(1e-5));
    // The spin itself: R diag(1 / sqrt(I_k / m)) R^T (draw) |V-|.
    Vector3 b = q.conjugate() * drawn;
    for (int i = 0; i < 3; ++i) b[i] /= std::sqrt(sig.unit_inertia[std::size_t(i)]);
    CHECK((w - q * b * speed).norm() < 1e-4f * w.norm());
    // The same draw by length keeps the spin whatever the orientation, so its energy changes.
    Vector3 vl = v0, wl = w0;
    Pcg32 rl(1, 1);
    REQUIRE(statistical_response<3>(length_view, q, n, vl, wl, rl).applied);
    CHECK((wl - drawn * (speed / view.length)).norm() < 1e-5f * wl.norm());
    low = std::min(low, rotational(q, wl));
    high = std::max(high, rotational(q, wl));
  }
  CHECK(high > 3 * low);
}

TEST_CASE("spin by energy: the table is looked up at the incoming spin's energy, by the body's own axes")
{
  // The thin body of the test above: about its long axis (body x) a spin has 1/50 of the energy
  // it has about a short one.
  Sig3 sig = make_sig3();
  sig.unit_inertia = {0.002f, 0.1f, 0.1f};
  Sig3 by_gyration = sig, by_length = sig;
  sig.spin = ResponseSpin::energy;
  by_gyration.spin = ResponseSpin::gyration;
  const SignatureView<3> view = sig.view(), gyration_view = by_gyration.view(), length_view = by_length.view();
  const Vector3 n(0, 0, 1), v(1, 0, -std::sqrt(3.0f));  // |V-| = 2 m/s
  const Scalar speed = v.norm(), k = std::sqrt((0.002f + 0.1f + 0.1f) / 3), omega = 4;
  const Scalar along_long = omega * std::sqrt(0.002f) / k * view.length / speed;
  const Scalar along_short = omega * std::sqrt(0.1f) / k * view.length / speed;
  // The body turned a quarter about z: its long axis lies along world y.
  const Quaternion quarter(Eigen::AngleAxisf(Scalar(1.5707963), Vector3::UnitZ()));
  const struct {
    Quaternion q;
    Vector3 w;
    Scalar expected;
  } cases[] = {{Quaternion::Identity(), Vector3(omega, 0, 0), along_long},
               {Quaternion::Identity(), Vector3(0, omega, 0), along_short},
               {quarter, Vector3(0, omega, 0), along_long},
               {quarter, Vector3(omega, 0, 0), along_short}};
  for (const auto& c : cases) {
    CAPTURE(c.expected);
    const ContactFrame<3> frame = contact_frame(n, v, c.w);
    Scalar x[4], xg[4], xl[4];
    REQUIRE(response_coordinates<3>(view, frame, c.q, n, v, c.w, x) == 3);
    response_coordinates<3>(gyration_view, frame, c.q, n, v, c.w, xg);
    response_coordinates<3>(length_view, frame, c.q, n, v, c.w, xl);
    CHECK(x[2] == doctest::Approx(c.expected).epsilon(1e-5));
    // Tables by gyration (format 2.4) and by length are looked up as before: |W-| L / |V-|.
    CHECK(xg[2] == doctest::Approx(omega * view.length / speed).epsilon(1e-6));
    CHECK(xl[2] == xg[2]);
    CHECK(x[0] == xg[0]);
    CHECK(x[1] == xg[1]);
  }
  // A body with three equal moments: energy and length give the same ratio.
  Sig3 round = make_sig3();
  round.unit_inertia = {0.05f, 0.05f, 0.05f};
  round.spin = ResponseSpin::energy;
  const Vector3 w(1, 2, 3);
  Scalar x[4], xl[4];
  response_coordinates<3>(round.view(), contact_frame(n, v, w), quarter, n, v, w, x);
  response_coordinates<3>(length_view, contact_frame(n, v, w), quarter, n, v, w, xl);
  CHECK(x[2] == doctest::Approx(xl[2]).epsilon(1e-6));
}

TEST_CASE("spin by gyration: add_shape refuses it in 2D, without every moment, or as an unknown value")
{
  const auto refused = [](auto& world, const auto& v) {
    const std::uint32_t shapes = world.shape_count();
    CHECK(world.add_shape(v).status == Status::invalid_shape);
    CHECK(world.shape_count() == shapes);
  };
  auto w3 = std::make_unique<World3<4>>();
  Sig3 sig = make_sig3();
  sig.spin = ResponseSpin::gyration;
  SignatureView<3> v = sig.view();
  v.unit_inertia[1] = 0;  // not recorded
  refused(*w3, v);
  v.unit_inertia[1] = Scalar(1e-9) * v.length * v.length;  // a radius of gyration that vanishes
  refused(*w3, v);
  v = sig.view();
  v.spin = static_cast<ResponseSpin>(3);
  refused(*w3, v);
  v = sig.view();
  v.spin = ResponseSpin::energy;
  v.unit_inertia[2] = 0;  // `energy` needs every moment as well
  refused(*w3, v);
  CHECK(w3->add_shape(sig.view()).ok());
  // The measure is part of the table: a shape by gyration hashes apart from the same by length.
  Sig3 by_length = make_sig3();
  CHECK(detail::signature_hash(by_length.view()) != detail::signature_hash(sig.view()));

  auto w2 = std::make_unique<World2<4>>();
  SignatureView<2> v2 = testing::square2d_synthetic.view();
  v2.spin = ResponseSpin::gyration;
  refused(*w2, v2);
  v2.spin = ResponseSpin::energy;
  refused(*w2, v2);
  CHECK(w2->add_shape(testing::square2d_synthetic.view()).ok());
}

TEST_CASE("2D frame transforms: mirrored contacts flip the spin and the tangent")
{
  Sig2 s{};
  s.name = "test2";
  s.length = 1;
  s.bounding_radius = 1;
  s.unit_inertia = {0.2f, 0, 0};
  s.material = Material{0.3f, 0.2f, 0};
  s.restitution_threshold = 0.1f;
  s.axis_count = 2;
  s.height_axis = {0, 1, 2};
  s.height_mean = {0.5f, 0.6f, 0.7f};
  s.height_stddev = {0, 0, 0};
  s.axis0 = {0, 0.5f, 1};
  s.axis1 = {-2, 0, 2};
  s.axis2 = {0};
  s.axis3 = {0};
  for (std::uint32_t cell = 0; cell < 9; ++cell) {
    const Scalar spin = s.axis1[cell % 3];
    s.response_mean[cell * 3 + 0] = Scalar(0.1) * spin;  // spin keeps its sense, scaled down
    s.response_mean[cell * 3 + 1] = Scalar(0.05);         // extra tangential speed
    s.response_mean[cell * 3 + 2] = Scalar(0.02);         // extra normal speed
  }
  s.rest_normals = {0, 1, 1, 0};
  s.rest_heights = {0.5f, 0.5f};
  s.rest_frequencies = {0.5f, 0.5f};
  const SignatureView<2> view = s.view();
  const Vector2 n(0, 1);
  Pcg32 g(5, 5);
  // Same contact and its mirror image: moving right spinning clockwise, moving left spinning
  // counter-clockwise. Zero stddev: the responses are exact mirror images.
  Vector2 v1(1, -1), v2(-1, -1);
  Scalar w1 = -1.5f, w2 = 1.5f;
  REQUIRE(statistical_response<2>(view, Rot2{}, n, v1, w1, g).applied);
  REQUIRE(statistical_response<2>(view, Rot2{}, n, v2, w2, g).applied);
  CHECK(v1.x() == doctest::Approx(-v2.x()));
  CHECK(v1.y() == doctest::Approx(v2.y()));
  CHECK(w1 == doctest::Approx(-w2));
  CHECK(w1 < 0);  // the spin kept its sense
  CHECK(v1.y() > 0);
}

TEST_CASE("rest poses: nearest pose, turn direction and snap")
{
  const Sig3 sig3 = make_sig3();
  const SignatureView<3> view = sig3.view();
  const Quaternion tilted(Eigen::AngleAxisf(0.3f, Vector3(1, 0, 0)));
  CHECK(nearest_rest_pose<3>(view, tilted, Vector3(0, 0, 1)) == 0);
  const Vector3 turn = rest_turn(tilted, Vector3(0, 0, 1), Vector3(0, 0, 1), 0.1f);
  CHECK(turn.x() < 0);  // rotate back about -x
  CHECK(turn.norm() == doctest::Approx(std::sin(0.3) / 0.1).epsilon(1e-4));
  const Quaternion snapped = snap_to_rest(tilted, Vector3(0, 0, 1), Vector3(0, 0, 1));
  CHECK((snapped * Vector3(0, 0, 1) - Vector3(0, 0, 1)).norm() < 1e-6f);
  const Quaternion upside(Eigen::AngleAxisf(3.14159265f, Vector3(0, 1, 0)));
  CHECK((snap_to_rest(upside, Vector3(0, 0, 1), Vector3(0, 0, 1)) * Vector3(0, 0, 1) - Vector3(0, 0, 1)).norm() < 1e-5f);
  const Rot2 r = Rot2::from_angle(0.4f);
  const Rot2 r2 = snap_to_rest(r, Vector2(0, 1), Vector2(0, 1));
  CHECK((r2 * Vector2(0, 1) - Vector2(0, 1)).norm() < 1e-6f);
}

TEST_CASE("rest pose basins: uniform directions fall into the poses at the table's frequencies")
{
  // The bunny's plain nearest-pose cells hold 18%, 19%, 25%, 17% and 21% of all directions; its
  // table says 42%, 29%, 15%, 8% and 6% of the kept drops. Independent random directions (not
  // the lattice the biases were fitted on) must fall into the biased basins at the table's shares.
  const SignatureView<3> bunny = statsim::tables::bunny.view();
  Scalar bias[max_rest_poses];
  rest_basin_biases<3>(bunny, bias);
  float total = 0;
  for (std::uint32_t p = 0; p < bunny.rest.count; ++p) total += bunny.rest.frequencies[p];
  Pcg32 g(17, 4);
  constexpr int n = 20000;
  int plain[max_rest_poses] = {}, biased[max_rest_poses] = {};
  for (int k = 0; k < n; ++k) {
    float a, b, c, d;
    g.gaussian_pair(a, b);
    g.gaussian_pair(c, d);
    const Quaternion q = Quaternion(a, b, c, d).normalized();
    ++plain[nearest_rest_pose<3>(bunny, q, Vector3(0, 0, 1))];
    ++biased[nearest_rest_pose<3>(bunny, q, Vector3(0, 0, 1), bias)];
  }
  float tv_plain = 0, tv_biased = 0;
  for (std::uint32_t p = 0; p < bunny.rest.count; ++p) {
    const float expected = bunny.rest.frequencies[p] / total;
    CHECK(std::fabs(float(biased[p]) / n - expected) < 0.015f);
    tv_plain += std::fabs(float(plain[p]) / n - expected) / 2;
    tv_biased += std::fabs(float(biased[p]) / n - expected) / 2;
  }
  CHECK(tv_plain > 0.2f);  // the geometry alone is far from the table
  CHECK(tv_biased < 0.02f);
  // A symmetric signature (six faces, equal frequencies) needs no bias beyond what the lattice
  // of fitting directions resolves (0.005 in cosine moves a border by 0.2 degrees); 2D as well.
  const SignatureView<3> cube = statsim::testing::cube_synthetic.view();
  rest_basin_biases<3>(cube, bias);
  for (std::uint32_t p = 0; p < 6; ++p) CHECK(std::fabs(bias[p]) < 5e-3f);
  const SignatureView<2> square = statsim::testing::square2d_synthetic.view();
  rest_basin_biases<2>(square, bias);
  for (std::uint32_t p = 0; p < 4; ++p) CHECK(std::fabs(bias[p]) < 1e-3f);
}
