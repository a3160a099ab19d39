#include "bench/bench.hpp"

#include "bench/bench_internal.hpp"
#include "common/atomic_file.hpp"
#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "mesh/shapes.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#ifndef STATSIM_BENCH_MESHES_DIR
#define STATSIM_BENCH_MESHES_DIR "tools/meshes"
#endif

namespace statsim::tools {
namespace bench {

// ---- bodies --------------------------------------------------------------------------------------

namespace {

constexpr double kDensity = 1000.0;  // kg/m^3 when no table gives the mass

TriMesh load_mesh(const std::string& path)
{
  TriMesh mesh;
  MeshError error;
  if (!load_obj(path, mesh, error)) throw std::runtime_error(error.message);
  return mesh;
}

// A point of the mesh frame in the body frame of `mp`: R^T (p - com).
Eigen::Vector3d to_body(const Eigen::Vector3d& p, const MassProperties& mp)
{
  return mp.principal_axes.transpose() * (p - mp.com);
}

void set_mesh(const TriMesh& mesh, const MassProperties& mp, std::vector<Eigen::Vector3d>& vertices,
              std::vector<int>& indices)
{
  vertices.clear();
  indices.clear();
  for (const auto& p : mesh.vertices) vertices.push_back(to_body(p, mp));
  for (const auto& t : mesh.triangles) indices.insert(indices.end(), t.begin(), t.end());
}

std::vector<Eigen::Vector4d> load_spheres(const std::string& path, const MassProperties& mp)
{
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::vector<Eigen::Vector4d> out;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream s(line);
    double x, y, z, r;
    if (!(s >> x >> y >> z >> r) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || !(r > 0))
      throw std::runtime_error(path + ":" + std::to_string(number) + ": expected 'x y z radius'");
    const Eigen::Vector3d c = to_body(Eigen::Vector3d(x, y, z), mp);
    out.emplace_back(c.x(), c.y(), c.z(), r);
  }
  if (out.empty()) throw std::runtime_error(path + ": no spheres");
  return out;
}

}  // namespace

Body3 load_body3(const std::string& shape, const std::string& meshes_dir)
{
  if (shape != "bunny" && shape != "box" && shape != "lshape")
    throw std::invalid_argument("unknown shape '" + shape + "' (bunny, box or lshape)");
  const std::string dir = meshes_dir.empty() ? std::string(STATSIM_BENCH_MESHES_DIR) : meshes_dir;
  Body3 body;
  body.shape = shape;
  const TriMesh full = load_mesh(dir + "/" + shape + ".obj");
  const MassProperties mp = compute_mass_properties(full, 1.0);  // per unit density
  set_mesh(full, mp, body.full_vertices, body.full_indices);
  for (const auto& p : body.full_vertices) body.bounding_radius = std::max(body.bounding_radius, p.norm());
  if (shape == "bunny") {
    const TriMesh low = load_mesh(dir + "/bunny_low.obj");
    set_mesh(low, mp, body.low_vertices, body.low_indices);
    body.spheres = load_spheres(dir + "/bunny_spheres7.txt", mp);
  } else {
    std::vector<BoxPart> parts;
    if (shape == "box") {
      Eigen::Vector3d lo, hi;
      bounding_box(full, lo, hi);
      parts.push_back(BoxPart{0.5 * (lo + hi), 0.5 * (hi - lo)});
    } else {
      for (const BoxPart& p : lshape_boxes()) parts.push_back(p);
    }
    for (const BoxPart& p : parts)
      body.boxes.push_back(Body3::Box{to_body(p.centre, mp), mp.principal_axes.transpose(), p.half_extents});
  }
  body.mass = kDensity * mp.volume;
  body.sphere_radius = body.bounding_radius;
  body.sphere_radius_note = "the bounding radius (no statistical table)";
  describe_table3(shape, body);
  body.inertia = mp.principal_moments * (body.mass / mp.volume);
  return body;
}

// ---- the run -------------------------------------------------------------------------------------

namespace {

bool is_bullet(const std::string& m)
{
  return m == "full" || m == "low" || m == "hull" || m == "spheres7" || m == "sphere";
}
bool is_box2d(const std::string& m)
{
  return m == "polygon" || m == "circle";
}

/// The broad phase a statsim method forces: "" (the runtime's default), "sap" or "grid".
std::string forced_broad_phase(const std::string& m)
{
  if (m == "statistical-sap") return "sap";
  if (m == "statistical-grid") return "grid";
  return "";
}

const std::vector<std::string>& methods3()
{
  static const std::vector<std::string> m{"full",        "low",         "hull",           "spheres7",
                                          "sphere",      "statistical", "statistical-sap", "statistical-grid"};
  return m;
}
const std::vector<std::string>& methods2()
{
  static const std::vector<std::string> m{"polygon", "circle", "statistical", "statistical-sap", "statistical-grid"};
  return m;
}
/// The benchmark's methods, plus statsim forced to each broad phase that is not its default.
std::vector<std::string> default_methods(int dim)
{
  std::vector<std::string> m = dim == 2 ? std::vector<std::string>{"polygon", "circle", "statistical"}
                                        : std::vector<std::string>{"full", "low", "spheres7", "sphere", "statistical"};
  const std::string d = statsim_default_broad_phase();
  if (d != "grid") m.push_back("statistical-grid");
  if (d != "sap") m.push_back("statistical-sap");
  return m;
}

std::string fmt(const char* format, double a)
{
  char buf[128];
  std::snprintf(buf, sizeof buf, format, a);
  return buf;
}

double median(std::vector<double> v)
{
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t k = v.size() / 2;
  return v.size() % 2 ? v[k] : 0.5 * (v[k - 1] + v[k]);
}

/// One timed repeat of one cell.
struct RepeatStats {
  std::vector<double> step_ms;  // every step's time
  double whole_ms = 0;
  double cpu_ms = 0;  // thread CPU time per step over the run
  double collision_ms = -1, broad_ms = -1, narrow_ms = -1;
  int first_sleep = -1;
};

struct CellState {
  BenchCell cell;
  std::vector<RepeatStats> repeats;
  double timed_seconds = 0;
  bool exhausted = false;  // budget used up: no more repeats
  std::string warning;
};

std::string machine_description()
{
  std::string cpu = "unknown CPU";
  {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("model name", 0) == 0) {
        const auto colon = line.find(':');
        if (colon != std::string::npos) cpu = line.substr(colon + 2);
        break;
      }
  }
  std::string load = "?";
  {
    std::ifstream in("/proc/loadavg");
    std::string a, b, c;
    if (in >> a >> b >> c) load = a + " " + b + " " + c;
  }
  std::string s = cpu + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads, load average " +
                  load + " at start; " +
#if defined(__clang__)
                  "clang " __clang_version__
#elif defined(__GNUC__)
                  "gcc " __VERSION__
#else
                  "unknown compiler"
#endif
      ;
#ifdef NDEBUG
  s += ", release build (NDEBUG)";
#else
  s += ", debug build (no NDEBUG): timings are not representative";
#endif
#if defined(__SANITIZE_ADDRESS__)
  s += ", AddressSanitizer: timings are not representative";
#endif
  return s;
}

class Runner {
public:
  explicit Runner(const BenchOptions& o) : o_(o) {}

