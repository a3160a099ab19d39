// The settling data of a signature (statsim/signature_settle.hpp): a body's settling time is drawn
// from its pose's quantiles; it rocks about the pose while the time runs and cannot sleep before
// it is over, then stops; a table without the data settles as before; malformed data is refused
// by add_shape with the world unchanged; a world with the data is deterministic and saves and
// loads mid-rock.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/snapshot.hpp"
#include "statsim/statistical.hpp"
#include "statsim/world3.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

using namespace statsim;

namespace {

// Four quantiles for each of the cube's six poses: 0.5, 1, 2, 4 s, at the probabilities 1/8,
// 3/8, 5/8, 7/8.
constexpr std::uint32_t settle_test_quantiles = 4;
Scalar settle_test_times[6 * settle_test_quantiles];

SignatureView<3> settle_test_view(SignatureView<3> v, const Scalar* times = nullptr, std::uint32_t count = 0)
{
  if (times == nullptr) {
    for (std::uint32_t i = 0; i < 6; ++i) {
      settle_test_times[4 * i + 0] = 0.5f;
      settle_test_times[4 * i + 1] = 1.0f;
      settle_test_times[4 * i + 2] = 2.0f;
      settle_test_times[4 * i + 3] = 4.0f;
    }
    times = settle_test_times;
    count = 6 * settle_test_quantiles;
  }
  v.settle.time = Span<const Scalar>(times, count);
  v.settle.quantiles = count / v.rest.count;
  return v;
}

// Every pose settles for `t` seconds.
SignatureView<3> settle_fixed_view(Scalar t)
{
  static std::vector<std::vector<Scalar>> kept;
  kept.emplace_back(std::size_t(6), t);
  return settle_test_view(testing::cube_synthetic.view(), kept.back().data(), 6);
}

// One cube dropped 2 cm onto the ground, tilted 30 degrees about x so that it has to turn into
// its pose. Steps of 1/60 s until it sleeps (at most `limit` s): when it chose its pose, when it
// slept, and the largest spin while its settling time ran.
struct Settled {
  double chosen = -1, asleep = -1, spin = 0;
  double quiet = -1;  // from when on centre and farthest point moved slower than 1 cm/s (after `chosen`)
};

Settled drop_one(const SignatureView<3>& view, double limit = 12)
{
  auto w = std::make_unique<World3<4>>();
  const auto shape = w->add_shape(view);
  REQUIRE(shape.ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  BodyDef3 b;
  b.shape = shape.id;
  b.position = Vector3(0, 0, Scalar(0.16));
  b.orientation = Quaternion(Eigen::AngleAxis<Scalar>(Scalar(0.52), Vector3::UnitX()));
  const auto id = w->add_body(b);
  REQUIRE(id.ok());
  Settled s;
  const Scalar dt = Scalar(1) / 60;
  for (int k = 1; k <= int(limit * 60); ++k) {
    REQUIRE(w->step(dt).ok());
    const auto& body = w->body(id.id);
    const double t = k * double(dt);
    if (s.chosen < 0 && body.rest_pose != no_rest_pose) s.chosen = t;
    if (body.slow_time < 0) s.spin = std::max(s.spin, double(body.angular_velocity.norm()));
    const double bound = double(view.bounding_radius);
    if (s.chosen >= 0 && !(body.linear_velocity.norm() < 0.01 && body.angular_velocity.norm() * bound < 0.01))
      s.quiet = t + double(dt);
    if (body.state == MotionState::asleep) {
      s.asleep = t;
      break;
    }
  }
  return s;
}

}  // namespace

TEST_CASE("settle: a settling time is drawn from the pose's quantiles")
{
  const SignatureView<3> sig = settle_test_view(testing::cube_synthetic.view());
  const SettleView& t = sig.settle;
  REQUIRE(t.present());
  CHECK(t.quantiles == 4);
  // Linear between the quantiles at (k + 1/2) / 4, held beyond the first and the last.
  CHECK(t.at(0, 0) == 0.5f);
  CHECK(t.at(2, 0.125f) == 0.5f);
  CHECK(t.at(2, 0.25f) == doctest::Approx(0.75));
  CHECK(t.at(5, 0.5f) == doctest::Approx(1.5));
  CHECK(t.at(5, 0.875f) == doctest::Approx(4.0));
  CHECK(t.at(5, 0.999f) == 4.0f);
  // Over many draws each quantile has its probability below it.
  Pcg32 rng(17, 4);
  const int draws = 40000;
  int below[4] = {};
  for (int i = 0; i < draws; ++i) {
    const Scalar x = t.at(3, rng.uniform());
    // The draws beyond the last probability hold the last value: below it, not at it, count.
    for (int k = 0; k < 4; ++k) {
      const Scalar q = t.time.values[3 * 4 + std::uint32_t(k)];
      below[k] += k < 3 ? x <= q : x < q;
    }
  }
  for (int k = 0; k < 4; ++k) {
    const double p = (k + 0.5) / 4, se = std::sqrt(p * (1 - p) / draws);
    CAPTURE(k);
    CHECK(std::fabs(double(below[k]) / draws - p) < 4 * se);
  }
}

TEST_CASE("settle: a body rocks while its settling time runs, sleeps once it is over, and stops in its pose")
{
  const Settled plain = drop_one(testing::cube_synthetic.view());
  REQUIRE(plain.chosen > 0);
  REQUIRE(plain.asleep > 0);
  // The sleep time (0.5 s) after the pose is reached: with a settling time of 3 s the body sleeps
  // 3 s after it chose its pose, and a sleep time later; with 6 s, 3 s later than that.
  const double sleep_time = double(WorldDef3{}.sleep_time), dt = 1.0 / 60;
  const Settled three = drop_one(settle_fixed_view(3)), six = drop_one(settle_fixed_view(6));
  for (const Settled* s : {&three, &six}) {
    REQUIRE(s->asleep > 0);
    CHECK(s->chosen == doctest::Approx(plain.chosen).epsilon(0.2));
  }
  CHECK(three.asleep >= three.chosen + 3 + sleep_time - 2 * dt);
  CHECK(three.asleep <= three.chosen + 3 + sleep_time + 0.25);
  CHECK(six.asleep - six.chosen == doctest::Approx(three.asleep - three.chosen + 3).epsilon(0.02));
  // It moved while the time ran: a rock, not a wait (its farthest point above the sleep speed).
  const double bound = double(testing::cube_synthetic.view().bounding_radius);
  CHECK(three.spin * bound > double(WorldDef3{}.sleep_speed));
  // A short settling time stops it in its pose sooner than the rest turn's creep into the pose
  // does, and before the long ones let it.
  const Settled quick = drop_one(settle_fixed_view(0.05f));
  REQUIRE(quick.quiet > 0);
  REQUIRE(plain.quiet > 0);
  CHECK(quick.quiet - quick.chosen < plain.quiet - plain.chosen);
  CAPTURE(three.chosen);
  CAPTURE(three.asleep);
  CAPTURE(three.spin);
  CHECK(three.quiet >= three.chosen + 3 - 2 * dt);
}

TEST_CASE("settle: add_shape refuses malformed settling data and leaves the world unchanged")
{
  const SignatureView<3> valid = settle_test_view(testing::cube_synthetic.view());
  static Scalar bad[6 * settle_test_quantiles];
  const Scalar nan = std::numeric_limits<Scalar>::quiet_NaN();
  const auto with = [](Scalar x, std::uint32_t at) {
    std::copy(settle_test_times, settle_test_times + 6 * settle_test_quantiles, bad);
    bad[at] = x;
    return [](SignatureView<3>& v) { v.settle.time = Span<const Scalar>(bad, 6 * settle_test_quantiles); };
  };
  std::vector<std::pair<std::string, std::function<void(SignatureView<3>&)>>> mutations = {
      {"a value short of whole poses", [](SignatureView<3>& v) { v.settle.time.size = 23, v.settle.quantiles = 0; }},
      {"a count that disagrees", [](SignatureView<3>& v) { v.settle.quantiles = 3; }},
      {"no values behind the count", [](SignatureView<3>& v) { v.settle.time.values = nullptr; }},
      {"more quantiles than a table may hold",
       [](SignatureView<3>& v) { v.settle.quantiles = max_settle_quantiles + 1; }},
  };
  auto w = std::make_unique<World3<4>>();
  for (const auto& [what, mutate] : mutations) {
    CAPTURE(what);
    SignatureView<3> v = valid;
    mutate(v);
    const std::uint32_t shapes = w->shape_count();
    CHECK(w->add_shape(v).status == Status::invalid_shape);
    CHECK(w->shape_count() == shapes);
  }
  // Values: negative, not a number, beyond max_settle_time, and a quantile below the one before.
  for (const auto& [x, at] : {std::pair<Scalar, std::uint32_t>{-0.1f, 0}, {nan, 5}, {max_settle_time * 2, 23},
                              {0.25f, 9}}) {
    CAPTURE(x);
    CAPTURE(at);
    SignatureView<3> v = valid;
    with(x, at)(v);
    const std::uint32_t shapes = w->shape_count();
    CHECK(w->add_shape(v).status == Status::invalid_shape);
    CHECK(w->shape_count() == shapes);
  }
  CHECK(w->add_shape(valid).ok());
}

TEST_CASE("settle: a world with settling data is deterministic, differs from one without, and loads mid-rock")
{
  using World = World3<30, 8, 180, 4>;
  const auto build = [](World& w, const SignatureView<3>& view) {
    const auto shape = w.add_shape(view);
    REQUIRE(shape.ok());
    REQUIRE(w.add_plane(Vector3(0, 0, 1), 0).ok());
    Pcg32 rng(5, 1);
    for (int i = 0; i < 30; ++i) {
      BodyDef3 b;
      b.shape = shape.id;
      b.position = Vector3(Scalar(0.6) * Scalar(i % 6), Scalar(0.6) * Scalar(i / 6), rng.uniform(0.4f, 1.2f));
      b.orientation = random_orientation<3>(rng);
      b.linear_velocity = Vector3(rng.uniform(-0.5f, 0.5f), rng.uniform(-0.5f, 0.5f), 0);
      b.angular_velocity = Vector3(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
      REQUIRE(w.add_body(b).ok());
    }
  };
  const auto run = [&](const SignatureView<3>& view) {
    auto w = std::make_unique<World>();
    build(*w, view);
    for (int s = 0; s < 240; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
    return w->state_hash();
  };
  const SignatureView<3> settle = settle_test_view(testing::cube_synthetic.view());
  const std::uint64_t a = run(settle);
  CHECK(a == run(settle));
  CHECK(a != run(testing::cube_synthetic.view()));
  // Saved while bodies rock (negative slow times), loaded into a fresh world: the same steps on.
  auto w = std::make_unique<World>();
  build(*w, settle);
  int rocking = 0;
  for (int s = 0; s < 90; ++s) REQUIRE(w->step(Scalar(1) / 60).ok());
  for (std::uint32_t i = 0; i < w->body_count(); ++i) rocking += w->body(i).slow_time < 0;
  CHECK(rocking > 0);
  std::vector<unsigned char> bytes(snapshot_size(*w));
  REQUIRE(save(*w, bytes.data(), bytes.size(), nullptr) == Status::ok);
  auto v = std::make_unique<World>();
  REQUIRE(v->add_shape(settle).ok());
  REQUIRE(load(*v, bytes.data(), bytes.size()) == Status::ok);
  for (int s = 0; s < 150; ++s) {
    REQUIRE(w->step(Scalar(1) / 60).ok());
    REQUIRE(v->step(Scalar(1) / 60).ok());
  }
  CHECK(v->state_hash() == w->state_hash());
}
