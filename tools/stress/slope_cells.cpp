// Stress cells on slopes: bodies resting below friction's angle and sliding above it, against
// the reference engines.
#include "stress/matrix.hpp"

#include "common/format.hpp"
#include "common/progress.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/square2d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace statsim::tools::stress {

// 8. slopes ------------------------------------------------------------------------------------------
/// What one method did on a slope, per body: whether it was asleep 10 s after it landed (its
/// centre first within R of the plane) and how far its centre had moved down the slope in those
/// 10 s, m.
struct SlopeRun {
  std::vector<bool> asleep;
  std::vector<double> slid;
};

/// Quantile q of the sorted values (nearest rank).
double quantile(const std::vector<double>& sorted, double q)
{
  if (sorted.empty()) return 0;
  const std::size_t k = std::min(sorted.size() - 1, static_cast<std::size_t>(q * double(sorted.size())));
  return sorted[k];
}

/// Steps a slope world frame by frame (`step()` advances one frame) until every body has been
/// on the slope for `after` seconds. `position(i)` is body i's centre, `asleep(i)` its state;
/// `height(x)` is the height of a centre above the plane and `along(x)` its position down the
/// slope.
template <class Step, class Position, class Asleep, class Height, class Along>
SlopeRun run_slope(std::size_t n, double frame, double after, double R, Step step, Position position, Asleep asleep,
                   Height height, Along along)
{
  SlopeRun r{std::vector<bool>(n, false), std::vector<double>(n, 0.0)};
  std::vector<long> landed(n, -1);
  std::vector<double> at_landing(n, 0.0);
  const long land_by = std::lround(3.0 / frame), wait = std::lround(after / frame);
  for (long f = 1; f <= land_by + wait; ++f) {
    step();
    bool done = true;
    for (std::size_t i = 0; i < n; ++i) {
      const auto x = position(i);
      if (landed[i] < 0 && height(x) < R) {
        landed[i] = f;
        at_landing[i] = along(x);
      }
      if (landed[i] >= 0 && f == landed[i] + wait) {
        r.asleep[i] = asleep(i);
        const double d = along(x) - at_landing[i];
        r.slid[i] = std::isfinite(d) ? d : kInf;
      }
      done = done && landed[i] >= 0 && f >= landed[i] + wait;
    }
    if (done) break;
    if (f == land_by)
      for (std::size_t i = 0; i < n; ++i)
        if (landed[i] < 0) throw std::runtime_error("stress: a body did not land on the slope within 3 s");
  }
  return r;
}

/// "asleep a/n, slid mean ... (quantiles)"; the mean distance slid, m, to `mean`.
std::string slope_summary(const SlopeRun& r, double& mean, std::size_t& asleep)
{
  std::vector<double> d = r.slid;
  std::sort(d.begin(), d.end());
  mean = 0;
  asleep = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    mean += d[i] / double(d.size());
    asleep += r.asleep[i];
  }
  return printf_string("asleep %zu/%zu, slid mean %.1f cm (p10 %.1f, median %.1f, p90 %.1f, max %.1f cm)", asleep, d.size(),
             100 * mean, 100 * quantile(d, 0.1), 100 * quantile(d, 0.5), 100 * quantile(d, 0.9), 100 * d.back());
}

/// Reference substeps per 1/60 s frame: 1/960 s, near the 1 ms the tables were gathered at (at
/// 1/240 s the share of reference bunnies asleep on 20 degrees is not yet converged).
constexpr int kSlopeReferenceSubsteps = 16;

