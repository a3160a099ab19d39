// Output of `statsim fidelity`: the table on stdout, the JSON, the charts, and the command.
#include "fidelity/fidelity.hpp"
#include "common/commands.hpp"
#include "bench/bench_internal.hpp"
#include "fidelity/convergence.hpp"

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "common/plot.hpp"
#include "statsim/world_def.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace statsim::tools::fidelity {
namespace {

using json = nlohmann::ordered_json;

std::string num(double x, const char* f = "%.3f")
{
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

std::string with_ci(const Distance& d)
{
  return num(d.value) + " [" + num(d.ci.lo) + ", " + num(d.ci.hi) + "]";
}

void put(json& j, const char* key, const Distance& d)
{
  j[key] = d.value;
  j[std::string(key) + "_ci"] = {d.ci.lo, d.ci.hi};
}

json distances_json(const Distances& d)
{
  json j;
  put(j, "rest_tvd", d.rest_tvd);
  put(j, "rest_height_err", d.rest_height_err);
  put(j, "travel_w1", d.travel_w1);
  put(j, "bounce_w1", d.bounce_w1);
  put(j, "rest_time_w1", d.rest_time_w1);
  put(j, "first_impact_ks", d.first_impact_ks);
  put(j, "first_impact_ks_v", d.first_impact_ks_v);
  put(j, "first_impact_ks_w", d.first_impact_ks_w);
  put(j, "summary_error", d.summary_error);
  if (d.piles) {
    json p;
    put(p, "radial_w1", d.pile_radial_w1);
    put(p, "height_w1", d.pile_height_w1);
    put(p, "rest_tvd", d.pile_rest_tvd);
    j["pile"] = p;
  }
  return j;
}

// The energy guard's clamp rate: clamped / applied sampled responses, summed over the runs.
struct ClampRate {
  std::uint64_t responses = 0, clamps = 0;
  double rate() const { return responses ? static_cast<double>(clamps) / static_cast<double>(responses) : 0.0; }
};

template <class Run>
ClampRate clamp_rate(const std::vector<Run>& runs)
{
  ClampRate c;
  for (const Run& r : runs) c.responses += r.responses, c.clamps += r.clamps;
  return c;
}

json scene_sample_json(const SceneSample& s, const std::vector<SceneMetric>& metrics)
{
  json j;
  j["dt"] = s.dt;
  json means, distances;
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    put(means, metrics[k].name.c_str(), s.means[k]);
    if (k < s.distances.size()) put(distances, metrics[k].name.c_str(), s.distances[k]);
  }
  j["means"] = means;
  if (!s.distances.empty()) j["distances"] = distances;
  put(j, "all_asleep_share", s.asleep);
  json runs = json::array();
  for (const SceneRun& r : s.runs) {
    json x;
    for (std::size_t k = 0; k < metrics.size(); ++k) x[metrics[k].name] = r.values[k];
    x["all_asleep"] = r.all_asleep;
    x["time_limited"] = r.time_limited;
    x["seconds"] = r.seconds;
    if (r.step_ms > 0) x["step_ms"] = r.step_ms;
    runs.push_back(x);
  }
  j["runs"] = runs;
  return j;
}

json scenes_json(const std::vector<SceneResult>& scenes)
{
  json out = json::object();
  for (const SceneResult& sc : scenes) {
    json j;
    j["description"] = sc.description;
    json metrics = json::array();
    for (const SceneMetric& m : sc.metrics)
      metrics.push_back({{"name", m.name}, {"unit", m.unit}, {"distance", m.relative ? "relative" : "difference"}});
    j["metrics"] = metrics;
    j["reference"] = scene_sample_json(sc.reference, sc.metrics);
    j["noise_floor"] = scene_sample_json(sc.reference_b, sc.metrics);
    json methods = json::object();
    for (const SceneSample& m : sc.methods) methods[m.name] = scene_sample_json(m, sc.metrics);
    j["methods"] = methods;
    out[sc.kind] = j;
  }
  return out;
}

// A drop's time to rest split where it would begin to settle in statsim (`DropRun::settle_onset`):
// the time before it (flights, tumbling, sliding) and the settling after it, which in the
// reference holds most of the rocking on curved backs. Over the drops that rested, as
// rest_time_w1; by rest configuration, with the drops that did not rest counted apart.
struct SettleSplit {
  double onset = 0, settle = 0;  // s, means over the drops that rested
  std::vector<std::size_t> drops, not_rested;
  std::vector<double> settle_by_config;  // s, mean over the configuration's rested drops; -1 if none
};

SettleSplit settle_split(const std::vector<DropRun>& drops, int configs)
{
  const auto n = static_cast<std::size_t>(configs);
  SettleSplit out;
  out.drops.assign(n, 0);
  out.not_rested.assign(n, 0);
  std::vector<double> onset, settle, sums(n, 0.0);
  for (const DropRun& r : drops) {
    const auto c = static_cast<std::size_t>(r.config);
    out.drops[c] += 1;
    if (r.time_limited) {
      out.not_rested[c] += 1;
      continue;
    }
    onset.push_back(r.settle_onset);
    settle.push_back(r.rest_time - r.settle_onset);
    sums[c] += r.rest_time - r.settle_onset;
  }
  out.onset = mean(onset);
  out.settle = mean(settle);
  for (std::size_t c = 0; c < n; ++c) {
    const std::size_t rested = out.drops[c] - out.not_rested[c];
    out.settle_by_config.push_back(rested ? sums[c] / static_cast<double>(rested) : -1.0);
  }
  return out;
}

json sample_json(const MethodResult& m, int configs)
{
  json j;
  j["description"] = m.description;
  j["dt"] = m.dt;
  j["runs"] = m.drops.size();
  std::size_t limited = 0, no_impact = 0, no_flight = 0;
  std::vector<double> hist(static_cast<std::size_t>(configs), 0.0);
  std::vector<double> travel, bounces, rest_time, height, flight_speed, flight_spin;
  for (const DropRun& r : m.drops) {
    limited += r.time_limited;
    no_impact += !r.impact;
    no_flight += !r.flight;
    hist[static_cast<std::size_t>(r.config)] += 1.0 / static_cast<double>(m.drops.size());
    travel.push_back(r.travel);
    bounces.push_back(r.bounces);
    if (!r.time_limited) rest_time.push_back(r.rest_time);
    height.push_back(r.rest_height);
    if (r.flight) flight_speed.push_back(r.flight_speed), flight_spin.push_back(r.flight_spin);
  }
  j["time_limited"] = limited;
  j["not_rested_share"] = m.drops.empty() ? 0.0 : static_cast<double>(limited) / static_cast<double>(m.drops.size());
  j["no_impact"] = no_impact;
  j["no_flight"] = no_flight;
  j["rest_histogram"] = hist;
  j["mean_travel"] = mean(travel);
  j["mean_bounces"] = mean(bounces);
  j["mean_rest_time"] = mean(rest_time);  // over the drops that rested
  const SettleSplit split = settle_split(m.drops, configs);
  j["mean_settle_onset"] = split.onset;
  j["mean_settle_time"] = split.settle;
  json by_config = json::array();
  for (std::size_t c = 0; c < split.drops.size(); ++c) {
    json x;
    x["drops"] = split.drops[c];
    x["not_rested"] = split.not_rested[c];
    if (split.settle_by_config[c] >= 0) x["mean_settle_time"] = split.settle_by_config[c];
    else x["mean_settle_time"] = nullptr;
    by_config.push_back(x);
  }
  j["settle_by_configuration"] = by_config;
  j["mean_rest_height_over_R"] = mean(height);
  j["mean_flight_speed"] = mean(flight_speed);
  j["mean_flight_spin"] = mean(flight_spin);
  const ClampRate drops = clamp_rate(m.drops);
  j["statistical_responses"] = drops.responses;
  j["energy_clamps"] = drops.clamps;
  if (drops.responses > 0) j["clamp_rate"] = drops.rate();
  else j["clamp_rate"] = nullptr;
  if (!m.piles.empty()) {
    std::size_t pl = 0;
    double secs = 0;
    for (const PileRun& p : m.piles) pl += p.time_limited, secs += p.seconds;
    j["pile_seeds"] = m.piles.size();
    j["pile_time_limited"] = pl;
    j["pile_mean_seconds"] = secs / static_cast<double>(m.piles.size());
    const ClampRate piles = clamp_rate(m.piles);
    j["pile_statistical_responses"] = piles.responses;
    j["pile_energy_clamps"] = piles.clamps;
    if (piles.responses > 0) j["pile_clamp_rate"] = piles.rate();
    else j["pile_clamp_rate"] = nullptr;
  }
  return j;
}

// The command with every option that changes the results (not --threads, --json, --chart, ...).
std::string command_line(const FidelityOptions& o)
{
  std::ostringstream c;
  c.precision(17);
  c << "statsim fidelity";
  if (o.mesh.empty()) c << " --shape " << o.shape;
  else c << " --mesh " << o.mesh;
  for (const auto& t : o.tables) c << " --table " << t.first << "=" << t.second;
  const std::vector<std::string> methods = o.methods.empty() ? default_methods() : o.methods;
  c << " --methods ";
  for (std::size_t i = 0; i < methods.size(); ++i) c << (i ? "," : "") << methods[i];
  c << " --runs " << o.runs << " --reference " << o.reference << " --dt " << o.dt << " --reference-dt "
    << o.reference_dt << " --time-limit "
    << o.time_limit;
  if (o.piles || !o.scenes.empty())
  {
    c << " --pile-seeds " << o.pile_seeds << " --pile-count " << o.pile_count;
    if (o.pile_reference_dt > 0) c << " --pile-reference-dt " << o.pile_reference_dt;
  }
  if (o.pile_reference_iterations != 10) c << " --pile-reference-iterations " << o.pile_reference_iterations;
  if (!o.convergence.empty()) c << " --convergence " << o.convergence << " --refinements " << o.refinements;
  if (!o.piles) c << " --no-piles";
  if (o.timing) c << " --bench-n " << o.bench_n << " --bench-steps " << o.bench_steps;
  else c << " --no-timing";
  if (!o.scenes.empty()) {
    c << " --scenes ";
    for (std::size_t i = 0; i < o.scenes.size(); ++i) c << (i ? "," : "") << o.scenes[i];
    if (!o.drops) c << " --scenes-only";
    c << " --scene-seeds " << o.scene_seeds << " --heap-count " << o.heap_count << " --bin-count " << o.bin_count
      << " --bin-cells " << o.bin_cells << " --column-height " << o.column_height << " --wall-columns "
      << o.wall_columns << " --wall-height " << o.wall_height << " --stack-time " << o.stack_time;
    if (!o.mix.empty()) c << " --mix " << o.mix;
    if (!o.scene_reference.empty()) c << " --scene-reference " << o.scene_reference;
  }
  c << " --seed " << o.seed;
  if (o.draw_seed != 0) c << " --draw-seed " << o.draw_seed;
  c << " --bootstrap " << o.bootstrap;
  return c.str();
}

// A step given as seconds ("0.001") or as a rate ("1/240").
double parse_step(const std::string& text, const char* option)
{
  const auto slash = text.find('/');
  try {
    std::size_t used = 0;
    if (slash == std::string::npos) {
      const double v = std::stod(text, &used);
      if (used == text.size()) return v;
    } else {
      const double a = std::stod(text.substr(0, slash), &used);
      if (used == slash) {
        const std::string rest = text.substr(slash + 1);
        const double b = std::stod(rest, &used);
        if (used == rest.size() && b != 0) return a / b;
      }
    }
  } catch (const std::exception&) {
  }
  throw std::invalid_argument(std::string(option) + ": expected seconds or 1/N, got '" + text + "'");
}

}  // namespace

