// Piles of `statsim fidelity`: the drop piles (drop_scene3 of every seed, run to rest) and the
// pile scenes of --scenes (heap, bin, column, wall), each measured and summarised per method.
#include "fidelity/stages.hpp"

#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "fidelity/metrics.hpp"
#include "fidelity/scene_reference.hpp"
#include "scenes/frames.hpp"
#include "scenes/piles.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace statsim::tools::fidelity {

PileRun run_pile(const Setup& setup, const MethodSpec& m, std::uint64_t seed, int count, double dt, double limit,
                 std::uint64_t world_seed)
{
  scenes::DropOptions o;
  o.count = count;
  o.bounding_radius = setup.radius;
  o.seed = seed;
  const scenes::DropScene3 scene = scenes::drop_scene3(o);
  MethodSpec many = m;
  many.gather_reference = false;  // GatherReferenceSim holds one body
  std::unique_ptr<bench::Sim> sim = build(setup, many, scene, world_seed, dt);
  const std::size_t n = scene.bodies.size();
  std::vector<double> quiet_since(n, -1);
  const long steps = static_cast<long>(std::ceil(limit / dt - 1e-9));
  PileRun out;
  out.time_limited = true;
  std::vector<scenes::BodyState3> s(n);
  double t = 0;
  for (long k = 1; k <= steps; ++k) {
    sim->step();
    t = static_cast<double>(k) * dt;
    bool all = true;
    for (std::size_t i = 0; i < n; ++i) {
      s[i] = sim->body_state(i);
      if (speed(s[i], setup.radius) < kQuietSpeed) {
        if (quiet_since[i] < 0) quiet_since[i] = t;
      } else {
        quiet_since[i] = -1;
      }
      const bool rest = sim->body_asleep(i) || (quiet_since[i] >= 0 && t - quiet_since[i] >= kQuietTime - 1e-9);
      all = all && rest;
    }
    if (all) {
      out.time_limited = false;
      break;
    }
  }
  out.seconds = t;
  out.responses = sim->statistical_responses();
  out.clamps = sim->energy_clamps();
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& b : s) c += b.position.head<2>();
  c /= static_cast<double>(n);
  for (const auto& b : s) {
    out.radius.push_back((b.position.head<2>() - c).norm());
    out.height.push_back(b.position.z());
    out.config.push_back(classify(b.orientation, setup.poses));
  }
  return out;
}


std::vector<std::string> scene_kinds(const std::vector<std::string>& names)
{
  std::vector<std::string> out;
  auto add = [&](const std::string& k) {
    if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  };
  for (const std::string& n : names) {
    if (n == "stack") add("column"), add("wall");
    else add(n);
  }
  return out;
}

