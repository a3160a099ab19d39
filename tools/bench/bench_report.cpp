// Reports of `statsim bench`: Markdown (Table 1 layout), CSV and the log-log chart.
#include "bench/bench.hpp"

#include "common/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace statsim::tools {
namespace {

std::string fmt(const char* format, double a)
{
  char buf[128];
  std::snprintf(buf, sizeof buf, format, a);
  return buf;
}

/// Milliseconds with 4 significant digits, never in exponent form.
std::string ms(double v)
{
  if (!(v >= 0) || !std::isfinite(v)) return "n/a";
  if (v >= 1000) return fmt("%.0f", v);
  if (v >= 100) return fmt("%.1f", v);
  if (v >= 10) return fmt("%.2f", v);
  if (v >= 1) return fmt("%.3f", v);
  if (v >= 0.1) return fmt("%.4f", v);
  if (v >= 0.01) return fmt("%.5f", v);
  return fmt("%.6f", v);
}

std::string pct(double v, double ref)
{
  if (!(v >= 0) || !(ref > 0)) return "";
  return fmt("%.2f%%", 100.0 * v / ref);
}

std::string ratio(double slow, double fast)
{
  if (!(slow > 0) || !(fast > 0)) return "n/a";
  const double r = slow / fast;
  return r >= 100 ? fmt("%.0fx", r) : r >= 10 ? fmt("%.1fx", r) : fmt("%.2fx", r);
}

const BenchCell* find(const BenchResult& r, const std::string& method, const std::string& bp, int n)
{
  for (const BenchCell& c : r.cells)
    if (c.method == method && c.n == n && (c.broadphase == bp || c.engine != "bullet")) return &c;
  return nullptr;
}

const BenchCell* measured(const BenchResult& r, const std::string& method, const std::string& bp, int n)
{
  const BenchCell* c = find(r, method, bp, n);
  return c && !c->skipped ? c : nullptr;
}

std::vector<std::string> methods_of(const BenchResult& r)
{
  std::vector<std::string> m;
  for (const BenchCell& c : r.cells)
    if (std::find(m.begin(), m.end(), c.method) == m.end()) m.push_back(c.method);
  return m;
}

std::vector<int> counts_of(const BenchResult& r)
{
  std::vector<int> n;
  for (const BenchCell& c : r.cells)
    if (std::find(n.begin(), n.end(), c.n) == n.end()) n.push_back(c.n);
  return n;
}

/// Broad phases of the report's tables: Bullet's in 3D; one pseudo-phase otherwise.
std::vector<std::string> table_phases(const BenchResult& r)
{
  if (r.options.dim == 2) return {"tree"};
  return r.options.broadphases;
}

/// How the statsim columns were run: "statistical: grid; statistical-sap: sap".
std::string statsim_phases(const BenchResult& r)
{
  std::string s;
  std::set<std::string> seen;
  for (const BenchCell& c : r.cells)
    if (c.engine == "statsim" && seen.insert(c.method).second)
      s += (s.empty() ? "" : ", ") + c.method + " with " + (c.broadphase == "sap" ? "sweep-and-prune" : c.broadphase);
  return s.empty() ? std::string("no statsim method") : "statsim: " + s;
}

std::string phase_title(const BenchResult& r, const std::string& bp)
{
  if (r.options.dim == 2) return "Box2D (dynamic AABB tree) vs statsim 2D; " + statsim_phases(r);
  if (bp == "sap") return "Bullet broad phase btAxisSweep3 (sweep-and-prune, as the paper); " + statsim_phases(r);
  return "Bullet broad phase btDbvtBroadphase (Bullet's default); " + statsim_phases(r) + " (the same runs as above)";
}

std::string reference_method(const BenchResult& r)
{
  return r.options.dim == 2 ? "polygon" : "full";
}

/// The method percentages refer to at N: `full` (polygon in 2D) if measured, else spheres7.
const BenchCell* reference_cell(const BenchResult& r, const std::string& bp, int n, std::string& name)
{
  name = reference_method(r);
  if (const BenchCell* c = measured(r, name, bp, n)) return c;
  if (r.options.dim == 3) {
    name = "spheres7";
    if (const BenchCell* c = measured(r, name, bp, n)) return c;
  }
  name.clear();
  return nullptr;
}

std::string cell_text(const BenchCell* c, double value)
{
  if (!c) return "";
  if (c->skipped) return "skipped";
  return ms(value);
}

}  // namespace