  BenchResult run()
  {
    BenchResult result;
    result.options = o_;
    result.machine = machine_description();
    result.command = command_line();
    std::vector<std::string> methods = o_.methods.empty() ? default_methods(o_.dim) : o_.methods;

    if (o_.dim == 3) {
      body3_ = load_body3(o_.shape, o_.meshes_dir);
      bullet_shapes_ = make_bullet_shapes(body3_);
      result.settings.push_back("shape " + o_.shape + ": bounding radius " + fmt("%.4g m", body3_.bounding_radius) +
                                ", mass " + fmt("%.4g kg", body3_.mass) + "; statistical table " + body3_.table_name);
      if (body3_.has_table) {
        result.settings.push_back("material (from the table, for every method): restitution " +
                                  fmt("%.3g", body3_.surface.restitution) + ", friction " +
                                  fmt("%.3g", body3_.surface.friction) + ", rolling resistance " +
                                  fmt("%.3g", body3_.surface.rolling_resistance));
      } else {
        result.settings.push_back("material (no table: statsim's defaults): restitution 0.3, friction 0.5");
      }
      for (auto& s : bullet_settings(body3_)) result.settings.push_back(s);
    } else {
      describe_table2(body2_);
      if (body2_.circle_radius <= 0) {
        body2_.circle_radius = body2_.bounding_radius;
        body2_.circle_radius_note = "the bounding radius (no statistical table)";
      }
      result.settings.push_back("shape square: side 1 m, bounding radius 0.7071 m, mass " + fmt("%.4g kg", body2_.mass) +
                                "; statistical table " + body2_.table_name);
      for (auto& s : box2d_settings(body2_)) result.settings.push_back(s);
    }
    result.settings.push_back(
        "statsim: WorldDef defaults" +
        std::string(o_.hull_contacts ? " (body contacts at the hulls where the table has body-body data)"
                                     : " but body contacts at the collision spheres (BodyContacts::collision_spheres)") +
        (o_.workers > 1 ? "; " + std::to_string(o_.workers) +
                              " workers (WorldDef::workers, tools/common/task_pool.hpp: the CPU columns count the "
                              "calling thread only, compare the step columns)"
                        : std::string("; no workers")) +
        " (broad phase " + statsim_default_broad_phase() +
        "; statistical-sap / statistical-grid force sweep-and-prune / the grid" +
        "; 4 support passes, shock propagation, sleep speed 0.05 m/s for 0.5 s, by islands), ground plane, float; world "
        "capacity: the smallest of 16, 128, 1024, 4096, 16384, 32768, 131072 holding N, 32 candidate pairs per body; "
        "seed = scene seed");

    // Cells, in report order.
    for (const std::string& m : methods) {
      std::vector<std::string> bps;
      std::string engine;
      if (o_.dim == 3 && is_bullet(m)) {
        bps = o_.broadphases;
        engine = "bullet";
      } else if (o_.dim == 2 && is_box2d(m)) {
        bps = {"tree"};
        engine = "box2d";
      } else {
        const std::string forced = forced_broad_phase(m);
        bps = {forced.empty() ? statsim_default_broad_phase() : forced};
        engine = "statsim";
      }
      for (const std::string& bp : bps) {
        std::string why_not;
        if (engine == "bullet" && !bullet_supports(*bullet_shapes_, m, why_not)) unavailable_[m + "/" + bp] = why_not;
        if (engine == "statsim" && !(o_.dim == 3 ? body3_.has_table : body2_.has_table))
          unavailable_[m + "/" + bp] =
              "statistical table missing (" + (o_.dim == 3 ? body3_.table_name : body2_.table_name) + ")";
        kinds_.push_back({m, engine, bp});
      }
    }
    for (const auto& [key, why] : unavailable_)
      if (o_.progress) std::fprintf(stderr, "statsim bench: %s: %s\n", key.c_str(), why.c_str());

    for (int n : o_.counts) run_count(n, result);
    return result;
  }

private:
  struct Kind {
    std::string method, engine, broadphase;
  };