namespace {

// A stack's pose for a shape built of boxes: the first box's axes along the world's (a box face
// down, the L-shape flat on its large face). The L-shape's body frame is its principal frame;
// a box is symmetric about its own axes, so turning the frame into a proper rotation by flipping
// one axis keeps every face axis-aligned.
Eigen::Quaterniond stack_orientation(const bench::Body3& body)
{
  if (body.boxes.empty())
    throw std::invalid_argument("the column and the wall need a shape built of boxes (box, lshape), not " + body.shape);
  Eigen::Matrix3d q = body.boxes.front().rotation.transpose();
  if (q.determinant() < 0) q.row(0) *= -1;
  return Eigen::Quaterniond(q).normalized();
}

// Volume of the closed triangle mesh (divergence theorem: the sum of the signed volumes of the
// tetrahedra from the origin to each triangle, a . (b x c) / 6).
double mesh_volume(const bench::Body3& body)
{
  double v = 0;
  for (std::size_t t = 0; t + 2 < body.full_indices.size(); t += 3) {
    const Eigen::Vector3d& a = body.full_vertices[static_cast<std::size_t>(body.full_indices[t])];
    const Eigen::Vector3d& b = body.full_vertices[static_cast<std::size_t>(body.full_indices[t + 1])];
    const Eigen::Vector3d& c = body.full_vertices[static_cast<std::size_t>(body.full_indices[t + 2])];
    v += a.dot(b.cross(c));
  }
  return std::fabs(v) / 6.0;
}

// The bounding radius R of the heap and bin: of the shape, or the larger of a mixed scene's two.
double scene_radius(const Setup& setup)
{
  return setup.mixed ? std::max(setup.radius, setup.mix_body.bounding_radius) : setup.radius;
}

scenes::PileScene3 make_scene(const Setup& setup, const FidelityOptions& o, const std::string& kind,
                              std::uint64_t seed)
{
  if (kind == "heap") {
    scenes::HeapOptions h;
    h.count = o.heap_count;
    h.bounding_radius = scene_radius(setup);
    h.seed = seed;
    h.shapes = setup.mixed ? 2 : 1;
    return scenes::heap_scene(h);
  }
  if (kind == "bin") {
    scenes::BinOptions b;
    b.count = o.bin_count;
    b.bounding_radius = scene_radius(setup);
    b.seed = seed;
    b.shapes = setup.mixed ? 2 : 1;
    b.cells = o.bin_cells;
    return scenes::bin_scene(b);
  }
  scenes::StackOptions s;
  s.orientation = stack_orientation(setup.body);
  s.height = kind == "column" ? o.column_height : o.wall_height;
  s.columns = kind == "column" ? 1 : o.wall_columns;
  scenes::rotated_extent(setup.body.full_vertices, s.orientation, s.lo, s.hi);
  return scenes::stack_scene(s);
}

std::string describe_scene(const scenes::PileScene3& sc, const FidelityOptions& o)
{
  char b[400];
  if (sc.kind == "heap")
    std::snprintf(b, sizeof b,
                  "heap: %zu bodies poured one every %.3g s from 4 points %.3g m apart at %.3g m above the origin, "
                  "%.3g m/s downwards, onto the ground; runs end when all rest after the last release or %.3g s after it",
                  sc.bodies.size(), sc.release_time.size() > 1 ? sc.release_time[1] : 0.0, sc.cell, sc.nozzle_height,
                  sc.pour_speed, o.time_limit);
  else if (sc.kind == "bin")
    std::snprintf(b, sizeof b,
                  "bin: %zu bodies in a square bin of inner side %.3g m (%d x %d cells of %.3g m, layers from %.3g m), "
                  "walls and ground planes; runs end when all rest or at %.3g s",
                  sc.bodies.size(), 2 * sc.bin_half_width, o.bin_cells, o.bin_cells, sc.cell, 1.5 * sc.cell,
                  o.time_limit);
  else
    std::snprintf(b, sizeof b,
                  "%s: %d column(s) of %d bodies in a rest pose, touching (pitch %.4g m, column width %.4g m, top "
                  "centre placed at %.4g m), no velocity; measured after %.3g s",
                  sc.kind.c_str(), sc.columns, sc.height, sc.pitch, sc.width, sc.bodies.back().position.z(),
                  o.stack_time);
  return b;
}

}  // namespace

std::string scene_description(const Setup& setup, const FidelityOptions& o, const std::string& kind)
{
  return describe_scene(make_scene(setup, o, kind, 1), o);
}