std::string bench_markdown(const BenchResult& r)
{
  const BenchOptions& o = r.options;
  std::string s;
  s += "# statsim bench: " + o.shape + " drop, " +
       (o.dim == 3 ? std::string("3D, Bullet vs statsim") : std::string("2D, Box2D vs statsim")) + "\n\n";
  s += "Command: `" + r.command + "`\n\n";
  s += "Machine: " + r.machine + "\n\n";
  s += "Times are milliseconds per step (dt = " + fmt("%.6g", o.dt) + " s): the mean over a run of " +
       std::to_string(o.steps) + " steps from the initial states, median over " + std::to_string(o.repeats) +
       " repeats (each in a fresh world, after " + std::to_string(o.warmup) +
       " warm-up steps in a discarded one; repeats interleaved across methods). *envelope*: the mean over steps of "
       "the fastest repeat at each step (the repeats are identical simulations; this filters out preemption on a "
       "loaded machine). *CPU time*: the thread's CPU time over the run per step (leaves out time spent waiting for "
       "a core; read once per repeat). *collision* = broad + narrow "
       "phase, *response* = the rest of the step; statsim does not expose phase times (n/a). *falling* = the steps "
       "before the first body of any method falls asleep at that N (the same window for every method: sleeping "
       "flatters each engine differently), *settling* = the steps after. Percentages: of `" +
       reference_method(r) + "` at the same N" + (o.dim == 3 ? " (of `spheres7` where `full` was skipped, marked +)" : "") +
       ".\n\n";

  const std::vector<std::string> methods = methods_of(r);
  const std::vector<int> counts = counts_of(r);
  for (const std::string& bp : table_phases(r)) {
    s += "## " + phase_title(r, bp) + "\n\n";
    s += "| N | type |";
    for (const auto& m : methods) s += " " + m + " (ms) | % |";
    s += "\n|---:|---|";
    for (std::size_t i = 0; i < methods.size(); ++i) s += "---:|---:|";
    s += "\n";
    for (int n : counts) {
      std::string ref_name;
      const BenchCell* ref = reference_cell(r, bp, n, ref_name);
      const bool alt = ref && ref_name == "spheres7";
      struct Row {
        const char* name;
        double BenchCell::*field;
      };
      const Row rows[] = {{"one step", &BenchCell::step_ms_median},
                          {"one step, envelope", &BenchCell::step_ms_envelope},
                          {"one step, CPU time", &BenchCell::cpu_ms},
                          {"collision", &BenchCell::collision_ms},
                          {"response", &BenchCell::response_ms},
                          {"falling", &BenchCell::fall_ms},
                          {"settling", &BenchCell::settle_ms}};
      int fall_steps = 0;
      for (const BenchCell& c : r.cells)
        if (c.n == n && !c.skipped) fall_steps = c.fall_steps;
      bool first = true;
      for (const Row& row : rows) {
        std::string name = row.name;
        if (name == "falling") name += " (steps 1-" + std::to_string(fall_steps) + ")";
        if (name == "settling") name += " (steps " + std::to_string(fall_steps + 1) + "-" + std::to_string(o.steps) + ")";
        s += "| " + (first ? std::to_string(n) : std::string()) + " | " + name + (alt ? " +" : "") + " |";
        first = false;
        for (const auto& m : methods) {
          const BenchCell* c = find(r, m, bp, n);
          const double v = c ? c->*(row.field) : -1;
          s += " " + cell_text(c, v) + " |";
          s += " " + (c && !c->skipped && ref ? pct(v, ref->*(row.field)) : std::string()) + " |";
        }
        s += "\n";
      }
    }
    s += "\n";
  }

  // Speed-ups of statistical.
  std::vector<std::pair<std::string, std::string>> others;
  for (const auto& m : methods) {
    if (m == "statistical") continue;
    for (const std::string& bp : table_phases(r))
      if (o.dim == 2 || find(r, m, bp, counts.empty() ? 0 : counts[0])) others.push_back({m, bp});
  }
  struct Metric {
    const char* title;
    double BenchCell::*field;
  };
  const Metric metrics[] = {
      {"one step, median of repeats", &BenchCell::step_ms_median},
      {"one step, envelope (fastest repeat at each step)", &BenchCell::step_ms_envelope},
      {"one step, thread CPU time, median of repeats", &BenchCell::cpu_ms},
      {"falling phase (before anything sleeps), median of repeats", &BenchCell::fall_ms},
  };
  for (const Metric& metric : metrics) {
    s += std::string("## Speed-up of statistical: ") + metric.title + " (other method's time / statistical's)\n\n| N |";
    for (const auto& [m, bp] : others) s += " " + m + (o.dim == 3 ? " (" + bp + ")" : std::string()) + " |";
    s += "\n|---:|";
    for (std::size_t i = 0; i < others.size(); ++i) s += "---:|";
    s += "\n";
    for (int n : counts) {
      s += "| " + std::to_string(n) + " |";
      const BenchCell* st = measured(r, "statistical", "sap", n);
      for (const auto& [m, bp] : others) {
        const BenchCell* c = measured(r, m, bp, n);
        if (!c || !st) {
          s += std::string(" ") + (!c && find(r, m, bp, n) ? "skipped" : "n/a") + " |";
          continue;
        }
        s += " " + ratio(c->*(metric.field), st->*(metric.field)) + " |";
      }
      s += "\n";
    }
    s += "\n";
  }

  // The performance goals.
  s += "## Goals\n\n";
  auto speedup = [&](const std::string& m, const std::string& bp, int n) -> std::optional<double> {
    const BenchCell* c = measured(r, m, bp, n);
    const BenchCell* st = measured(r, "statistical", "sap", n);
    if (!c || !st || !(st->step_ms_median > 0)) return std::nullopt;
    return c->step_ms_median / st->step_ms_median;
  };
  auto envelope = [&](const std::string& m, const std::string& bp, int n) -> std::string {
    const BenchCell* c = measured(r, m, bp, n);
    const BenchCell* st = measured(r, "statistical", "sap", n);
    if (!c || !st) return "";
    return ", envelope " + ratio(c->step_ms_envelope, st->step_ms_envelope) + ", CPU " + ratio(c->cpu_ms, st->cpu_ms);
  };
  s += "Ratios of medians (Bullet with btAxisSweep3); envelope and CPU-time ratios after them.\n\n";
  auto verdict = [](bool ok) { return ok ? std::string("met") : std::string("NOT met"); };
  if (o.dim == 3) {
    const std::string bp = "sap";
    for (int n : {100, 1000}) {
      const auto x = speedup("full", bp, n);
      s += "- statistical >= 100x faster than full at N = " + std::to_string(n) + ": " +
           (x ? ratio(*x, 1) + " (" + verdict(*x >= 100) + envelope("full", bp, n) + ")" : std::string("not measured")) +
           "\n";
    }
    for (const char* m : {"spheres7", "sphere"}) {
      const double need = std::string(m) == "spheres7" ? 3.0 : 1.0;
      s += std::string("- statistical >= ") + fmt("%g", need) + "x faster than " + m + " at every N:";
      bool all = true, any = false;
      for (int n : counts) {
        const auto x = speedup(m, bp, n);
        s += " N=" + std::to_string(n) + " " + (x ? ratio(*x, 1) : std::string("n/a"));
        const std::string e = envelope(m, bp, n);
        if (!e.empty()) s += " (" + e.substr(2) + ")";
        if (x) s += ";";
        if (x) {
          any = true;
          all = all && *x >= need;
        }
      }
      s += any ? " (" + verdict(all) + " where measured)\n" : " (not measured)\n";
    }
    const BenchCell* s10k = measured(r, "statistical", "sap", 10000);
    const BenchCell* s1k = measured(r, "statistical", "sap", 1000);
    s += "- 10,000 bodies, median step <= 5 ms: " +
         (s10k ? ms(s10k->step_ms_median) + " ms (" + verdict(s10k->step_ms_median <= 5) + "; envelope " +
                     ms(s10k->step_ms_envelope) + " ms, CPU " + ms(s10k->cpu_ms) + " ms)"
               : std::string("not measured")) +
         "\n";
    if (s10k && s1k) {
      const double growth = (s10k->step_ms_median / 10000) / (s1k->step_ms_median / 1000);
      const double growth_e = (s10k->step_ms_envelope / 10000) / (s1k->step_ms_envelope / 1000);
      const double growth_c = (s10k->cpu_ms / 10000) / (s1k->cpu_ms / 1000);
      s += "- time per body from N = 1,000 to 10,000 grows <= 1.5x: " + fmt("%.2fx", growth) + " (" +
           verdict(growth <= 1.5) + "; envelope " + fmt("%.2fx", growth_e) + ", CPU " + fmt("%.2fx", growth_c) + ")\n";
    } else {
      s += "- time per body from N = 1,000 to 10,000 grows <= 1.5x: not measured\n";
    }
    // Issue 18's goals, on thread CPU time (the wall clock of this shared machine waits for a core).
    s += "- 10,000 bodies, CPU per step <= 4 ms (bar 5 ms): " +
         (s10k ? ms(s10k->cpu_ms) + " ms (" + verdict(s10k->cpu_ms <= 4) + ")" : std::string("not measured")) + "\n";
    const BenchCell* sphere10k = measured(r, "sphere", bp, 10000);
    s += "- statistical >= 20x faster than sphere at N = 10,000 (CPU): " +
         (s10k && sphere10k && s10k->cpu_ms > 0
              ? ratio(sphere10k->cpu_ms / s10k->cpu_ms, 1) + " (" + verdict(sphere10k->cpu_ms >= 20 * s10k->cpu_ms) + ")"
              : std::string("not measured")) +
         "\n";
    const BenchCell* s100k = measured(r, "statistical", "sap", 100000);
    if (s10k && s100k && s10k->cpu_ms > 0) {
      const double growth = (s100k->cpu_ms / 100000) / (s10k->cpu_ms / 10000);
      const double growth_w = (s100k->step_ms_median / 100000) / (s10k->step_ms_median / 10000);
      s += "- time per body from N = 10,000 to 100,000 grows <= 1.3x (CPU): " + fmt("%.2fx", growth) + " (" +
           verdict(growth <= 1.3) + "; wall-clock median " + fmt("%.2fx", growth_w) + ")\n";
    } else {
      s += "- time per body from N = 10,000 to 100,000 grows <= 1.3x (CPU): not measured\n";
    }
  } else {
    const auto x = speedup("polygon", "tree", 1000);
    s += "- statsim 2D >= 5x faster than Box2D polygons at N = 1,000: " +
         (x ? ratio(*x, 1) + " (" + verdict(*x >= 5) + envelope("polygon", "tree", 1000) + ")"
            : std::string("not measured")) +
         "\n";
  }
  s += "\n";

  // Per-cell details.
  s += "## Runs\n\n| method | broad phase | N | repeats | step ms median [min, max] | envelope ms | broad ms | narrow "
       "ms | first sleep (step) | asleep at end | mean height (m) | contacts per body | note |\n";
  s += "|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (const BenchCell& c : r.cells) {
    s += "| " + c.method + " | " + c.broadphase + " | " + std::to_string(c.n) + " | ";
    if (c.skipped) {
      s += "0 | skipped | | | | | | | | " + c.note + " |\n";
      continue;
    }
    s += std::to_string(c.repeats) + " | " + ms(c.step_ms_median) + " [" + ms(c.step_ms_min) + ", " +
         ms(c.step_ms_max) + "] | " + ms(c.step_ms_envelope) + " | " + ms(c.broad_ms) + " | " + ms(c.narrow_ms) + " | " +
         (c.first_sleep_step >= 0 ? std::to_string(c.first_sleep_step) : std::string("none")) + " | " +
         fmt("%.0f%%", 100 * c.asleep_end) + " | " + fmt("%.3f", c.mean_height_end) + " | " +
         fmt("%.2f", c.contacts_end) + " | " + c.note + " |\n";
  }
  s += "\n## Settings\n\n";
  for (const std::string& line : r.settings) s += "- " + line + "\n";
  return s;
}