  std::string command_line() const
  {
    auto join = [](const auto& v) {
      std::string s;
      for (const auto& x : v) {
        if (!s.empty()) s += ",";
        std::ostringstream os;
        os << x;
        s += os.str();
      }
      return s;
    };
    std::string c = "statsim bench";
    if (o_.dim == 2) c += " --dim 2";
    c += " --shape " + o_.shape + " --n " + join(o_.counts);
    c += " --methods " + join(o_.methods.empty() ? default_methods(o_.dim) : o_.methods);
    if (o_.dim == 3) c += " --broadphase " + join(o_.broadphases);
    c += " --dt " + fmt("%.9g", o_.dt) + " --steps " + std::to_string(o_.steps) + " --warmup " +
         std::to_string(o_.warmup) + " --repeat " + std::to_string(o_.repeats) + " --limit-ms " +
         fmt("%g", o_.limit_ms) + " --budget-s " + fmt("%g", o_.budget_s) + " --seed " + std::to_string(o_.seed);
    if (!o_.hull_contacts) c += " --body-contacts spheres";
    if (o_.all_features) c += " --all-features";
    return c;
  }

  std::unique_ptr<Sim> make(const Kind& k, const scenes::DropScene3* s3, const scenes::DropScene2* s2) const
  {
    if (k.engine == "bullet") return make_bullet(bullet_shapes_, k.method, k.broadphase, *s3, o_.dt);
    if (k.engine == "box2d") return make_box2d(body2_, k.method, *s2, o_.dt);
    StatsimVariant v;
    v.hull_contacts = o_.hull_contacts;
    v.workers = o_.workers;
    v.all_features = o_.all_features;
    if (o_.dim == 3) return make_statsim3(body3_, *s3, o_.seed, o_.dt, forced_broad_phase(k.method), v);
    return make_statsim2(body2_, *s2, o_.seed, o_.dt, forced_broad_phase(k.method), v);
  }