std::string drops_csv(const FidelityResult& r)
{
  std::ostringstream out;
  out.precision(17);
  out << "sample,run,impact,flight,flight_speed,flight_spin,bounces,travel,rest_time,time_limited,settle_onset,config,"
         "rest_height,responses,clamps,impact_speed,impact_spin\n";
  const auto rows = [&out](const std::string& sample, const std::vector<DropRun>& drops) {
    for (std::size_t i = 0; i < drops.size(); ++i) {
      const DropRun& d = drops[i];
      out << sample << ',' << i << ',' << int(d.impact) << ',' << int(d.flight) << ',' << d.flight_speed << ','
          << d.flight_spin << ',' << d.bounces << ',' << d.travel << ',' << d.rest_time << ',' << int(d.time_limited)
          << ',' << d.settle_onset << ',' << d.config << ',' << d.rest_height << ',' << d.responses << ',' << d.clamps
          << ',' << d.impact_speed << ',' << d.impact_spin << '\n';
    }
  };
  rows("reference", r.reference.drops);
  rows("reference_b", r.reference_b.drops);
  for (const MethodResult& m : r.methods) rows(m.name, m.drops);
  return out.str();
}

std::string profile_csv(const FidelityResult& r, double time_limit)
{
  std::ostringstream out;
  out.precision(9);
  out << "sample,t,moving,speed,spin_speed,height_above_rest\n";
  const std::size_t bins = static_cast<std::size_t>(std::ceil(time_limit / kProfileStep - 1e-9));
  const auto rows = [&](const std::string& sample, const std::vector<DropRun>& drops) {
    for (std::size_t k = 0; k < bins; ++k) {
      double moving = 0, speed = 0, spin = 0, height = 0;
      for (const DropRun& d : drops) {
        if (k >= d.profile_speed.size()) continue;  // at rest: 0 to every mean
        moving += 1;
        speed += d.profile_speed[k];
        spin += d.profile_spin[k];
        height += double(d.profile_height[k]) - d.rest_height * r.bounding_radius;
      }
      const double n = drops.empty() ? 1.0 : static_cast<double>(drops.size());
      out << sample << ',' << static_cast<double>(k + 1) * kProfileStep << ',' << moving / n << ',' << speed / n << ','
          << spin / n << ',' << height / n << '\n';
    }
  };
  rows("reference", r.reference.drops);
  rows("reference_b", r.reference_b.drops);
  for (const MethodResult& m : r.methods) rows(m.name, m.drops);
  return out.str();
}

