// Paper Figure 3 with Box2D 2.4.1 as the reference engine.
//
// One drop: a 1x1 box (b2PolygonShape::SetAsBox(0.5, 0.5)) moves straight down at a fixed speed
// |v| with angular velocity w and no gravity towards a static two-sided edge on y = 0. We want
// the height of its centre at the moment it first touches the line.
//
// The skin problem. Box2D 2.4.1 gives every polygon and edge a skin of b2_polygonRadius =
// 2 * b2_linearSlop = 0.01 m around its "core" geometry, and its edge-polygon manifold reports
// points (IsTouching) once the cores are within the sum of both radii, 0.02 m. It also only
// notices contact at step boundaries. Recording the centre height when Box2D reports touching
// would thus bias heights upwards by up to ~2 cm plus up to one step of travel, depending on the
// step phase: exactly the discretisation the paper's random start heights are meant to expose.
//
// How the bias is removed. Box2D steps the drop (broad phase, narrow phase, continuous
// collision) until it reports a touching contact between box and ground. Until then no contact
// impulse has been applied, and with no gravity and no damping Box2D's integrator moves the body
// exactly linearly: c += v dt, angle += w dt (checked on every step against the analytic motion).
// So we take Box2D's state at the start of the step *before* the report (contact is evaluated at
// step starts, so the core cannot have crossed earlier without Box2D noticing; an analytic check
// from the initial state confirms it), and find the earliest time t* at which the lowest vertex of
// the core square (Box2D's own m_vertices, no skin) reaches y = 0 under that free motion:
//   g(t) = min_i [ y_c - |v| t + (R(angle0 + w t) p_i).y ].
// The minimising vertex changes with time, so g is only piecewise smooth and can dip below zero
// briefly; conservative advancement finds the first crossing without skipping such a dip: g is
// Lipschitz with L = |v| + |w| max_i |p_i|, so no crossing can happen before t + g(t)/L. Once a
// step lands at or below zero, bisection refines the bracket to machine precision. The recorded
// height is y_c - |v| t*: the centre height when the core square first touches the core line,
// independent of the skin, the step length and where in a step the contact falls.
//
// Box2D is not perfect at high spin (around 1 rad per step): its continuous collision sometimes
// notices a fast corner one step late (covered: the search starts a step before the report) or
// not at all, when the corner dips through the line and out again between steps. The exact free
// flight from the initial state catches those, and is also used to check the refinement (they
// agree to Box2D's float32 rounding). The run's summary counts all of these cases.
//
// The drop and the refinement live in box2d_util.cpp (measure_first_contact, for any polygon
// body), shared with `statsim gather2d`'s collision-height table.
#include "ref2d/fig3.hpp"

#include "common/pi.hpp"
#include "common/atomic_file.hpp"
#include "common/parallel.hpp"
#include "common/plot.hpp"
#include "common/progress.hpp"
#include "ref2d/box2d_util.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>