void Matrix::slopes()
{
  // 3D: 100 bunnies, 10 x 10 at 5 R spacing on a plane through the origin that falls along +y
  // (alone: they do not meet), each released at rest in a random orientation with its centre
  // 0.5 m + R above the plane (vertically); friction 0.5 and restitution 0.3, the table's
  // material, for every method. 2D: 20 unit squares 3 m apart along a line falling along +x,
  // released the same way. The references are Bullet's full mesh and Box2D's polygon at
  // 1/960 s; the methods run at 1/60 s. Judged 10 s after each body lands.
  const double frame = 1.0 / 60, after = 10.0;
  const int side = opt_.quick ? 6 : 10;
  for (const double degrees : {10.0, 20.0, 35.0}) {
    const double a = degrees * 3.14159265358979323846 / 180;
    // The same test on every tilt: the bodies rest where the reference's rest and move on where
    // they move on. On 10 and 20 degrees tan(a) is below the friction, yet reference bunnies roll
    // on their curved backs and some are still moving 10 s after landing (README, "Slopes"):
    // requiring every body asleep there would require what the reference does not do.
    const auto judge = [&](const std::string& name, const std::string& m, const SlopeRun& r, const SlopeRun& ref,
                           const std::string& ref_name) {
      double mean = 0, ref_mean = 0;
      std::size_t asleep = 0, ref_asleep = 0;
      const std::size_t n = r.slid.size();
      const std::string figure = slope_summary(r, mean, asleep);
      slope_summary(ref, ref_mean, ref_asleep);
      const bool close = std::fabs(mean - ref_mean) <= 0.2 * std::fabs(ref_mean);
      add(name, m, std::fabs(double(asleep) - double(ref_asleep)) <= 0.1 * double(n) && close, figure,
          printf_string("rests and moves on as the reference: share asleep 10 s after landing within 0.1 and mean "
                        "distance slid within 20%% of the reference's (%s: %zu/%zu asleep, %.1f cm)",
                        ref_name.c_str(), ref_asleep, n, 100 * ref_mean));
    };

    // 3D
    const Eigen::Vector3d normal(0, std::sin(a), std::cos(a)), downhill(0, std::cos(a), -std::sin(a));
    Setup3 setup;
    setup.planes = {{normal, 0.0}};
    std::vector<scenes::BodyState3> states;
    scenes::SceneRng rng(41);
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j) {
        scenes::BodyState3 s;
        const double x = (i - (side - 1) / 2.0) * 5 * R(), along = (j - (side - 1) / 2.0) * 5 * R();
        s.position = Eigen::Vector3d(x, 0, 0) + downhill * along + Eigen::Vector3d(0, 0, 0.5 + R());
        s.orientation = random_q(rng);
        states.push_back(s);
      }
    const auto run3 = [&](const std::string& method, int substeps) {
      auto sim = sim3(method, setup, states, frame / substeps);
      return run_slope(
          states.size(), frame, after, R(),
          [&]() {
            for (int k = 0; k < substeps; ++k) sim->step();
          },
          [&](std::size_t i) { return sim->body_state(i).position; },
          [&](std::size_t i) { return sim->body_asleep(i); },
          [&](const Eigen::Vector3d& x) { return x.dot(normal); },
          [&](const Eigen::Vector3d& x) { return x.dot(downhill); });
    };
    const std::string name = printf_string("slope %.0f deg, %zu bunnies, friction 0.5", degrees, states.size());
    const std::vector<std::string> methods = methods3();
    if (!methods.empty()) {
      const SlopeRun ref = run3("full", kSlopeReferenceSubsteps);
      const std::string ref_name = "Bullet full mesh at 1/960 s";
      double mean;
      std::size_t asleep;
      add(name, "full 1/960 s", true, slope_summary(ref, mean, asleep), "the reference of this scene's cells");
      for (const std::string& m : methods) judge(name, m, run3(m, 1), ref, ref_name);
    }

    // 2D
    if (!want("polygon") && !want("statistical2d")) continue;
    const Eigen::Vector2d normal2(std::sin(a), std::cos(a)), downhill2(std::cos(a), -std::sin(a));
    const double r2 = 0.70710678118654752;
    std::vector<scenes::BodyState2> states2;
    for (int i = 0; i < 20; ++i) {
      scenes::BodyState2 s;
      s.position = downhill2 * (3.0 * (i - 9.5)) + Eigen::Vector2d(0, 0.5 + r2);
      s.angle = rng.uniform(0, 6.283185307179586);
      states2.push_back(s);
    }
    const auto run2 = [&](const std::string& method, int substeps) {
      std::unique_ptr<Sim2> sim;
      if (method == "polygon")
        sim = std::make_unique<Box2dSim>(states2, double(tables::square2d.mass),
                                         double(tables::square2d.material.restitution),
                                         double(tables::square2d.material.friction), a);
      else
        sim = std::make_unique<StatsimSim2>(states2, contacts(), ground_hulls(), a);
      return run_slope(
          states2.size(), frame, after, r2,
          [&]() {
            for (int k = 0; k < substeps; ++k) sim->step(frame / substeps);
          },
          [&](std::size_t i) { return sim->state(i).x; }, [&](std::size_t i) { return sim->state(i).asleep; },
          [&](const Eigen::Vector2d& x) { return x.dot(normal2); },
          [&](const Eigen::Vector2d& x) { return x.dot(downhill2); });
    };
    const std::string name2 = printf_string("slope %.0f deg, 20 squares (2D), friction 0.5", degrees);
    const SlopeRun ref2 = run2("polygon", kSlopeReferenceSubsteps);
    double mean2;
    std::size_t asleep2;
    add(name2, "polygon 1/960 s", true, slope_summary(ref2, mean2, asleep2), "the reference of this scene's cells");
    for (const std::string& m : kMethods2)
      if (want(m)) judge(name2, m, run2(m, 1), ref2, "Box2D polygon at 1/960 s");
  }
}

}  // namespace statsim::tools::stress