std::string fidelity_json(const FidelityResult& r)
{
  const int configs = static_cast<int>(r.pose_labels.size());
  json j;
  j["generator"] = "statsim fidelity";
  j["command"] = r.command;
  j["shape"] = r.shape;
  j["bounding_radius"] = r.bounding_radius;
  j["summary_error_definition"] = summary_error_definition();
  j["definitions"] = fidelity_definitions();
  j["rest_configurations"] = r.pose_labels;
  j["options"] = {{"runs", r.options.runs},
                  {"dt", r.options.dt},
                  {"reference", r.options.reference},
                  {"reference_dt", r.options.reference_dt},
                  {"time_limit", r.options.time_limit},
                  {"piles", r.options.piles},
                  {"pile_seeds", r.options.pile_seeds},
                  {"pile_count", r.options.pile_count},
                  {"pile_reference_dt", r.options.pile_reference_dt},
                  {"bench_n", r.options.bench_n},
                  {"bench_steps", r.options.bench_steps},
                  {"seed", r.options.seed},
                  {"draw_seed", r.options.draw_seed},
                  {"bootstrap", r.options.bootstrap},
                  {"drops", r.options.drops},
                  {"scenes", r.options.scenes},
                  {"scene_seeds", r.options.scene_seeds},
                  {"heap_count", r.options.heap_count},
                  {"bin_count", r.options.bin_count},
                  {"bin_cells", r.options.bin_cells},
                  {"column_height", r.options.column_height},
                  {"wall_columns", r.options.wall_columns},
                  {"wall_height", r.options.wall_height},
                  {"stack_time", r.options.stack_time},
                  {"mix", r.options.mix}};
  json ref = sample_json(r.reference, configs);
  ref["method"] = "full";
  ref["reference"] = r.options.reference;
  ref["description"] = r.reference.description;
  ref["settings"] = r.settings;
  j["reference"] = ref;
  j["reference_b"] = sample_json(r.reference_b, configs);
  json methods = json::object();
  for (const MethodResult& m : r.methods) {
    json x = distances_json(m.d);
    if (m.step_ms >= 0) x["step_ms"] = m.step_ms;
    else x["step_ms"] = nullptr;
    if (m.table_bytes >= 0) x["table_bytes"] = m.table_bytes;
    else x["table_bytes"] = nullptr;
    const ClampRate c = clamp_rate(m.drops);
    if (c.responses > 0) x["clamp_rate"] = c.rate();
    else x["clamp_rate"] = nullptr;
    x["sample"] = sample_json(m, configs);
    methods[m.name] = x;
  }
  j["methods"] = methods;
  j["noise_floor"] = distances_json(r.noise_floor);
  if (!r.scenes.empty()) {
    j["scenes_definitions"] = scenes_definitions();
    j["scenes"] = scenes_json(r.scenes);
    json summary = json::object();
    for (std::size_t m = 0; m < r.scenes.front().methods.size(); ++m) {
      const PileSummary p = pile_summary(r.scenes, m);
      summary[r.scenes.front().methods[m].name] = {{"pile_error", p.pile_error}, {"step_ms", p.step_ms}};
    }
    j["pile_summary"] = summary;
  }
  j["seconds"] = r.seconds;
  return j.dump(2) + "\n";
}

