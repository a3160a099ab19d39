// The gathering of `statsim gather2d` (see gather2d.hpp): runs the stages in order on the
// options' worker threads: h_coll drops, response trials and their statistics, rest drops and
// their poses, the body-body data.
#include "ref2d/gather2d.hpp"

#include "common/parallel.hpp"
#include "common/pi.hpp"
#include "common/progress.hpp"
#include "common/sample_stats.hpp"
#include "ref2d/gather2d_body_contacts.hpp"
#include "ref2d/gather2d_trials.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

namespace statsim::tools {
namespace {

// fn(i) for every trial i < n on the options' worker threads, in order of i, with a progress
// line `label`.
template <class Fn>
auto run_trials(const char* label, std::size_t n, const Gather2dOptions& o, Fn&& fn)
{
  Progress progress(label, n, o.progress);
  auto trials = parallel_map(
      n,
      [&](std::size_t i) {
        auto t = fn(i);
        progress.add();
        return t;
      },
      o.threads);
  progress.finish();
  return trials;
}

void rest_experiment(const Gather2dContext& ctx, Gather2dResult& r)
{
  const Gather2dOptions& o = r.options;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n = static_cast<std::size_t>(o.rest_drops);
  const std::vector<RestTrial2d> trials = run_trials("gather2d rest poses", n, o, [&](std::size_t i) {
    std::mt19937_64 rng = trial_rng(o.seed, kRestPoses, 0, i);
    return simulate_rest(ctx, o, rng);
  });
  r.rest_drops = static_cast<int>(n);
  r.rest_ups.clear();
  r.rest_settled.clear();
  r.rest_time_limited = 0;
  for (const RestTrial2d& t : trials) {
    r.rest_ups.push_back(t.up);
    r.rest_settled.push_back(t.settled);
    r.rest_time_limited += t.settled ? 0 : 1;
  }
  RestPoses2d poses = cluster_rest_poses(r.shape, r.rest_ups, r.rest_settled, o);
  r.clusters = std::move(poses.clusters);
  r.rest_dropped = poses.dropped;
  r.seconds_rest = seconds_since(start);
}

// A result with what every run records (the options, the shape, L and the restitution threshold),
// and Box2D ready for worker threads.
Gather2dResult start_result(const Gather2dOptions& options, const Gather2dContext& ctx)
{
  Gather2dResult r;
  r.options = options;
  r.shape = ctx.shape;
  r.length = ctx.length;
  r.restitution_threshold = ctx.threshold;
  warm_up_box2d(ctx);
  return r;
}

}  // namespace

Gather2dResult run_rest_poses(const Gather2dOptions& options)
{
  validate_gather2d_options(options);
  const Gather2dContext ctx = make_context(options);
  Gather2dResult r = start_result(options, ctx);
  rest_experiment(ctx, r);
  return r;
}

Gather2dResult run_gather2d(const Gather2dOptions& options)
{
  validate_gather2d_options(options);
  const Gather2dOptions& o = options;
  const Gather2dContext ctx = make_context(o);
  Gather2dResult r = start_result(o, ctx);

  // 1. Height table.
  {
    const auto start = std::chrono::steady_clock::now();
    const double max_spin = o.height_ratios.back() * o.height_speed / ctx.length;
    r.height_dt = step_for_spin(1.0 / 60.0, max_spin);
    const std::size_t nr = o.height_ratios.size();
    const std::size_t per = static_cast<std::size_t>(o.height_trials);
    const std::vector<FirstContact> trials = run_trials("gather2d heights", nr * per, o, [&](std::size_t flat) {
      const std::size_t i = flat / per, k = flat % per;
      std::mt19937_64 rng = trial_rng(o.seed, kHeightTable, i, k);
      const double angle = 2.0 * kPi * uniform01(rng);
      const double sign = (rng() >> 63) != 0 ? 1.0 : -1.0;
      const double spin = sign * o.height_ratios[i] * o.height_speed / ctx.length;
      // Start clear of the skin and the fat-AABB margin, at a random phase of one step.
      const double height = ctx.shape.bounding_radius + 0.1 + uniform01(rng) * o.height_speed * r.height_dt;
      return measure_first_contact(ctx.pieces, height, angle, o.height_speed, spin, r.height_dt);
    });
    for (std::size_t i = 0; i < nr; ++i) {
      HeightRow row;
      row.ratio = o.height_ratios[i];
      std::vector<double> hs;
      for (std::size_t k = 0; k < per; ++k) {
        const FirstContact& t = trials[i * per + k];
        hs.push_back(t.height);
        row.late += t.late ? 1 : 0;
        row.missed += t.missed ? 1 : 0;
      }
      const MeanStd s = mean_std(hs);
      row.mean = s.mean;
      row.std = s.std;
      row.min = *std::min_element(hs.begin(), hs.end());
      row.max = *std::max_element(hs.begin(), hs.end());
      row.trials = static_cast<int>(per);
      r.heights.push_back(row);
    }
    r.seconds_heights = seconds_since(start);
  }

  // 2. Response tables.
  {
    const auto start = std::chrono::steady_clock::now();
    double max_abs_spin = 0.0;
    for (double s : o.signed_spins) {
      max_abs_spin = std::max(max_abs_spin, std::fabs(s));
    }
    r.response_dt = step_for_spin(o.response_dt, max_abs_spin * o.speeds.back() / ctx.length);
    const std::size_t a0 = o.cos_thetas.size(), a1 = o.signed_spins.size(), a2 = o.speeds.size();
    const std::size_t cells = a0 * a1 * a2;
    const std::size_t per = static_cast<std::size_t>(o.trials);
    const std::vector<ResponseTrial2d> trials = run_trials("gather2d responses", cells * per, o, [&](std::size_t flat) {
      const std::size_t cell = flat / per, k = flat % per;
      const std::size_t i = cell / (a1 * a2), j = (cell / a2) % a1, l = cell % a2;
      std::mt19937_64 rng = trial_rng(o.seed, kResponseTable, cell, k);
      return simulate_response(ctx, o.cos_thetas[i], o.signed_spins[j], o.speeds[l], r.response_dt,
                               o.response_time_limit, rng);
    });
    for (std::size_t cell = 0; cell < cells; ++cell) {
      ResponseCell c;
      c.cos_theta = o.cos_thetas[cell / (a1 * a2)];
      c.spin = o.signed_spins[(cell / a2) % a1];
      c.speed = o.speeds[cell % a2];
      c.trials = static_cast<int>(per);
      double steps = 0.0;
      for (int comp = 0; comp < 3; ++comp) {
        std::vector<double> xs;
        for (std::size_t k = 0; k < per; ++k) {
          xs.push_back(trials[cell * per + k].out[comp]);
        }
        const MeanStd s = mean_std(xs);
        c.mean[static_cast<std::size_t>(comp)] = s.mean;
        c.std[static_cast<std::size_t>(comp)] = s.std;
      }
      for (std::size_t k = 0; k < per; ++k) {
        c.time_limited += trials[cell * per + k].time_limited;
        steps += trials[cell * per + k].steps;
      }
      c.mean_steps = steps / static_cast<double>(per);
      r.response_trials += c.trials;
      r.response_time_limited += c.time_limited;
      r.cells.push_back(c);
    }
    r.seconds_responses = seconds_since(start);
  }

  // 3. Rest poses.
  rest_experiment(ctx, r);

  // 4. Body-body data.
  if (o.body_contacts) body_contacts_experiment(ctx, r);
  return r;
}

}  // namespace statsim::tools