namespace statsim::tools {
namespace {

constexpr double kHalfDiagonal = 0.70710678118654752440;  // sqrt(2)/2: circumradius of the square
// Start clearance above the highest possible first-contact height: Box2D's fat-AABB margin, so
// the drop begins with no pair in the broad phase and takes several free steps.
constexpr double kClearance = 0.1;

// Random numbers (mix64, uniform01), the free motion and the exact first contact of the core
// square (measure_first_contact) are shared with `statsim gather2d`: see box2d_util.hpp.

std::string fixed(double v, int decimals)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// A plain decimal without trailing zeros: 0.05, 16, 0.35.
std::string plain(double v)
{
  std::string s = fixed(v, 10);
  if (s.find('.') != std::string::npos) {
    while (!s.empty() && s.back() == '0') {
      s.pop_back();
    }
    if (!s.empty() && s.back() == '.') {
      s.pop_back();
    }
  }
  return s == "-0" ? "0" : s;
}

}  // namespace

void validate_fig3_options(const Fig3Options& o)
{
  if (o.ratios.empty()) {
    throw std::invalid_argument("fig3: need at least one ratio");
  }
  for (double r : o.ratios) {
    if (!std::isfinite(r) || r < 0.0) {
      throw std::invalid_argument("fig3: ratios |w|/|v| must be finite and >= 0, got " + plain(r));
    }
  }
  if (!o.trials_per_ratio.empty() && o.trials_per_ratio.size() != o.ratios.size()) {
    throw std::invalid_argument("fig3: trials_per_ratio needs one count per ratio");
  }
  for (std::size_t i = 0; i < o.ratios.size(); ++i) {
    const int n = o.trials_per_ratio.empty() ? o.trials : o.trials_per_ratio[i];
    if (n < 2) {
      throw std::invalid_argument("fig3: need at least 2 trials per ratio (for a standard deviation), got " +
                                  std::to_string(n));
    }
  }
  if (!std::isfinite(o.speed) || o.speed <= 0.0) {
    throw std::invalid_argument("fig3: the speed must be positive, got " + plain(o.speed) + " m/s");
  }
  if (!std::isfinite(o.dt) || o.dt <= 0.0 || o.dt > 1.0) {
    throw std::invalid_argument("fig3: the time step must be in (0, 1] s, got " + plain(o.dt));
  }
  // Box2D clamps motion per step beyond these limits, which would break the free-flight model.
  if (o.speed * o.dt >= 0.99 * static_cast<double>(b2_maxTranslation)) {
    throw std::invalid_argument("fig3: speed * dt = " + plain(o.speed * o.dt) +
                                " m per step exceeds Box2D's b2_maxTranslation (2 m); lower --speed or --dt");
  }
  const double max_ratio = *std::max_element(o.ratios.begin(), o.ratios.end());
  if (max_ratio * o.speed * o.dt >= 0.99 * static_cast<double>(b2_maxRotation)) {
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "fig3: at |w|/|v| = %s the square would turn %.3g rad per step, beyond Box2D's "
                  "b2_maxRotation (%.3g rad): with dt = %.4g s the speed can be at most %.3g m/s; lower "
                  "--dt or --speed (the heights depend only on |w|/|v|, not on |v|)",
                  plain(max_ratio).c_str(), max_ratio * o.speed * o.dt, static_cast<double>(b2_maxRotation), o.dt,
                  0.99 * static_cast<double>(b2_maxRotation) / (max_ratio * o.dt));
    throw std::invalid_argument(buf);
  }
}

std::vector<double> default_fig3_ratios()
{
  return {0.0, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5, 2.0,
          3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0, 48.0, 64.0};
}

Fig3Drop fig3_drop(const Fig3Options& options, double ratio, std::size_t ratio_index, std::size_t trial)
{
  std::mt19937_64 rng(mix64(mix64(mix64(options.seed) ^ ratio_index) ^ trial));
  Fig3Drop d;
  d.angle = 2.0 * kPi * uniform01(rng);
  const double sign = (rng() >> 63) != 0 ? 1.0 : -1.0;
  d.spin = sign * ratio * options.speed;
  d.height = kHalfDiagonal + kClearance + uniform01(rng) * options.speed * options.dt;
  return d;
}

Fig3Trial simulate_fig3_drop(const Fig3Drop& drop, double speed, double dt)
{
  b2PolygonShape square;
  square.SetAsBox(0.5f, 0.5f);
  try {
    return measure_first_contact({square}, drop.height, drop.angle, speed, drop.spin, dt);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string("fig3: ") + e.what());
  }
}