std::string scenes_table(const FidelityResult& r)
{
  std::ostringstream s;
  s << "# statsim fidelity, pile scenes: " << r.shape << " (R = " << num(r.bounding_radius, "%.4f") << " m), "
    << r.options.scene_seeds << " seeds per sample\n\nReference: Bullet full at dt "
    << (r.options.pile_reference_dt > 0 ? num(r.options.pile_reference_dt, "%.5g") + " s"
                                        : std::string("each scene's own step (below)"))
    << " with the settings of statsim bench; methods at dt "
    << num(r.options.dt, "%.5g")
    << " s. Means over the seeds and distances to reference A (relative: (mean - mean_ref) / mean_ref; else the "
       "difference in the unit), with 90% bootstrap intervals over the seeds; the noise floor is reference B "
       "(seeds N+1..2N) against A.\n";
  for (const SceneResult& sc : r.scenes) {
    s << "\n## " << sc.kind << "\n\n" << sc.description << "; reference at dt " << num(sc.reference.dt, "%.5g")
      << " s\n\n| sample |";
    for (const SceneMetric& m : sc.metrics)
      s << " " << m.name << (m.unit.empty() ? "" : " (" + m.unit + ")") << " | "
        << (m.relative ? "relative distance" : "difference") << " |";
    s << " all asleep | rested before the limit | mean s simulated | CPU ms per step |\n|---|";
    for (std::size_t k = 0; k < sc.metrics.size(); ++k) s << "---|---|";
    s << "---|---|---|---|\n";
    auto row = [&](const std::string& name, const SceneSample& x) {
      s << "| " << name << " |";
      for (std::size_t k = 0; k < sc.metrics.size(); ++k)
        s << " " << with_ci(x.means[k]) << " | " << (k < x.distances.size() ? with_ci(x.distances[k]) : "-") << " |";
      double rested = 0, secs = 0, ms = 0;
      for (const SceneRun& run : x.runs) rested += !run.time_limited, secs += run.seconds, ms += run.step_ms;
      const double n = x.runs.empty() ? 1.0 : static_cast<double>(x.runs.size());
      s << " " << num(x.asleep.value, "%.2f") << " | " << num(rested / n, "%.2f") << " | " << num(secs / n, "%.2f")
        << " | " << (ms > 0 ? num(ms / n, "%.4f") : std::string("-")) << " |\n";
    };
    row("reference A (Bullet full)", sc.reference);
    for (const SceneSample& m : sc.methods) row(m.name, m);
    row("noise floor (reference B vs A)", sc.reference_b);
  }
  if (!r.scenes.empty() && !r.scenes.front().methods.empty()) {
    s << "\n## Pile summary\n\npile_error: the mean over the heap's and the bin's figures of |distance| / goal (angle "
         "of repose 3 deg, heap height 10%, bin fill height and packing 5%); 1 = at the goals on average. "
         "CPU ms per step: thread CPU time of the heap and bin runs' steps, mean over those runs.\n\n"
         "| method | pile_error | CPU ms per step |\n|---|---|---|\n";
    for (std::size_t m = 0; m < r.scenes.front().methods.size(); ++m) {
      const PileSummary p = pile_summary(r.scenes, m);
      s << "| " << r.scenes.front().methods[m].name << " | " << num(p.pile_error, "%.3f") << " | "
        << num(p.step_ms, "%.4f") << " |\n";
    }
  }
  s << "\n" << scenes_definitions() << "\n";
  return s.str();
}