  void run_count(int n, BenchResult& result)
  {
    scenes::DropOptions so;
    so.count = n;
    so.seed = o_.seed;
    so.bounding_radius = o_.dim == 3 ? body3_.bounding_radius : body2_.bounding_radius;
    scenes::DropScene3 s3;
    scenes::DropScene2 s2;
    if (o_.dim == 3) {
      s3 = scenes::drop_scene3(so);
      result.settings.push_back("N = " + std::to_string(n) + ": " + scenes::describe(s3));
    } else {
      s2 = scenes::drop_scene2(so);
      result.settings.push_back("N = " + std::to_string(n) + ": " + scenes::describe(s2));
    }

    std::vector<CellState> cells;
    for (const Kind& k : kinds_) {
      CellState c;
      c.cell.method = k.method;
      c.cell.engine = k.engine;
      c.cell.broadphase = k.broadphase;
      c.cell.n = n;
      c.cell.steps = o_.steps;
      const std::string key = k.method + "/" + k.broadphase;
      if (auto it = unavailable_.find(key); it != unavailable_.end()) {
        c.cell.skipped = true;
        c.cell.note = it->second;
      } else if (auto jt = over_limit_.find(key); jt != over_limit_.end()) {
        c.cell.skipped = true;
        c.cell.note = "skipped: over the " + fmt("%g", o_.limit_ms) + " ms/step limit at N = " +
                      std::to_string(jt->second);
      } else if (auto lt = last_measured_.find(key);
                 lt != last_measured_.end() && lt->second.second * n / lt->second.first > o_.limit_ms) {
        // Time per step grows at least linearly with N: skip without running.
        c.cell.skipped = true;
        c.cell.note = "skipped: over the " + fmt("%g", o_.limit_ms) + " ms/step limit (estimated " +
                      fmt("%.0f ms", lt->second.second * n / lt->second.first) + " from " +
                      fmt("%.0f ms", lt->second.second) + " at N = " + std::to_string(lt->second.first) +
                      ", scaled linearly)";
        over_limit_[key] = n;
      }
      cells.push_back(c);
    }

    // Warm-up (also a first estimate of the step time).
    for (std::size_t i = 0; i < cells.size(); ++i) {
      CellState& c = cells[i];
      if (c.cell.skipped || o_.warmup <= 0) continue;
      std::unique_ptr<Sim> sim = make(kinds_[i], &s3, &s2);
      const Clock::time_point t0 = Clock::now();
      for (int k = 0; k < o_.warmup; ++k) sim->step();
      const double ms = 1e-6 * static_cast<double>(elapsed_ns(t0, Clock::now())) / o_.warmup;
      if (ms > o_.limit_ms) skip(c, i, "warm-up steps took " + fmt("%.0f ms", ms));
    }

    for (int r = 0; r < o_.repeats; ++r)
      for (std::size_t i = 0; i < cells.size(); ++i) {
        CellState& c = cells[i];
        if (c.cell.skipped || c.exhausted) continue;
        run_repeat(c, i, r, &s3, &s2);
      }

    // The falling window: steps before the first body of any method fell asleep (sleeping
    // flatters every engine, each in its own way, so the phase is cut at the same step for all).
    int fall_steps = o_.steps;
    for (const CellState& c : cells)
      if (!c.cell.skipped)
        for (const RepeatStats& r : c.repeats)
          if (r.first_sleep > 0) fall_steps = std::min(fall_steps, r.first_sleep);
    for (CellState& c : cells) {
      finish(c, fall_steps);
      if (!c.cell.skipped) last_measured_[c.cell.method + "/" + c.cell.broadphase] = {n, c.cell.step_ms_median};
      result.cells.push_back(c.cell);
    }
  }