std::string bench_csv(const BenchResult& r)
{
  auto num = [](double v) { return v >= 0 && std::isfinite(v) ? fmt("%.9g", v) : std::string(); };
  auto quote = [](const std::string& t) {
    std::string q = "\"";
    for (char ch : t) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
  };
  std::string s =
      "method,n,broadphase,step_ms_median,step_ms_min,step_ms_max,collision_ms,response_ms,broad_ms,narrow_ms,"
      "fall_ms,settle_ms,fall_steps,first_sleep_step,step_ms_envelope,cpu_ms,repeats,steps,engine,skipped,asleep_end,mean_height_end,"
      "contacts_per_body_end,note\n";
  for (const BenchCell& c : r.cells) {
    const bool m = !c.skipped;
    s += c.method + "," + std::to_string(c.n) + "," + c.broadphase + ",";
    s += (m ? num(c.step_ms_median) : "") + "," + (m ? num(c.step_ms_min) : "") + "," + (m ? num(c.step_ms_max) : "") +
         ",";
    s += (m ? num(c.collision_ms) : "") + "," + (m ? num(c.response_ms) : "") + "," + (m ? num(c.broad_ms) : "") + "," +
         (m ? num(c.narrow_ms) : "") + ",";
    s += (m ? num(c.fall_ms) : "") + "," + (m ? num(c.settle_ms) : "") + "," +
         (m ? std::to_string(c.fall_steps) : std::string()) + "," +
         (m && c.first_sleep_step >= 0 ? std::to_string(c.first_sleep_step) : std::string()) + "," +
         (m ? num(c.step_ms_envelope) : "") + "," + (m ? num(c.cpu_ms) : "") + ",";
    s += std::to_string(c.repeats) + "," + std::to_string(c.steps) + "," + c.engine + "," + (c.skipped ? "1" : "0") +
         ",";
    s += (m ? num(c.asleep_end) : "") + "," + (m ? num(c.mean_height_end) : "") + "," + (m ? num(c.contacts_end) : "") +
         "," + quote(c.note) + "\n";
  }
  return s;
}

void write_bench_chart(const BenchResult& r, const std::filesystem::path& path)
{
  std::vector<std::string> args{"--out", path.string(), "--shape", r.options.shape};
  if (r.options.chart_cpu) args.push_back("--cpu");
  plot::run_script_on("bench.py", bench_csv(r), ".csv", args);
}

}  // namespace statsim::tools