std::string fidelity_table(const FidelityResult& r)
{
  if (!r.options.drops) {
    std::ostringstream w;
    w << scenes_table(r) << "\nReference settings:\n";
    for (const std::string& line : r.settings) w << "- " << line << "\n";
    w << "\nWall time " << num(r.seconds, "%.1f") << " s.\n";
    return w.str();
  }
  std::ostringstream s;
  s << "# statsim fidelity: " << r.shape << " (R = " << num(r.bounding_radius, "%.4f") << " m), " << r.options.runs
    << " single drops per sample";
  if (r.options.piles) s << ", " << r.options.pile_seeds << " piles of " << r.options.pile_count;
  s << "\n\nReference: Bullet full at dt " << num(r.options.reference_dt, "%.5g") << " s with the settings of statsim "
    << r.options.reference;
  if (r.options.piles)
    s << " (piles: at " << num(pile_reference_step(r.options, "piles"), "%.5g")
      << " s with the settings of statsim bench)";
  s << "; methods at dt " << num(r.options.dt, "%.5g") << " s. Distances with 90% bootstrap intervals.\n\n";
  s << "| method | rest_tvd | rest_height_err | travel_w1 | bounce_w1 | rest_time_w1 | not rested | "
       "first_impact_ks (v, w) | no flight |";
  if (r.options.piles) s << " pile radial_w1 | pile height_w1 | pile rest_tvd |";
  s << " clamp rate | step_ms | table_bytes | summary_error |\n|---|---|---|---|---|---|---|---|---|";
  if (r.options.piles) s << "---|---|---|";
  s << "---|---|---|---|\n";
  auto share = [](const MethodResult& m, bool (*f)(const DropRun&)) {
    std::size_t n = 0;
    for (const DropRun& d : m.drops) n += f(d);
    return m.drops.empty() ? 0.0 : static_cast<double>(n) / static_cast<double>(m.drops.size());
  };
  auto row = [&](const std::string& name, const Distances& d, const MethodResult& m, double step_ms, long long bytes) {
    const ClampRate c = clamp_rate(m.drops);
    s << "| " << name << " | " << with_ci(d.rest_tvd) << " | " << with_ci(d.rest_height_err) << " | "
      << with_ci(d.travel_w1) << " | " << with_ci(d.bounce_w1) << " | " << with_ci(d.rest_time_w1) << " | "
      << num(share(m, [](const DropRun& x) { return x.time_limited; })) << " | " << with_ci(d.first_impact_ks)
      << " (" << num(d.first_impact_ks_v.value) << ", " << num(d.first_impact_ks_w.value) << ") | "
      << num(share(m, [](const DropRun& x) { return !x.flight; })) << " |";
    if (r.options.piles)
      s << " " << with_ci(d.pile_radial_w1) << " | " << with_ci(d.pile_height_w1) << " | "
        << with_ci(d.pile_rest_tvd) << " |";
    s << " " << (c.responses ? num(c.rate(), "%.4f") : "-") << " | " << (step_ms >= 0 ? num(step_ms, "%.4g") : "-")
      << " | " << (bytes >= 0 ? std::to_string(bytes) : "-") << " | " << with_ci(d.summary_error) << " |\n";
  };
  for (const MethodResult& m : r.methods) row(m.name, m.d, m, m.step_ms, m.table_bytes);
  row("noise floor (reference B vs A)", r.noise_floor, r.reference_b, -1, -1);
  s << "\n'not rested' and 'no flight' are the method's shares (the noise floor's row: reference B's); reference A: "
    << num(share(r.reference, [](const DropRun& x) { return x.time_limited; })) << " not rested, "
    << num(share(r.reference, [](const DropRun& x) { return !x.flight; }))
    << " no flight. 'clamp rate': sampled responses scaled down by the energy guard / those applied, over the single "
       "drops.\n\n";
  auto counts = [&](const MethodResult& m) {
    std::size_t limited = 0, no_impact = 0, no_flight = 0;
    for (const DropRun& d : m.drops) limited += d.time_limited, no_impact += !d.impact, no_flight += !d.flight;
    std::size_t pl = 0;
    for (const PileRun& p : m.piles) pl += p.time_limited;
    s << "- " << m.name << " (" << m.description << "): " << limited << " of " << m.drops.size()
      << " drops hit the time limit, " << no_impact << " without a first contact, " << no_flight
      << " without a flight after it";
    const ClampRate c = clamp_rate(m.drops);
    if (c.responses)
      s << "; energy guard: " << c.clamps << " of " << c.responses << " sampled responses clamped";
    if (!m.piles.empty()) {
      s << "; " << pl << " of " << m.piles.size() << " piles hit the time limit";
      const ClampRate p = clamp_rate(m.piles);
      if (p.responses) s << ", " << p.clamps << " of " << p.responses << " pile responses clamped";
    }
    s << "\n";
  };
  counts(r.reference);
  counts(r.reference_b);
  for (const MethodResult& m : r.methods) counts(m);
  // Where the time to rest goes: before the settle onset and after it, by rest configuration.
  s << "\nTime to rest, split where statsim's default settle speed (" << num(double(WorldDef<3>{}.settle_speed), "%g")
    << " m/s, centre or farthest point) was last reached; over the drops that rested; by configuration: mean "
       "settling time in s (drops, not rested):\n";
  auto split_line = [&](const std::string& name, const MethodResult& m) {
    const SettleSplit sp = settle_split(m.drops, static_cast<int>(r.pose_labels.size()));
    s << "- " << name << ": onset " << num(sp.onset, "%.2f") << " s, settling " << num(sp.settle, "%.2f") << " s;";
    for (std::size_t c = 0; c < sp.drops.size(); ++c) {
      s << (c ? ", " : " ") << c << ": " << (sp.settle_by_config[c] >= 0 ? num(sp.settle_by_config[c], "%.2f") : std::string("-"))
        << " (" << sp.drops[c] << ", " << sp.not_rested[c] << ")";
    }
    s << "\n";
  };
  split_line("reference A", r.reference);
  split_line("reference B", r.reference_b);
  for (const MethodResult& m : r.methods) split_line(m.name, m);
  s << "\nReference settings:\n";
  for (const std::string& line : r.settings) s << "- " << line << "\n";
  s << "\nRest configurations: ";
  for (std::size_t i = 0; i < r.pose_labels.size(); ++i) s << (i ? "; " : "") << i << " " << r.pose_labels[i];
  s << "\n\n" << summary_error_definition() << "\n";
  if (!r.scenes.empty()) s << "\n" << scenes_table(r);
  s << "\nWall time " << num(r.seconds, "%.1f") << " s.\n";
  return s.str();
}