  void skip(CellState& c, std::size_t kind, const std::string& why)
  {
    c.cell.skipped = true;
    c.cell.note = "skipped: over the " + fmt("%g", o_.limit_ms) + " ms/step limit (" + why + ")";
    const Kind& k = kinds_[kind];
    over_limit_[k.method + "/" + k.broadphase] = c.cell.n;
    if (o_.progress) std::fprintf(stderr, "  %s/%s N=%d %s\n", k.method.c_str(), k.broadphase.c_str(), c.cell.n, c.cell.note.c_str());
  }

  void run_repeat(CellState& c, std::size_t kind, int r, const scenes::DropScene3* s3, const scenes::DropScene2* s2)
  {
    const Kind& k = kinds_[kind];
    std::unique_ptr<Sim> sim = make(k, s3, s2);
    const int steps = o_.steps;
    std::vector<double> total(static_cast<std::size_t>(steps)), coll(static_cast<std::size_t>(steps)),
        broad(static_cast<std::size_t>(steps)), narrow(static_cast<std::size_t>(steps));
    int first_sleep = -1;
    bool have_phases = true;
    const Clock::time_point start = Clock::now();
    Clock::time_point last_report = start;
    double window = 0;  // sum of the last 10 step times, ms
    double running = 0;  // sum of all step times so far, ms
    const double cpu0 = thread_cpu_ms();
    for (int s = 0; s < steps; ++s) {
      const Clock::time_point t0 = Clock::now();
      sim->step();
      const Clock::time_point t1 = Clock::now();
      const double ms = 1e-6 * static_cast<double>(elapsed_ns(t0, t1));
      const std::size_t u = static_cast<std::size_t>(s);
      total[u] = ms;
      const PhaseTimes p = sim->phases();
      if (p.collision() < 0) have_phases = false;
      coll[u] = 1e-6 * static_cast<double>(p.collision());
      broad[u] = 1e-6 * static_cast<double>(p.broad);
      narrow[u] = 1e-6 * static_cast<double>(p.narrow);
      if (first_sleep < 0 && sim->asleep() > 0) first_sleep = s + 1;  // steps [0, s] ran before anything slept
      window += ms;
      running += ms;
      if (s >= 10) window -= total[u - 10];
      if ((s >= 9 && window / 10 > o_.limit_ms) || ms > 10 * o_.limit_ms) {
        skip(c, kind, "step " + std::to_string(s + 1) + ": " + fmt("%.0f ms", s >= 9 ? window / 10 : ms));
        return;
      }
      if (o_.progress && std::chrono::duration<double>(t1 - last_report).count() > 30) {
        last_report = t1;
        std::fprintf(stderr, "  %s/%s N=%d repeat %d: step %d/%d, %.1f ms/step so far\n", k.method.c_str(),
                     k.broadphase.c_str(), c.cell.n, r + 1, s + 1, steps,
                     running / (s + 1));
      }
    }
    RepeatStats st;
    st.cpu_ms = (thread_cpu_ms() - cpu0) / steps;
    st.step_ms = total;
    double sum = 0;
    for (double t : total) sum += t;
    st.whole_ms = sum / steps;
    st.first_sleep = first_sleep;
    if (have_phases) {
      double a = 0, b = 0, cc = 0;
      for (int s = 0; s < steps; ++s) {
        a += coll[static_cast<std::size_t>(s)];
        b += broad[static_cast<std::size_t>(s)];
        cc += narrow[static_cast<std::size_t>(s)];
      }
      st.collision_ms = a / steps;
      st.broad_ms = b / steps;
      st.narrow_ms = cc / steps;
    }
    c.repeats.push_back(st);
    c.timed_seconds += sum * 1e-3;
    if (c.timed_seconds > o_.budget_s && r + 1 < o_.repeats) {
      c.exhausted = true;
      c.warning = "stopped after " + std::to_string(r + 1) + " repeat(s): over the " + fmt("%g", o_.budget_s) +
                  " s budget";
    }
    const EndState e = sim->end_state();
    const double nb = static_cast<double>(c.cell.n);
    c.cell.asleep_end = static_cast<double>(e.asleep) / nb;
    c.cell.mean_height_end = e.mean_height;
    c.cell.contacts_end = static_cast<double>(e.contacts) / nb;
    const std::string w = sim->warning();
    if (!w.empty()) c.warning = c.warning.empty() ? w : c.warning + "; " + w;
    if (o_.progress)
      std::fprintf(stderr, "  %-11s %-4s N=%-6d repeat %d/%d: %10.4f ms/step, CPU %10.4f ms/step (first sleep at step %d)\n",
                   k.method.c_str(), k.broadphase.c_str(), c.cell.n, r + 1, o_.repeats, st.whole_ms, st.cpu_ms,
                   first_sleep);
  }

