// The gathering of `statsim gather` (see gather.hpp): runs the stages in order, each on the
// options' worker threads: h_coll flights, response trials and their fit, rest drops and their
// poses, the body-body data, the spin measure, the landing data and the settling data.
#include "ref3d/gather.hpp"

#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "common/sample_stats.hpp"
#include "ref3d/gather_body_contacts.hpp"
#include "ref3d/reference_pool.hpp"
#include "ref3d/sampling.hpp"
#include "ref3d/signature_json.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace statsim::tools::ref3d {

GatherResult gather(const GatherOptions& options)
{
  validate_gather_options(options);
  GatherResult r;
  r.options = options;
  GatherOptions& o = r.options;
  r.model = build_model(o);
  if (o.name.empty()) o.name = r.model.name;
  if (!cpp_identifier(o.name)) throw std::runtime_error("table name '" + o.name + "' is not a C++ identifier (use --name)");
  if (o.with_speed && o.speeds.empty()) o.speeds = default_paper_speeds();
  const ShapeModel& m = r.model;
  const unsigned threads = o.threads;

  // 1. h_coll.
  {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t nr = o.height_ratios.size(), n = static_cast<std::size_t>(o.height_trials);
    Progress progress("h_coll", nr * n, o.progress);
    std::vector<double> h(nr * n);
    const std::size_t chunk = 50;
    const std::size_t tasks = (nr * n + chunk - 1) / chunk;
    parallel_for(
        tasks,
        [&](std::size_t task) {
          const std::size_t end = std::min(nr * n, (task + 1) * chunk);
          for (std::size_t k = task * chunk; k < end; ++k) h[k] = height_trial(m, o.height_ratios[k / n], o.seed, k);
          progress.add(end - task * chunk);
        },
        threads);
    progress.finish();
    for (std::size_t i = 0; i < nr; ++i) {
      const MeanStd s = mean_std(n, [&](std::size_t k) { return h[i * n + k]; });
      r.height_mean.push_back(s.mean);
      r.height_std.push_back(s.std);
    }
    r.height_flights = static_cast<long long>(nr * n);
    r.height_seconds = seconds_since(t0);
  }

  ReferencePool pool(m, o.reference);
  {
    Reference probe(m, o.reference);
    r.ground = probe.ground() == Ground::box ? "box" : "plane";
  }

  // 2. Responses (the trials are kept for the spin measure).
  const std::vector<double> fixed_speed{o.speed};
  const std::vector<double>& speeds = o.with_speed ? o.speeds : fixed_speed;
  const std::size_t nt = o.cos_theta.size(), np = o.cos_phi.size(), nv = speeds.size(), ns = o.spin_ratios.size();
  const std::size_t cells = nt * np * nv * ns, trials = static_cast<std::size_t>(o.trials);
  // Every cell's trials, at spin ratios by length or by energy (trial_spin).
  const auto response_trials = [&](bool by_energy, const char* stage) {
    std::vector<ResponseTrial> all(cells * trials);
    Progress progress(stage, cells * trials, o.progress);
    parallel_for(
        cells,
        [&](std::size_t cell) {
          const std::size_t is = cell % ns, iv = (cell / ns) % nv, ip = (cell / (ns * nv)) % np,
                            it = cell / (ns * nv * np);
          pool.with([&](const Reference& ref) {
            for (std::size_t t = 0; t < trials; ++t)
              all[cell * trials + t] = response_trial(ref, o, o.cos_theta[it], o.cos_phi[ip], speeds[iv],
                                                      o.spin_ratios[is], kResponseStream, cell * trials + t, by_energy);
            return 0;
          });
          progress.add(trials);
        },
        threads);
    progress.finish();
    return all;
  };
  std::vector<ResponseTrial> all;
  {
    const auto t0 = std::chrono::steady_clock::now();
    r.axes = {o.cos_theta, o.cos_phi};
    if (o.with_speed) r.axes.push_back(o.speeds);
    r.axes.push_back(o.spin_ratios);
    all = response_trials(o.response_spin == SpinOption::energy, "responses");
    static_cast<ResponseFit&>(r) = fit_responses(all, trials, nt, np, nv, o.spin_ratios);
    r.response_seconds = seconds_since(t0);
  }

  // 3. Rest poses (the drops are kept for the settling data).
  std::vector<DropTrial> drops(static_cast<std::size_t>(o.rest_drops));
  {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t n = drops.size();
    Progress progress("rest drops", n, o.progress);
    parallel_for(
        n,
        [&](std::size_t i) {
          drops[i] = pool.with([&](const Reference& ref) { return drop_trial(ref, o, i); });
          progress.add(1);
        },
        threads);
    progress.finish();
    static_cast<RestPoseFit&>(r) = fit_rest_poses(m, drops, o);
    r.rest_seconds = seconds_since(t0);
  }

  // 4. Body-body data.
  if (o.body_contacts) gather_body_contacts(r);

  // 5. The spin measure (gather_spin.hpp), before the landing data, whose draws read it. Where
  // auto finds gyration better, the table is by energy: its cells' trials again, at spin ratios
  // by energy, as the runtime will look them up (the same seeds: only the spins' lengths differ).
  choose_spin(r, all);
  const bool auto_energy = o.response_spin == SpinOption::automatic && r.spin == ResponseSpin::gyration;
  if (auto_energy || o.response_spin == SpinOption::energy) {
    const auto t0 = std::chrono::steady_clock::now();
    if (auto_energy) all = response_trials(true, "responses by energy");
    static_cast<ResponseFit&>(r) = fit_responses(gyration_values(all), trials, nt, np, nv, o.spin_ratios);
    r.spin = ResponseSpin::energy;
    r.response_seconds += seconds_since(t0);
  }

  // 6. Landing data, against the tables as the runtime reads them (the JSON's, at the stored
  // precision; it has no landing data yet).
  if (o.landing && o.body_contacts) {  // a table holds landing data after its body-body data
    const LoadedSignature3 tables = parse_signature_json(json_text(r, "landing stage"), "the gathered tables");
    r.landing = gather_landing(o, pool, tables.view());
  }

  // 7. Settling data, from the rest drops of 3. (a table holds it after its landing data).
  if (o.settle && o.landing && o.body_contacts) r.settle = fit_settle(drops, r.rest, o);
  return r;
}

}  // namespace statsim::tools::ref3d