namespace {

/// The WorldDef fields a method's +FIELD=VALUE may set, for the help text.
std::string setting_list()
{
  std::string out;
  for (const auto& [name, meaning] : bench::world_setting_names()) out += (out.empty() ? "" : ", ") + name;
  return out;
}

}  // namespace

namespace {

std::vector<std::string> chart_options(const Charts& charts)
{
  std::vector<std::string> args;
  if (!charts.chart.empty()) args.insert(args.end(), {"--chart", charts.chart});
  if (!charts.bytes_chart.empty()) args.insert(args.end(), {"--chart-bytes", charts.bytes_chart});
  if (!charts.metric_dir.empty()) args.insert(args.end(), {"--metric-charts", charts.metric_dir});
  return args;
}

}  // namespace

void write_charts(const std::filesystem::path& json_file, const Charts& charts)
{
  std::vector<std::string> args{json_file.string()};
  const std::vector<std::string> options = chart_options(charts);
  args.insert(args.end(), options.begin(), options.end());
  plot::run_script("fidelity.py", args);
}

void write_charts(const FidelityResult& r, const Charts& charts)
{
  plot::run_script_on("fidelity.py", fidelity_json(r), ".json", chart_options(charts));
}

void register_fidelity_commands(CLI::App& app)
{
  auto opts = std::make_shared<FidelityOptions>();
  auto json_path = std::make_shared<std::string>();
  auto chart_path = std::make_shared<std::string>();
  auto charts_dir = std::make_shared<std::string>();
  auto bytes_chart_path = std::make_shared<std::string>();
  auto method_list = std::make_shared<std::string>();
  auto table_args = std::make_shared<std::vector<std::string>>();
  auto no_piles = std::make_shared<bool>(false);
  auto scene_list = std::make_shared<std::string>();
  auto scenes_only = std::make_shared<bool>(false);
  auto no_timing = std::make_shared<bool>(false);
  auto quiet = std::make_shared<bool>(false);
  auto replot = std::make_shared<std::string>();
  auto dt_text = std::make_shared<std::string>("1/60");
  auto reference_dt_text = std::make_shared<std::string>("0.001");
  auto pile_dt_text = std::make_shared<std::string>("0");
  CLI::App* cmd = app.add_subcommand(
      "fidelity",
      std::string("Accuracy against speed: every method's single drops (and piles) against Bullet with the full "
                  "mesh, as distances between distributions with bootstrap intervals and a noise floor.\n\n") +
          fidelity_definitions() + "\n" + summary_error_definition() + "\n\n" + scenes_definitions());
  cmd->add_option("--shape", opts->shape, "bunny, box or lshape (a compiled table)")
      ->check(CLI::IsMember({"bunny", "box", "lshape"}));
  cmd->add_option("--mesh", opts->mesh, "OBJ of a shape without a compiled table (Bullet full: GImpact of it; needs --table; statistical, "
                  "-norest and -independent then use the first --table, whose rest poses classify every run)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--table", *table_args,
                  "NAME=FILE.json (statsim gather --json): adds method statistical:NAME; repeatable");
  cmd->add_option("--methods", *method_list,
                  "comma-separated: full, full-gather (Bullet full with the gathering's settings at --dt: the "
                  "reference's engine at the methods' step), low, hull, spheres7, sphere, statistical, "
                  "statistical-norest, statistical-independent, statistical-spheres (collision spheres between bodies, the "
                  "paper's rule; the others run the library's default, hull contacts where the table has body-body "
                  "data and sleep by islands), "
                  "statistical:NAME; a statistical method followed by +FIELD=VALUE sets WorldDef fields by name "
                  "(statistical+shock_propagation=0+support_iterations=8; fields: " + setting_list() + ") (default: "
                  "full,low,spheres7,sphere,statistical,statistical-norest,statistical-independent)");
  cmd->add_option("--runs", opts->runs, "single drops per sample")->capture_default_str();
  cmd->add_option("--dt", *dt_text, "step of the methods, s (a number or 1/N)")->capture_default_str();
  cmd->add_option("--reference-dt", *reference_dt_text, "step of the reference in single drops, s (a number or 1/N)")
      ->capture_default_str();
  cmd->add_option("--reference", opts->reference,
                  "single drops' reference settings: gather (tools/ref3d's, the tables' own) or bench (statsim "
                  "bench's); piles always use bench's")
      ->check(CLI::IsMember({"gather", "bench"}))
      ->capture_default_str();
  cmd->add_option("--time-limit", opts->time_limit, "s; a run ends at rest or here")->capture_default_str();
  cmd->add_flag("--no-piles", *no_piles, "skip the piles");
  cmd->add_option("--pile-seeds", opts->pile_seeds, "piles: scene seeds 1..N (noise floor N+1..2N)")->capture_default_str();
  cmd->add_option("--pile-count", opts->pile_count, "bodies per pile")->capture_default_str();
  cmd->add_option("--pile-reference-dt", *pile_dt_text,
                  "step of the reference in piles and scenes, s (a number or 1/N); 0: each scene's converged step "
                  "(heap 1/3840, bin 1/960, column and wall 1/480, drop piles 1/960)")
      ->capture_default_str();
  cmd->add_option("--pile-reference-iterations", opts->pile_reference_iterations,
                  "solver iterations per step of the reference in piles and scenes")
      ->capture_default_str();
  cmd->add_option("--convergence", opts->convergence,
                  "step or iterations: run only the reference of --scenes and the drop piles at --refinements + 1 "
                  "levels (the step halved, or the iterations doubled, from one to the next) and report each "
                  "figure's change beside its noise floor")
      ->check(CLI::IsMember({"step", "iterations"}));
  cmd->add_option("--refinements", opts->refinements, "--convergence: levels after the first")->capture_default_str();
  auto convergence_json_path = std::make_shared<std::string>();
  cmd->add_option("--convergence-json", *convergence_json_path,
                  "JSON of an earlier --convergence run: only print its tables again (compared anew)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--scenes", *scene_list,
                  "comma-separated pile scenes (tools/scenes/piles.hpp): heap, bin, stack (= column,wall), column, "
                  "wall; against Bullet full at --pile-reference-dt with statsim bench's settings");
  cmd->add_flag("--scenes-only", *scenes_only, "run only --scenes (no single drops, piles or step time)");
  cmd->add_option("--scene-seeds", opts->scene_seeds, "scenes: seeds 1..N per sample (noise floor N+1..2N)")
      ->capture_default_str();
  cmd->add_option("--heap-count", opts->heap_count, "bodies of the heap")->capture_default_str();
  cmd->add_option("--bin-count", opts->bin_count, "bodies of the bin")->capture_default_str();
  cmd->add_option("--bin-cells", opts->bin_cells, "lattice cells along the bin's side (side = cells x 2.1 R)")
      ->capture_default_str();
  cmd->add_option("--column-height", opts->column_height, "bodies of the column")->capture_default_str();
  cmd->add_option("--wall-columns", opts->wall_columns, "columns of the wall")->capture_default_str();
  cmd->add_option("--wall-height", opts->wall_height, "bodies per column of the wall")->capture_default_str();
  cmd->add_option("--stack-time", opts->stack_time, "s simulated before the column and the wall are measured")
      ->capture_default_str();
  cmd->add_option("--mix", opts->mix,
                  "heap and bin: half the bodies of this second shape (bunny, box, lshape), in turn with --shape's; "
                  "methods statistical and full only");
  cmd->add_option("--scene-reference", opts->scene_reference,
                  "JSON of an earlier --scenes run (--json) with the same scenes, seeds and reference step: its "
                  "reference samples stand in for running the reference again")
      ->check(CLI::ExistingFile);
  cmd->add_option("--scene-frames", opts->scene_frames,
                  "directory: the final state of seed 1 of each scene, reference A and each method, as frame files "
                  "(KIND_METHOD.csv) for statsim render");
  cmd->add_option("--bench-n", opts->bench_n, "bodies of the step-time scene")->capture_default_str();
  cmd->add_option("--bench-steps", opts->bench_steps, "steps of the step-time scene")->capture_default_str();
  cmd->add_flag("--no-timing", *no_timing, "do not measure step_ms");
  cmd->add_option("--seed", opts->seed, "seed of the single-drop streams")->capture_default_str();
  cmd->add_option("--draw-seed", opts->draw_seed,
                  "0: each statsim world of a single drop seeded by the drop's stream; else the same drops with "
                  "other draws of the tables (how far statsim's own sampling moves a figure)")
      ->capture_default_str();
  cmd->add_option("--bootstrap", opts->bootstrap, "bootstrap resamples per interval")->capture_default_str();
  cmd->add_option("--threads", opts->threads, "worker threads (0: every core); results do not depend on it")
      ->capture_default_str();
  cmd->add_option("--meshes", opts->meshes_dir, "directory of the meshes (default: the source tree's tools/meshes)");
  cmd->add_option("--json", *json_path, "write the results as JSON");
  auto drops_csv_path = std::make_shared<std::string>();
  cmd->add_option("--drops-csv", *drops_csv_path,
                  "write every single drop of every sample as a CSV row (sample, run, first flight's |v+| and |w+|, "
                  "rises, travel, time to rest, rest configuration and height, ...), the distances' raw data");
  auto profile_csv_path = std::make_shared<std::string>();
  cmd->add_option("--profile-csv", *profile_csv_path,
                  "write the single drops' mean motion against time, per sample every 0.05 s: share not yet at rest, "
                  "mean |v|, |w| R and height above the final height (a drop at rest counts 0)");
  cmd->add_option("--chart", *chart_path,
                  "FILE.png (and FILE.svg): summary error against time per step (log x), Pareto front, noise floor");
  cmd->add_option("--metric-charts", *charts_dir, "directory: one chart per distance (PNG and SVG)");
  cmd->add_option("--chart-bytes", *bytes_chart_path,
                  "FILE.png (and FILE.svg): summary error against table bytes (log x), one point per statistical table, noise floor");
  cmd->add_flag("--quiet", *quiet, "no progress on stderr");
  cmd->add_option("--replot", *replot, "JSON of an earlier run: only redraw --chart / --chart-bytes / --metric-charts from it");
  cmd->callback([=]() {
    FidelityOptions o = *opts;
    o.piles = !*no_piles;
    o.drops = !*scenes_only;
    for (const std::string& k : split_list(*scene_list))
      if (!k.empty()) o.scenes.push_back(k);
    o.timing = !*no_timing;
    o.progress = !*quiet;
    for (const std::string& m : split_list(*method_list))
      if (!m.empty()) o.methods.push_back(m);
    for (const std::string& t : *table_args) {
      const auto eq = t.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == t.size())
        throw CLI::ValidationError("--table", "expected NAME=FILE.json, got '" + t + "'");
      o.tables.emplace_back(t.substr(0, eq), t.substr(eq + 1));
    }
    try {
      const Charts charts{*chart_path, *bytes_chart_path, *charts_dir};
      const std::pair<const char*, std::shared_ptr<std::string>> csv_outputs[] = {{"--drops-csv", drops_csv_path},
                                                                                  {"--profile-csv", profile_csv_path}};
      for (const auto& [option, path] : csv_outputs)
        if (!path->empty() && (!replot->empty() || !convergence_json_path->empty()))
          throw std::invalid_argument(std::string(option) +
                                      " needs a run: --replot and --convergence-json only print or draw");
      if (!replot->empty()) {
        // Redraw the charts of an earlier run from its JSON, without running anything.
        if (!charts.any()) throw std::invalid_argument("--replot needs --chart, --chart-bytes or --metric-charts");
        write_charts(std::filesystem::path(*replot), charts);
        return;
      }
      if (!convergence_json_path->empty()) {
        std::ifstream in(*convergence_json_path);
        std::stringstream text;
        text << in.rdbuf();
        std::cout << convergence_table(convergence_from_json(text.str())) << std::flush;
        return;
      }
      o.dt = parse_step(*dt_text, "--dt");
      o.reference_dt = parse_step(*reference_dt_text, "--reference-dt");
      o.pile_reference_dt = parse_step(*pile_dt_text, "--pile-reference-dt");
      validate(o);
      // Fail on unwritable outputs before the run, not after it.
      if (!json_path->empty()) ensure_writable_directory(std::filesystem::absolute(*json_path).parent_path());
      for (const auto& [option, path] : csv_outputs) {
        if (path->empty()) continue;
        if (!o.drops) throw std::invalid_argument(std::string(option) + " needs the single drops (no --scenes-only)");
        if (!o.convergence.empty())
          throw std::invalid_argument(std::string(option) + ": --convergence runs no single drops");
        ensure_writable_directory(std::filesystem::absolute(*path).parent_path());
      }
      if (!chart_path->empty()) ensure_writable_directory(std::filesystem::absolute(*chart_path).parent_path());
      if (!charts_dir->empty()) ensure_writable_directory(*charts_dir);
      if (!o.scene_frames.empty()) ensure_writable_directory(o.scene_frames);
      if (!bytes_chart_path->empty())
        ensure_writable_directory(std::filesystem::absolute(*bytes_chart_path).parent_path());
      if (charts.any()) plot::find_python();  // a missing matplotlib too
      if (!o.convergence.empty()) {
        if (charts.any()) throw std::invalid_argument("--convergence draws no chart");
        ConvergenceResult r = run_convergence(o);
        r.command = command_line(o);
        std::cout << convergence_table(r) << std::flush;
        if (!json_path->empty()) write_file_atomic(*json_path, convergence_json(r));
        return;
      }
      FidelityResult r = run_fidelity(o);
      r.command = command_line(o);
      std::cout << fidelity_table(r) << std::flush;
      if (!json_path->empty()) write_file_atomic(*json_path, fidelity_json(r));
      if (!drops_csv_path->empty()) write_file_atomic(*drops_csv_path, drops_csv(r));
      if (!profile_csv_path->empty()) write_file_atomic(*profile_csv_path, profile_csv(r, o.time_limit));
      if (charts.any()) write_charts(r, charts);
    } catch (const std::exception& e) {
      std::cerr << "statsim fidelity: error: " << e.what() << "\n";
      throw CLI::RuntimeError(1);
    }
  });
}

}  // namespace statsim::tools::fidelity