  /// `fall_steps`: the falling window common to every method at this N (steps before the first
  /// body of any method falls asleep).
  void finish(CellState& c, int fall_steps) const
  {
    BenchCell& b = c.cell;
    if (!c.warning.empty()) b.note = b.note.empty() ? c.warning : b.note + "; " + c.warning;
    if (b.skipped || c.repeats.empty()) {
      b.skipped = true;
      b.repeats = 0;
      return;
    }
    std::vector<double> whole, fall, settle, coll, resp, broad, narrow, sleep, cpu;
    b.fall_steps = fall_steps;
    for (const RepeatStats& r : c.repeats) {
      whole.push_back(r.whole_ms);
      cpu.push_back(r.cpu_ms);
      const std::size_t k = r.step_ms.size(), f = std::min<std::size_t>(static_cast<std::size_t>(fall_steps), k);
      double a = 0, z = 0;
      for (std::size_t s = 0; s < k; ++s) (s < f ? a : z) += r.step_ms[s];
      if (f > 0) fall.push_back(a / static_cast<double>(f));
      if (f < k) settle.push_back(z / static_cast<double>(k - f));
      if (r.collision_ms >= 0) {
        coll.push_back(r.collision_ms);
        resp.push_back(r.whole_ms - r.collision_ms);
        broad.push_back(r.broad_ms);
        narrow.push_back(r.narrow_ms);
      }
      if (r.first_sleep >= 0) sleep.push_back(r.first_sleep);
    }
    b.repeats = static_cast<int>(c.repeats.size());
    // Envelope: every repeat does the same work step by step (deterministic engines, same
    // initial states), so the fastest of the repeats at each step is that step's time with the
    // least interference from other processes.
    {
      double sum = 0;
      const std::size_t k = c.repeats[0].step_ms.size();
      for (std::size_t s = 0; s < k; ++s) {
        double best = c.repeats[0].step_ms[s];
        for (const RepeatStats& r : c.repeats) best = std::min(best, r.step_ms[s]);
        sum += best;
      }
      b.step_ms_envelope = sum / static_cast<double>(k);
    }
    b.step_ms_median = median(whole);
    b.cpu_ms = median(cpu);
    b.step_ms_min = *std::min_element(whole.begin(), whole.end());
    b.step_ms_max = *std::max_element(whole.begin(), whole.end());
    if (!fall.empty()) b.fall_ms = median(fall);
    if (!settle.empty()) b.settle_ms = median(settle);
    if (!coll.empty()) {
      b.collision_ms = median(coll);
      b.response_ms = median(resp);
      b.broad_ms = median(broad);
      b.narrow_ms = median(narrow);
    }
    b.first_sleep_step = sleep.size() * 2 > c.repeats.size() ? static_cast<int>(median(sleep)) : -1;
  }