namespace {

struct SceneOutcome {
  SceneRun run;
  std::vector<scenes::BodyState3> states;  // final
  std::vector<bool> asleep;
  std::vector<int> shapes;  // a mixed scene's shape of each body (PileScene3::shapes)
};

SceneOutcome run_scene(const Setup& setup, const MethodSpec& m, const scenes::PileScene3& sc,
                       const FidelityOptions& o, double dt, std::uint64_t world_seed,
                       const std::vector<double>& volumes)
{
  const double radius = scene_radius(setup);
  const scenes::DropScene3 drop = sc.as_drop_scene();
  std::vector<bullet::Plane> planes;
  for (const scenes::ScenePlane& p : sc.planes) planes.push_back({p.normal, p.offset});
  std::unique_ptr<bench::Sim> sim;
  if (m.bullet) {
    // dbvt: the sweep-and-prune broad phase holds N + 2 handles, too few with the bin's walls.
    bullet::DropSettings s = bench::bullet_drop_settings(setup.body, m.bullet_method, "dbvt", drop);
    s.planes = planes;
    s.solver_iterations = m.solver_iterations;
    if (sc.shapes.empty())
      sim = bench::make_bullet(bench::make_bullet_shapes(setup.body), m.bullet_method, s, sc.bodies, dt);
    else
      sim = bench::make_bullet_mixed({bench::make_bullet_shapes(setup.body), bench::make_bullet_shapes(setup.mix_body)},
                                     sc.shapes, m.bullet_method, s, sc.bodies, dt);
  } else {
    // The statsim world adds the ground itself; the rest are walls.
    const std::vector<bullet::Plane> walls(planes.begin() + 1, planes.end());
    if (sc.shapes.empty())
      sim = bench::make_statsim3_table(m.table, setup.body.mass, drop, world_seed, dt, "", m.variant, walls);
    else
      sim = bench::make_statsim3_mixed({m.table, setup.mix_table}, {setup.body.mass, setup.mix_body.mass}, sc.shapes,
                                       drop, world_seed, dt, m.variant, walls);
  }
  const bool stack = sc.kind == "column" || sc.kind == "wall";
  // The heap's time limit counts from its last release.
  const double limit = stack ? o.stack_time : o.time_limit + (sc.release_time.empty() ? 0.0 : sc.release_time.back());
  const std::size_t n = sc.bodies.size();
  std::vector<double> quiet_since(n, -1);
  const long steps = static_cast<long>(std::ceil(limit / dt - 1e-9));
  SceneOutcome out;
  out.shapes = sc.shapes;
  out.run.time_limited = !stack;
  out.states.resize(n);
  double t = 0, step_cpu = 0;
  long stepped = 0;
  std::size_t released = 0;  // heap: bodies are released in order
  for (long k = 1; k <= steps; ++k) {
    for (; released < sc.release.size() && sc.release_time[released] <= t + 1e-9; ++released)
      sim->place_body(released, sc.release[released]);
    const double cpu = bench::thread_cpu_ms();
    sim->step();
    step_cpu += bench::thread_cpu_ms() - cpu;
    ++stepped;
    t = static_cast<double>(k) * dt;
    if (stack || released < sc.release.size()) continue;
    bool all = true;
    for (std::size_t i = 0; i < n; ++i) {
      const scenes::BodyState3 s = sim->body_state(i);
      if (speed(s, radius) < kQuietSpeed) {
        if (quiet_since[i] < 0) quiet_since[i] = t;
      } else {
        quiet_since[i] = -1;
      }
      all = all && (sim->body_asleep(i) || (quiet_since[i] >= 0 && t - quiet_since[i] >= kQuietTime - 1e-9));
    }
    if (all) {
      out.run.time_limited = false;
      break;
    }
  }
  out.run.seconds = t;
  out.run.step_ms = stepped > 0 ? step_cpu / static_cast<double>(stepped) : 0.0;
  out.run.all_asleep = true;
  std::vector<Eigen::Vector3d> centres(n);
  out.asleep.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.states[i] = sim->body_state(i);
    centres[i] = out.states[i].position;
    out.asleep[i] = sim->body_asleep(i);
    out.run.all_asleep = out.run.all_asleep && out.asleep[i];
  }
  if (sc.kind == "heap") {
    const scenes::HeapProfile h = scenes::heap_profile(centres, radius, 0.5 * radius);
    out.run.values = {h.angle_deg, h.height};
  } else if (sc.kind == "bin") {
    std::vector<double> z;
    for (const Eigen::Vector3d& c : centres) z.push_back(c.z());
    const double side = 2 * sc.bin_half_width;
    // A mixed bin: the mean volume of its bodies.
    double volume = 0;
    for (std::size_t i = 0; i < n; ++i) volume += volumes[sc.shapes.empty() ? 0 : static_cast<std::size_t>(sc.shapes[i])];
    volume /= static_cast<double>(n);
    const scenes::BinFill f = scenes::bin_fill(z, volume, side * side);
    out.run.values = {f.fill_height, f.packing};
  } else {
    std::vector<Eigen::Quaterniond> orientations(n);
    for (std::size_t i = 0; i < n; ++i) orientations[i] = out.states[i].orientation;
    std::vector<scenes::SceneBox> boxes;
    for (const bench::Body3::Box& b : setup.body.boxes) boxes.push_back({b.centre, b.rotation, b.half_extents});
    const scenes::StackHold h = scenes::stack_hold(sc, boxes, centres, orientations);
    out.run.values = {h.held, 1e3 * h.overlap};
  }
  return out;
}