Fig3Result run_fig3(const Fig3Options& options)
{
  validate_fig3_options(options);
  const auto start = std::chrono::steady_clock::now();

  Fig3Result result;
  result.options = options;
  const std::size_t nr = options.ratios.size();
  std::vector<std::size_t> offset(nr + 1, 0);
  for (std::size_t i = 0; i < nr; ++i) {
    const int n = options.trials_per_ratio.empty() ? options.trials : options.trials_per_ratio[i];
    offset[i + 1] = offset[i] + static_cast<std::size_t>(n);
  }
  const std::size_t total = offset[nr];

  // Box2D 2.4.1 fills its contact-function table lazily on first use (b2Contact::Create): do that
  // here, on one thread, before the workers start. (Box2D also bumps global statistics counters
  // such as b2_gjkCalls and b2_toiCalls without synchronisation; they never feed back into the
  // simulation, so results are unaffected, but a ThreadSanitizer build will flag them.)
  simulate_fig3_drop(fig3_drop(options, options.ratios[0], 0, 0), options.speed, options.dt);

  Progress progress("fig3", total, options.progress);
  std::vector<Fig3Trial> trials = parallel_map(
      total,
      [&](std::size_t flat) {
        const std::size_t i =
            static_cast<std::size_t>(std::upper_bound(offset.begin(), offset.end(), flat) - offset.begin()) - 1;
        const Fig3Drop drop = fig3_drop(options, options.ratios[i], i, flat - offset[i]);
        Fig3Trial t = simulate_fig3_drop(drop, options.speed, options.dt);
        progress.add();
        return t;
      },
      options.threads);
  progress.finish();

  Fig3Diagnostics& d = result.diagnostics;
  const double skin = 2.0 * static_cast<double>(b2_polygonRadius);
  double gap_sum = 0.0;
  double bias_sum = 0.0;
  for (std::size_t i = 0; i < nr; ++i) {
    Fig3Row row;
    row.ratio = options.ratios[i];
    row.trials = static_cast<int>(offset[i + 1] - offset[i]);
    std::vector<double> hs;
    hs.reserve(static_cast<std::size_t>(row.trials));
    for (std::size_t k = offset[i]; k < offset[i + 1]; ++k) {
      const Fig3Trial& t = trials[k];
      hs.push_back(t.height);
      d.trials += 1;
      d.steps += static_cast<std::uint64_t>(t.steps);
      // Box2D evaluates the skin in float32: allow a hair above 0.02 m.
      if (t.report_gap > 0.0 && t.report_gap <= skin * (1.0 + 1e-4)) {
        d.skin_reports += 1;
        gap_sum += t.report_gap;
        d.max_skin_gap = std::max(d.max_skin_gap, t.report_gap);
      } else if (t.report_gap > 0.0) {
        d.in_step_reports += 1;
      }
      d.late += t.late ? 1 : 0;
      d.missed += t.missed ? 1 : 0;
      d.grazing += t.grazing ? 1 : 0;
      row.late += t.late ? 1 : 0;
      row.missed += t.missed ? 1 : 0;
      bias_sum += t.naive_height - t.height;
      d.max_float_drift = std::max(d.max_float_drift, t.float_drift);
      d.max_free_flight_error = std::max(d.max_free_flight_error, t.free_flight_error);
    }
    row.min = *std::min_element(hs.begin(), hs.end());
    row.max = *std::max_element(hs.begin(), hs.end());
    double sum = 0.0;
    for (double h : hs) {
      sum += h;
    }
    row.mean = sum / static_cast<double>(hs.size());
    double ss = 0.0;
    for (double h : hs) {
      ss += (h - row.mean) * (h - row.mean);
    }
    row.std = std::sqrt(ss / static_cast<double>(hs.size() - 1));
    result.rows.push_back(row);
    result.heights.push_back(std::move(hs));
  }
  d.mean_skin_gap = d.skin_reports > 0 ? gap_sum / static_cast<double>(d.skin_reports) : 0.0;
  d.mean_naive_bias = bias_sum / static_cast<double>(total);
  d.seconds = seconds_since(start);
  return result;
}

std::string fig3_csv(const Fig3Result& result)
{
  std::string out = "ratio,min,mean,std,max,trials\n";
  for (const Fig3Row& r : result.rows) {
    out += plain(r.ratio) + "," + fixed(r.min, 12) + "," + fixed(r.mean, 12) + "," + fixed(r.std, 12) + "," +
           fixed(r.max, 12) + "," + std::to_string(r.trials) + "\n";
  }
  return out;
}