  BenchOptions o_;
  Body3 body3_;
  Body2 body2_;
  std::shared_ptr<BulletShapes> bullet_shapes_;
  std::vector<Kind> kinds_;
  std::map<std::string, std::string> unavailable_;
  std::map<std::string, int> over_limit_;
  std::map<std::string, std::pair<int, double>> last_measured_;  // N and median ms/step
};

}  // namespace
}  // namespace bench

// ---- public API ----------------------------------------------------------------------------------

void validate_bench_options(const BenchOptions& o)
{
  auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
  if (o.dim != 2 && o.dim != 3) bad("--dim must be 2 or 3");
  if (o.dim == 3 && o.shape != "bunny" && o.shape != "box" && o.shape != "lshape")
    bad("--shape must be bunny, box or lshape in 3D (got '" + o.shape + "')");
  if (o.dim == 2 && o.shape != "square" && o.shape != "bunny")  // "bunny" is the 3D default
    bad("--shape must be square in 2D (got '" + o.shape + "')");
  if (o.counts.empty()) bad("--n needs at least one count");
  for (int n : o.counts)
    if (n < 1 || static_cast<std::uint32_t>(n) > bench::statsim_capacity())
      bad("--n: counts must be 1.." + std::to_string(bench::statsim_capacity()) + " (got " + std::to_string(n) + ")");
  const auto& valid = o.dim == 3 ? bench::methods3() : bench::methods2();
  for (const std::string& m : o.methods)
    if (std::find(valid.begin(), valid.end(), m) == valid.end()) {
      std::string list;
      for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
      bad("--methods: unknown method '" + m + "' for --dim " + std::to_string(o.dim) + " (" + list + ")");
    }
  if (o.dim == 3) {
    if (o.broadphases.empty()) bad("--broadphase needs at least one of sap, dbvt");
    for (const std::string& b : o.broadphases)
      if (b != "sap" && b != "dbvt") bad("--broadphase: unknown '" + b + "' (sap, dbvt)");
  }
  if (!(o.dt > 0) || !std::isfinite(o.dt) || o.dt > 0.1) bad("--dt must be in (0, 0.1] s");
  if (o.steps < 1) bad("--steps must be >= 1");
  if (o.warmup < 0) bad("--warmup must be >= 0");
  if (o.repeats < 1) bad("--repeat must be >= 1");
  if (!(o.limit_ms > 0)) bad("--limit-ms must be positive");
  if (!(o.budget_s > 0)) bad("--budget-s must be positive");
}

BenchResult run_bench(const BenchOptions& options)
{
  BenchOptions o = options;
  if (o.dim == 2 && o.shape == "bunny") o.shape = "square";
  validate_bench_options(o);
  return bench::Runner(o).run();
}

}  // namespace statsim::tools