void write_scene_frames(const std::string& path, const Setup& setup, const SceneOutcome& r)
{
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + path);
  scenes::write_frames_header(f);
  for (std::size_t i = 0; i < r.states.size(); ++i)
    scenes::write_frame_row(f, 0, r.run.seconds, static_cast<std::uint32_t>(i),
                            (!r.shapes.empty() && r.shapes[i] == 1 ? setup.mix_body : setup.body).shape.c_str(),
                            r.states[i].position,
                            r.states[i].orientation, r.asleep[i] ? 2 : 0, 0.0);
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
}

double metric_mean(const std::vector<SceneRun>& runs, std::size_t k)
{
  double s = 0;
  for (const SceneRun& r : runs) s += r.values[k];
  return runs.empty() ? 0.0 : s / static_cast<double>(runs.size());
}

double metric_distance(const SceneMetric& m, const std::vector<SceneRun>& a, const std::vector<SceneRun>& ref,
                       std::size_t k)
{
  const double d = metric_mean(a, k) - metric_mean(ref, k);
  if (!m.relative) return d;
  const double r = metric_mean(ref, k);
  return r != 0 ? d / r : 0.0;
}

double asleep_share(const std::vector<SceneRun>& runs)
{
  double n = 0;
  for (const SceneRun& r : runs) n += r.all_asleep;
  return runs.empty() ? 0.0 : n / static_cast<double>(runs.size());
}

// Means (with intervals over resampled seeds) and, against `ref`, the distances.
void summarise(SceneSample& s, const std::vector<SceneMetric>& metrics, const std::vector<SceneRun>* ref,
               int resamples)
{
  const std::size_t n = s.runs.size();
  auto own = [&](auto stat) {
    return bootstrap(
        n, n, [&](const std::vector<std::size_t>& ia, const std::vector<std::size_t>&) { return stat(pick(s.runs, ia)); },
        resamples);
  };
  s.means.clear();
  s.distances.clear();
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    s.means.push_back({metric_mean(s.runs, k), own([k](const std::vector<SceneRun>& r) { return metric_mean(r, k); })});
    if (!ref) continue;
    const SceneMetric& m = metrics[k];
    s.distances.push_back({metric_distance(m, s.runs, *ref, k),
                           resampled(s.runs, *ref,
                                     [&](const std::vector<SceneRun>& a, const std::vector<SceneRun>& b) {
                                       return metric_distance(m, a, b, k);
                                     },
                                     [](double x) { return x; }, resamples)});
  }
  s.asleep = {asleep_share(s.runs), own([](const std::vector<SceneRun>& r) { return asleep_share(r); })};
}


}  // namespace

SceneRun run_scene_seed(const Setup& setup, const MethodSpec& m, const FidelityOptions& o, const std::string& kind,
                        std::uint64_t seed, double dt)
{
  std::vector<double> volumes{mesh_volume(setup.body)};
  if (setup.mixed) volumes.push_back(mesh_volume(setup.mix_body));
  return run_scene(setup, m, make_scene(setup, o, kind, seed), o, dt, mix(o.seed, seed), volumes).run;
}

