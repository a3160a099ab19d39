// `statsim fidelity --convergence`: see convergence.hpp.
#include "fidelity/convergence.hpp"

#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "common/sample_stats.hpp"
#include "fidelity/stages.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace statsim::tools::fidelity {
namespace {

using json = nlohmann::ordered_json;

// The two-sided 90% quantile of the standard normal distribution.
constexpr double kZ90 = 1.6448536269514722;

std::string num(double x, const char* f = "%.4g")
{
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

// A step as "1/N s" when it is a whole rate, else in seconds.
std::string step_text(double dt)
{
  const double rate = 1.0 / dt;
  if (std::fabs(rate - std::round(rate)) < 1e-6 * rate) return "1/" + num(std::round(rate), "%.0f") + " s";
  return num(dt, "%.6g") + " s";
}

MeanStd level_stats(const ConvergenceLevel& level, std::size_t m)
{
  return mean_std(level.values.size(), [&](std::size_t i) { return level.values[i][m]; });
}

double level_sd(const ConvergenceLevel& level, std::size_t m)
{
  return level_stats(level, m).std;
}

std::string level_label(const ConvergenceLevel& l)
{
  return step_text(l.dt) + ", " + std::to_string(l.iterations) + " iterations";
}

// The pile figures of one drop pile.
std::vector<double> pile_values(const PileRun& p, std::uint32_t poses)
{
  double r = 0, z = 0, in_pose = 0;
  for (double x : p.radius) r += x;
  for (double x : p.height) z += x;
  for (int c : p.config) in_pose += c >= 0 && static_cast<std::uint32_t>(c) < poses ? 1 : 0;
  const double n = std::max<double>(1, static_cast<double>(p.radius.size()));
  return {r / n, z / n, in_pose / n};
}

}  // namespace

double level_mean(const ConvergenceLevel& level, std::size_t m)
{
  return level_stats(level, m).mean;
}

double convergence_resolution(const SceneMetric& metric)
{
  const std::string& n = metric.name;
  if (goal_tolerance(metric) > 0) return goal_tolerance(metric) / 10;
  if (n == "mean_radius" || n == "mean_height") return 0.01;
  if (n == "overlap") return 0.1;
  if (n == "in_rest_pose") return 0.01;
  return 0.0;
}

namespace {

ConvergenceChange change_between(const ConvergenceLevel& a, const ConvergenceLevel& b, const SceneMetric& metric,
                                 std::size_t m)
{
  ConvergenceChange c;
  c.change = level_mean(b, m) - level_mean(a, m);
  const double sa = level_sd(a, m), sb = level_sd(b, m);
  c.floor = kZ90 * std::sqrt(sa * sa / static_cast<double>(std::max<std::size_t>(1, a.values.size())) +
                             sb * sb / static_cast<double>(std::max<std::size_t>(1, b.values.size())));
  // "height" etc. are relative figures, measured against the mean of reference A.
  const double resolution = convergence_resolution(metric) * (metric.relative ? std::fabs(level_mean(a, m)) : 1.0);
  c.floor = std::max(c.floor, resolution);
  return c;
}

bool within(const std::vector<ConvergenceChange>& row)
{
  for (const ConvergenceChange& c : row)
    if (!(std::fabs(c.change) <= c.floor)) return false;
  return true;
}

}  // namespace

void compare_levels(ConvergenceScene& scene)
{
  scene.changes.clear();
  scene.to_finest.clear();
  scene.converged = -1;
  const std::size_t levels = scene.levels.size();
  auto row = [&](std::size_t a, std::size_t b) {
    std::vector<ConvergenceChange> r;
    for (std::size_t m = 0; m < scene.metrics.size(); ++m)
      r.push_back(change_between(scene.levels[a], scene.levels[b], scene.metrics[m], m));
    return r;
  };
  for (std::size_t k = 0; k + 1 < levels; ++k) {
    scene.changes.push_back(row(k, k + 1));
    scene.to_finest.push_back(row(k, levels - 1));
  }
  // From the finest refinement back: level k holds when every finer level is within its floors.
  for (std::size_t k = levels - 1; k-- > 0;) {
    bool all = true;
    for (std::size_t j = k + 1; j < levels && all; ++j) all = within(row(k, j));
    if (!all) break;
    scene.converged = static_cast<int>(k);
  }
}

std::vector<SceneMetric> pile_convergence_metrics()
{
  // The means are relative figures: their resolution is a share of the mean.
  return {{"mean_radius", "m", true}, {"mean_height", "m", true}, {"in_rest_pose", "", false}};
}

ConvergenceResult run_convergence(const FidelityOptions& options)
{
  validate(options);
  if (options.convergence.empty()) throw std::invalid_argument("run_convergence needs --convergence step or iterations");
  const auto t_start = std::chrono::steady_clock::now();
  FidelityOptions o = options;
  // Only the reference runs: the methods' set-up is not needed beyond the shape and its poses.
  if (o.methods.empty()) o.methods = {"full"};
  const std::unique_ptr<Setup> setup = std::make_unique<Setup>(make_setup(o));

  ConvergenceResult res;
  res.options = options;
  res.shape = shape_label(options);
  for (const std::string& line : bench::bullet_settings(setup->body))
    res.settings.push_back("reference (statsim bench's settings): " + line);

  const int levels = options.refinements + 1;
  auto level_dt = [&](const std::string& kind, int k) {
    const double dt = pile_reference_step(options, kind);
    return options.convergence == "step" ? dt / std::ldexp(1.0, k) : dt;
  };
  auto level_iterations = [&](int k) {
    return options.convergence == "iterations" ? options.pile_reference_iterations << k
                                               : options.pile_reference_iterations;
  };

  std::vector<std::string> kinds = scene_kinds(options.scenes);
  if (options.drops && options.piles) kinds.push_back("piles");
  for (const std::string& kind : kinds) {
    ConvergenceScene sc;
    sc.kind = kind;
    if (kind == "piles") {
      sc.metrics = pile_convergence_metrics();
      sc.description = "piles: " + std::to_string(options.pile_count) +
                       " bodies dropped at once (drop_scene3, the benchmark's scene), run until all rest or " +
                       num(options.time_limit, "%.3g") + " s";
    } else {
      sc.metrics = scene_metrics(kind);
      sc.description = scene_description(*setup, options, kind);
    }
    for (int k = 0; k < levels; ++k) {
      ConvergenceLevel l;
      l.dt = level_dt(kind, k);
      l.iterations = level_iterations(k);
      sc.levels.push_back(l);
    }
    res.scenes.push_back(std::move(sc));
  }

  // Jobs (scene, level, seed), the finest levels first so that the longest runs start first.
  struct Job {
    std::size_t scene;
    int level;
    std::uint64_t seed;
  };
  std::vector<Job> jobs;
  for (int k = levels - 1; k >= 0; --k)
    for (std::size_t s = 0; s < res.scenes.size(); ++s) {
      const int seeds = res.scenes[s].kind == "piles" ? options.pile_seeds : options.scene_seeds;
      for (int i = 1; i <= seeds; ++i) jobs.push_back({s, k, static_cast<std::uint64_t>(i)});
    }
  struct Outcome {
    std::vector<double> values;
    bool time_limited = false;
    bool all_asleep = false;
    double cpu_ms = 0;
  };
  Progress progress("fidelity: convergence", jobs.size(), options.progress);
  const std::vector<Outcome> out = parallel_map(
      jobs.size(),
      [&](std::size_t j) {
        const Job& job = jobs[j];
        const ConvergenceLevel& level = res.scenes[job.scene].levels[static_cast<std::size_t>(job.level)];
        const MethodSpec ref = pile_reference_method(level.iterations);
        Outcome r;
        const double t0 = bench::thread_cpu_ms();
        if (res.scenes[job.scene].kind == "piles") {
          const PileRun p = run_pile(*setup, ref, job.seed, options.pile_count, level.dt, options.time_limit,
                                     mix(options.seed, job.seed));
          r.values = pile_values(p, setup->poses.rest.count);
          r.time_limited = p.time_limited;
          r.all_asleep = !p.time_limited;
        } else {
          const SceneRun s = run_scene_seed(*setup, ref, options, res.scenes[job.scene].kind, job.seed, level.dt);
          r.values = s.values;
          r.time_limited = s.time_limited;
          r.all_asleep = s.all_asleep;
        }
        r.cpu_ms = bench::thread_cpu_ms() - t0;
        progress.add();
        return r;
      },
      resolve_thread_count(options.threads));
  // The jobs of one scene and level are in seed order.
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    ConvergenceLevel& l = res.scenes[jobs[j].scene].levels[static_cast<std::size_t>(jobs[j].level)];
    l.values.push_back(out[j].values);
    l.time_limited += out[j].time_limited;
    l.all_asleep += out[j].all_asleep;
    l.cpu_seconds += out[j].cpu_ms / 1e3;
  }
  for (ConvergenceScene& sc : res.scenes) compare_levels(sc);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

std::string convergence_table(const ConvergenceResult& r)
{
  std::ostringstream t;
  const FidelityOptions& o = r.options;
  t << "Convergence of the piles' reference (Bullet full, statsim bench's settings) for " << r.shape << ": the "
    << (o.convergence == "step" ? "step halved" : "solver iterations doubled") << " from level to level; each figure's mean "
    << "+- its standard deviation over the seeds, then its change to the next level and to the finest and, in brackets, "
       "the noise floor (1.645 standard errors of the difference of the two means, at least the figure's resolution); "
       "'yes' where no figure moves past its floor.\n";
  for (const ConvergenceScene& sc : r.scenes) {
    const std::size_t n = sc.levels.empty() ? 0 : sc.levels.front().values.size();
    t << "\n" << sc.kind << " (" << n << " seeds): " << sc.description << "\n\n| level |";
    for (const SceneMetric& m : sc.metrics) t << " " << m.name << (m.unit.empty() ? "" : " (" + m.unit + ")") << " |";
    t << " within floors | time-limited | all asleep | CPU s per run |\n|---|";
    for (std::size_t m = 0; m < sc.metrics.size(); ++m) t << "---|";
    t << "---|---|---|---|\n";
    for (std::size_t k = 0; k < sc.levels.size(); ++k) {
      const ConvergenceLevel& l = sc.levels[k];
      t << "| " << level_label(l) << " |";
      for (std::size_t m = 0; m < sc.metrics.size(); ++m) t << " " << num(level_mean(l, m)) << " +- " << num(level_sd(l, m)) << " |";
      t << " |";
      t << " " << l.time_limited << " of " << l.values.size() << " | " << l.all_asleep << " of " << l.values.size() << " | "
        << num(l.values.empty() ? 0.0 : l.cpu_seconds / static_cast<double>(l.values.size()), "%.3g") << " |\n";
      if (k >= sc.changes.size()) continue;
      auto change_row = [&](const char* label, const std::vector<ConvergenceChange>& changes) {
        t << "| " << label << " |";
        for (const ConvergenceChange& c : changes) t << " " << num(c.change, "%+.4g") << " (" << num(c.floor) << ") |";
        t << " " << (within(changes) ? "yes" : "no") << " | | | |\n";
      };
      change_row("change to the next level (floor)", sc.changes[k]);
      if (k + 2 < sc.levels.size()) change_row("change to the finest level (floor)", sc.to_finest[k]);
    }
    t << "\n";
    if (sc.converged >= 0)
      t << sc.kind << ": converged at " << level_label(sc.levels[static_cast<std::size_t>(sc.converged)])
        << " (no finer level moves a figure past its floor)\n";
    else
      t << sc.kind << ": not converged within these levels (the finest level moves a figure of the one before past "
                      "its floor)\n";
  }
  t << "\nwall time " << num(r.seconds, "%.1f") << " s\n";
  return t.str();
}

std::string convergence_json(const ConvergenceResult& r)
{
  json j;
  j["command"] = r.command;
  j["shape"] = r.shape;
  j["convergence"] = r.options.convergence;
  j["floor_definition"] =
      "max(1.645 sqrt(s_a^2/n_a + s_b^2/n_b), resolution), s_a the standard deviation over the n_a seeds at level a";
  {
    json res = json::object();
    for (const ConvergenceScene& sc : r.scenes)
      for (const SceneMetric& m : sc.metrics) res[m.name] = convergence_resolution(m);
    j["resolution"] = res;
  }
  j["settings"] = r.settings;
  j["seconds"] = r.seconds;
  json scenes = json::array();
  for (const ConvergenceScene& sc : r.scenes) {
    json s;
    s["kind"] = sc.kind;
    s["description"] = sc.description;
    json metrics = json::array();
    for (const SceneMetric& m : sc.metrics) metrics.push_back({{"name", m.name}, {"unit", m.unit}});
    s["metrics"] = metrics;
    json levels = json::array();
    for (std::size_t k = 0; k < sc.levels.size(); ++k) {
      const ConvergenceLevel& l = sc.levels[k];
      json lj;
      lj["dt"] = l.dt;
      lj["iterations"] = l.iterations;
      lj["values"] = l.values;
      std::vector<double> means, sds;
      for (std::size_t m = 0; m < sc.metrics.size(); ++m) {
        const MeanStd st = level_stats(l, m);
        means.push_back(st.mean);
        sds.push_back(st.std);
      }
      lj["means"] = means;
      lj["sds"] = sds;
      lj["time_limited"] = l.time_limited;
      lj["all_asleep"] = l.all_asleep;
      lj["cpu_seconds"] = l.cpu_seconds;
      auto put_changes = [&](const char* change_key, const char* floor_key, const std::vector<ConvergenceChange>& row) {
        std::vector<double> change, floor;
        for (const ConvergenceChange& c : row) {
          change.push_back(c.change);
          floor.push_back(c.floor);
        }
        lj[change_key] = change;
        lj[floor_key] = floor;
      };
      if (k < sc.changes.size()) {
        put_changes("change_to_next", "floor", sc.changes[k]);
        put_changes("change_to_finest", "floor_to_finest", sc.to_finest[k]);
      }
      levels.push_back(lj);
    }
    s["levels"] = levels;
    s["converged_level"] = sc.converged;
    scenes.push_back(s);
  }
  j["scenes"] = scenes;
  return j.dump(1) + "\n";
}

ConvergenceResult convergence_from_json(const std::string& text)
{
  try {
    const json j = json::parse(text);
    ConvergenceResult r;
    r.command = j.at("command").get<std::string>();
    r.shape = j.at("shape").get<std::string>();
    r.options.convergence = j.at("convergence").get<std::string>();
    r.settings = j.at("settings").get<std::vector<std::string>>();
    r.seconds = j.at("seconds").get<double>();
    for (const json& s : j.at("scenes")) {
      ConvergenceScene sc;
      sc.kind = s.at("kind").get<std::string>();
      sc.description = s.at("description").get<std::string>();
      const std::vector<SceneMetric> known = sc.kind == "piles" ? pile_convergence_metrics() : scene_metrics(sc.kind);
      for (const json& m : s.at("metrics")) {
        const std::string name = m.at("name").get<std::string>();
        const auto it = std::find_if(known.begin(), known.end(), [&](const SceneMetric& k) { return k.name == name; });
        if (it == known.end()) throw std::runtime_error("unknown figure '" + name + "' of " + sc.kind);
        sc.metrics.push_back(*it);
      }
      for (const json& l : s.at("levels")) {
        ConvergenceLevel level;
        level.dt = l.at("dt").get<double>();
        level.iterations = l.at("iterations").get<int>();
        level.values = l.at("values").get<std::vector<std::vector<double>>>();
        for (const std::vector<double>& v : level.values)
          if (v.size() != sc.metrics.size()) throw std::runtime_error("a seed's figures do not match the metrics of " + sc.kind);
        level.time_limited = l.at("time_limited").get<int>();
        level.all_asleep = l.at("all_asleep").get<int>();
        level.cpu_seconds = l.at("cpu_seconds").get<double>();
        sc.levels.push_back(std::move(level));
      }
      compare_levels(sc);
      r.scenes.push_back(std::move(sc));
    }
    return r;
  } catch (const json::exception& e) {
    throw std::runtime_error(std::string("not a convergence JSON: ") + e.what());
  }
}

}  // namespace statsim::tools::fidelity