void write_fig3_outputs(const Fig3Result& result, const std::filesystem::path& dir)
{
  const std::filesystem::path csv = dir / "fig3.csv";
  write_file_atomic(csv, fig3_csv(result));
  plot::run_script("fig3.py", {csv.string(), "--out", (dir / "fig3.png").string()});
}

std::string fig3_summary(const Fig3Result& result)
{
  const Fig3Options& o = result.options;
  const Fig3Diagnostics& d = result.diagnostics;
  const auto count = [](std::uint64_t n) { return static_cast<unsigned long long>(n); };
  std::string s;
  char buf[900];
  // (Debian's libbox2d 2.4.1 still says 2.4.0 in b2_version: print major.minor only.)
  std::snprintf(buf, sizeof buf,
                "fig3: 1x1 square (Box2D %d.%d, b2PolygonShape::SetAsBox(0.5, 0.5)) falling at |v| = %s m/s "
                "onto the edge y = 0; dt = %s s, seed %llu\n",
                b2_version.major, b2_version.minor, plain(o.speed).c_str(), plain(o.dt).c_str(),
                static_cast<unsigned long long>(o.seed));
  s += buf;
  s += "  |w|/|v|       min      mean       std       max  trials  box2d-late  box2d-missed\n";
  for (const Fig3Row& r : result.rows) {
    std::snprintf(buf, sizeof buf, "  %7s  %8.5f  %8.5f  %8.5f  %8.5f  %6d  %10d  %12d\n", plain(r.ratio).c_str(), r.min,
                  r.mean, r.std, r.max, r.trials, r.late, r.missed);
    s += buf;
  }
  std::snprintf(buf, sizeof buf,
                "Skin bias: Box2D gives the box and the edge a skin of b2_polygonRadius = %.3f m each and reports "
                "touching once the\n"
                "  cores are within %.3f m. %llu of %llu drops were reported that way, with the core square still "
                "%.4f m (mean;\n"
                "  max %.4f m) above the line; %llu more were caught inside a step by continuous collision (fast "
                "corners).\n"
                "  Recording Box2D's centre height after the reporting step would bias the heights by %+.4f m on "
                "average.\n",
                static_cast<double>(b2_polygonRadius), 2.0 * static_cast<double>(b2_polygonRadius),
                count(d.skin_reports), count(d.trials), d.mean_skin_gap, d.max_skin_gap, count(d.in_step_reports),
                d.mean_naive_bias);
  s += buf;
  s += "Removed: every height is taken at the first contact of the core square itself. From Box2D's state at the\n"
       "  start of the step before its report (free flight until then: no gravity, damping or contact impulse),\n"
       "  the earliest time the lowest core vertex reaches y = 0 under y(t) = y0 - |v| t, angle(t) = angle0 + w t\n"
       "  is found (conservative advancement, then bisection); the centre height at that time is recorded.\n";
  std::snprintf(buf, sizeof buf,
                "Checks: contact-free Box2D steps matched the analytic motion to %.1e; refined heights match the "
                "exact free flight\n"
                "  from the initial state to %.1e m (float32 state). Box2D reported %llu contacts one step late "
                "(covered: the search\n"
                "  starts a step before the report) and missed %llu (a fast corner dipped through the line and out "
                "between steps;\n"
                "  caught by the exact free flight from the initial state, whose height is used). %llu grazing "
                "contacts, shallower than\n"
                "  the float32 noise, appeared in only one of the two; the earlier contact is used.\n",
                d.max_free_flight_error, d.max_float_drift, count(d.late), count(d.missed), count(d.grazing));
  s += buf;
  std::snprintf(buf, sizeof buf, "%llu drops, %llu Box2D steps, %.2f s\n", count(d.trials), count(d.steps),
                d.seconds);
  s += buf;
  return s;
}

}  // namespace statsim::tools