std::vector<SceneResult> run_scenes(const Setup& setup, const FidelityOptions& o, unsigned threads)
{
  std::vector<SceneResult> results;
  std::vector<double> volumes{mesh_volume(setup.body)};
  if (setup.mixed) volumes.push_back(mesh_volume(setup.mix_body));
  const std::size_t seeds = static_cast<std::size_t>(o.scene_seeds);
  const std::size_t samples = 2 + setup.methods.size();
  const MethodSpec ref = pile_reference_method(o.pile_reference_iterations);
  std::string stored_text;
  if (!o.scene_reference.empty()) {
    std::ifstream in(o.scene_reference, std::ios::binary);
    if (!in) throw std::runtime_error("--scene-reference: cannot read " + o.scene_reference);
    std::ostringstream text;
    text << in.rdbuf();
    stored_text = text.str();
  }
  for (const std::string& kind : scene_kinds(o.scenes)) {
    SceneResult res;
    res.kind = kind;
    res.metrics = scene_metrics(kind);
    res.description = scene_description(setup, o, kind);
    const bool stored = !stored_text.empty();
    StoredSceneReference from_file;
    if (stored)
      from_file = stored_scene_reference(stored_text, shape_label(o), kind, res.description, res.metrics, seeds,
                                         pile_reference_step(o, kind));
    Progress progress(("fidelity: " + kind).c_str(), samples * seeds, o.progress);
    // Job j: sample j % samples, seed index j / samples (the expensive reference runs spread out).
    const std::vector<SceneOutcome> all = parallel_map(
        samples * seeds,
        [&](std::size_t job) {
          const std::size_t sample = job % samples, k = job / samples;
          const std::uint64_t seed = 1 + k + (sample == 1 ? seeds : 0);
          if (stored && sample < 2) {
            SceneOutcome r;
            r.run = (sample == 0 ? from_file.a : from_file.b)[k];
            progress.add();
            return r;
          }
          const MethodSpec& m = sample < 2 ? ref : setup.methods[sample - 2];
          const double dt = sample < 2 ? pile_reference_step(o, kind) : o.dt;
          SceneOutcome r = run_scene(setup, m, make_scene(setup, o, kind, seed), o, dt, mix(o.seed, seed), volumes);
          progress.add();
          if (k != 0 || o.scene_frames.empty()) r.states.clear();
          return r;
        },
        threads);
    res.reference.name = "reference";
    res.reference.dt = pile_reference_step(o, kind);
    res.reference_b.name = "reference_b";
    res.reference_b.dt = pile_reference_step(o, kind);
    res.methods.resize(setup.methods.size());
    for (std::size_t i = 0; i < setup.methods.size(); ++i) {
      res.methods[i].name = setup.methods[i].name;
      res.methods[i].dt = o.dt;
    }
    for (std::size_t job = 0; job < all.size(); ++job) {
      const std::size_t sample = job % samples;
      SceneSample& s = sample == 0 ? res.reference : sample == 1 ? res.reference_b : res.methods[sample - 2];
      s.runs.push_back(all[job].run);
      if (!all[job].states.empty()) {
        const std::string file = o.scene_frames + "/" + kind + "_" + (sample == 0 ? std::string("reference") : s.name) +
                                 ".csv";
        if (sample != 1) write_scene_frames(file, setup, all[job]);
      }
    }
    summarise(res.reference, res.metrics, nullptr, o.bootstrap);
    summarise(res.reference_b, res.metrics, &res.reference.runs, o.bootstrap);
    for (SceneSample& s : res.methods) summarise(s, res.metrics, &res.reference.runs, o.bootstrap);
    results.push_back(std::move(res));
  }
  return results;
}


}  // namespace statsim::tools::fidelity
