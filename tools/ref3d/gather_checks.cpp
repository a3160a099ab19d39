// See gather_checks.hpp.
#include "ref3d/gather_checks.hpp"

#include "common/format.hpp"
#include "common/parallel.hpp"
#include "common/pi.hpp"
#include "common/progress.hpp"
#include "common/sample_stats.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/reference_pool.hpp"
#include "ref3d/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace statsim::tools::ref3d {

// ---- checks ----------------------------------------------------------------------------------

namespace {

struct CheckCell {
  double cos_theta, cos_phi, spin_ratio;
};

}  // namespace

std::string speed_check_report(const GatherOptions& options, const std::vector<double>& speeds, int trials)
{
  GatherOptions o = options;
  validate_gather_options(o);
  const ShapeModel m = build_model(o);
  ReferencePool pool(m, o.reference);
  const std::vector<CheckCell> cells = {{1.0, 0.0, 0.0}, {1.0, 0.0, 0.5}, {0.7, 0.0, 0.0},  {0.7, 0.5, 1.0},
                                        {0.4, 0.0, 0.3}, {0.4, -0.5, 2.0}, {0.1, 0.0, 0.0}, {0.1, 0.5, 1.0}};
  const std::size_t nc = cells.size(), nv = speeds.size(), n = static_cast<std::size_t>(trials);
  std::vector<ResponseTrial> all(nc * nv * n);
  Progress progress("speed check", nc * nv * n, o.progress);
  parallel_for(
      nc * nv,
      [&](std::size_t task) {
        const std::size_t c = task / nv, v = task % nv;
        pool.with([&](const Reference& ref) {
          // The same orientations at every speed (index independent of the speed): paired samples.
          for (std::size_t t = 0; t < n; ++t)
            all[task * n + t] = response_trial(ref, o, cells[c].cos_theta, cells[c].cos_phi, speeds[v],
                                               cells[c].spin_ratio, kCheckStream, c * n + t, false);
          return 0;
        });
        progress.add(n);
      },
      o.threads);
  progress.finish();
  std::ostringstream s;
  s << "Speed invariance of the reference (" << m.name << ", " << trials
    << " impacts per cell and speed, the same orientations at every speed): normalised means\n";
  s << "(W+ L/|V-| and (V+ - V_particle+)/|V-|; restitution " << num(o.reference.restitution) << ", friction "
    << num(o.reference.friction) << ", threshold " << num(o.reference.restitution_threshold) << " m/s, dt "
    << num(o.reference.dt) << " s). Last column: the largest standard error of the means in the row.\n\n";
  s << "| cos theta | cos phi | s | quantity |";
  for (double v : speeds) s << " " << num(v) << " m/s |";
  s << " s.e. |\n|---|---|---|---|";
  for (std::size_t v = 0; v < nv; ++v) s << "---|";
  s << "---|\n";
  const char* names[] = {"w_x", "w_y", "w_z", "dv_x", "dv_y", "dv_z"};
  int time_limited = 0;
  for (const ResponseTrial& t : all) time_limited += t.time_limited ? 1 : 0;
  for (std::size_t c = 0; c < nc; ++c) {
    for (int comp : {1, 3, 5, 6}) {
      s << "| " << num(cells[c].cos_theta) << " | " << num(cells[c].cos_phi) << " | " << num(cells[c].spin_ratio) << " | "
        << (comp == 6 ? "|W+| L/|V-|" : names[comp]) << " |";
      double se = 0.0;
      for (std::size_t v = 0; v < nv; ++v) {
        const ResponseTrial* base = &all[(c * nv + v) * n];
        const MeanStd st = mean_std(n, [&](std::size_t k) {
          const Response& x = base[k].value;
          return comp == 6 ? std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) : x[comp];
        });
        se = std::max(se, st.std / std::sqrt(static_cast<double>(n)));
        s << " " << fmt("%+.3f", st.mean) << " |";
      }
      s << " " << fmt("%.3f", se) << " |\n";
    }
  }
  s << "\n" << time_limited << " of " << all.size() << " impacts hit the time limit.\n";
  return s.str();
}

namespace {
// A time step for humans: "1/60" when 1/dt is a whole number, else the decimal.
std::string step_name(double dt)
{
  const double inv = 1.0 / dt;
  if (std::fabs(inv - std::nearbyint(inv)) < 1e-9 * inv) return "1/" + num(std::nearbyint(inv));
  return num(dt);
}
}  // namespace

std::string step_check_report(const GatherOptions& options)
{
  GatherOptions base = options;
  base.cos_theta = {0.25, 0.7, 1.0};
  base.cos_phi = {-1.0, 0.0, 1.0};
  base.spin_ratios = {0.0, 1.0, 4.0, 8.0};
  base.height_ratios = {0.0};
  base.height_trials = 2;
  base.with_speed = false;
  const double dt = options.reference.dt;
  std::vector<double> steps;
  for (double d : {1.0 / 60.0, 1.0 / 240.0})
    if (d > 1.5 * dt) steps.push_back(d);
  steps.push_back(dt);
  steps.push_back(dt / 2);
  std::vector<GatherResult> runs;
  for (double d : steps) {
    GatherOptions o = base;
    o.reference.dt = d;
    runs.push_back(gather(o));
  }
  const GatherResult& fine = runs.back();
  std::ostringstream s;
  s << "Time step (" << fine.model.name << "): a small gathering at each dt, the same random trials: "
    << fine.response_mean.size() / 6 << " response cells (cos theta 0.25, 0.7, 1; cos phi -1, 0, 1; s 0, 1, 4, 8) x "
    << options.trials << " impacts at " << num(options.speed) << " m/s, and " << options.rest_drops
    << " rest drops. Response change: the largest |difference| of a normalised mean from the dt = " << step_name(steps.back())
    << " s run, and that difference over its standard error (unpaired). h_coll does not depend on dt (exact free flight).\n\n";
  s << "| dt (s) | drops settled | mean time to settle (s) | impacts time-limited | largest response change | in standard errors |\n";
  s << "|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const GatherResult& a = runs[k];
    double worst = 0.0, worst_z = 0.0;
    for (std::size_t i = 0; i < a.response_mean.size(); ++i) {
      const double d = std::fabs(a.response_mean[i] - fine.response_mean[i]);
      const double se = std::sqrt((a.response_std[i] * a.response_std[i] + fine.response_std[i] * fine.response_std[i]) /
                                  static_cast<double>(options.trials));
      worst = std::max(worst, d);
      if (se > 0) worst_z = std::max(worst_z, d / se);
    }
    s << "| " << step_name(steps[k]) << " | " << a.settled << " / " << (a.settled + a.unsettled) << " | "
      << fmt("%.2f", a.mean_settle_time) << " | " << a.time_limited << " | "
      << (k + 1 == runs.size() ? std::string("-") : fmt("%.4f", worst)) << " | "
      << (k + 1 == runs.size() ? std::string("-") : fmt("%.2f", worst_z)) << " |\n";
  }
  // Rest poses: those of the finest run, with their frequency at every dt (matched by normal).
  std::vector<RestPose> poses = fine.rest;
  poses.insert(poses.end(), fine.rest_rare.begin(), fine.rest_rare.end());
  s << "\n| rest pose (body-frame up) | h_rest (m) |";
  for (double d : steps) s << " frequency at dt " << step_name(d) << " |";
  s << "\n|---|---|";
  for (std::size_t k = 0; k < steps.size(); ++k) s << "---|";
  s << "\n";
  const double cos_tol = std::cos(options.rest_tolerance_deg * kPi / 180.0);
  for (const RestPose& p : poses) {
    s << "| " << vec3(p.normal, "%.3f") << " | " << fmt("%.4f", p.height) << " |";
    for (const GatherResult& a : runs) {
      double f = 0.0;
      for (const auto* list : {&a.rest, &a.rest_rare})
        for (const RestPose& q : *list)
          if (q.normal.dot(p.normal) >= cos_tol) f += q.frequency;
      s << " " << fmt("%.3f", f) << " |";
    }
    s << "\n";
  }
  return s.str();
}

std::string settings_check_report(const GatherOptions& options)
{
  // A face-down cube (the committed box) at normal incidence: it should leave at e |V-| with no
  // spin. Bullet's defaults vs the reference's settings, one fix at a time.
  const ShapeModel box = load_shape_model("box", "", options.density);
  struct Row {
    std::string name;
    ReferenceSettings s;
    bool start_gap;  // start a random fraction of a step above the ground (as a drop would)
  };
  ReferenceSettings defaults;
  defaults.dt = 1.0 / 60;
  defaults.solver_iterations = 10;
  defaults.warm_starting = true;
  defaults.split_impulse = false;
  defaults.margin = 0.04;
  defaults.ground_auto = false;
  defaults.ground = Ground::plane;
  defaults.multipoint_plane = false;
  defaults.speculative_contacts = true;
  defaults.restitution = options.reference.restitution;
  defaults.friction = options.reference.friction;
  defaults.restitution_threshold = 0.2;
  std::vector<Row> rows;
  rows.push_back({"Bullet defaults (dt 1/60, plane: one new contact point per step, margin 0.04, split impulse only "
                  "below 4 cm of penetration, warm starting, 10 iterations, speculative contacts)",
                  defaults, true});
  ReferenceSettings s1 = defaults;
  s1.split_impulse = true;
  s1.warm_starting = false;
  s1.solver_iterations = options.reference.solver_iterations;
  rows.push_back({"+ split impulse always, no warm starting, " + std::to_string(s1.solver_iterations) + " iterations",
                  s1, true});
  ReferenceSettings s2 = s1;
  s2.multipoint_plane = true;
  rows.push_back({"+ plane manifold of 4 points (setPlaneConvexMultipointIterations)", s2, true});
  ReferenceSettings s3 = s2;
  s3.speculative_contacts = false;
  rows.push_back({"+ no speculative contacts (contact processing threshold 0)", s3, true});
  ReferenceSettings s4 = s3;
  s4.dt = options.reference.dt;
  s4.margin = options.reference.margin;
  rows.push_back({"+ dt " + num(s4.dt) + " s, margin " + num(s4.margin) + " m", s4, true});
  ReferenceSettings s5 = s4;
  s5.ground_auto = true;
  rows.push_back({"+ box ground (btBoxBoxDetector: the whole contact face at once)", s5, true});
  ReferenceSettings s6 = s5;
  s6.restitution_threshold = options.reference.restitution_threshold;
  rows.push_back({"+ restitution threshold " + num(s6.restitution_threshold) + " m/s (Bullet: 0.2)", s6, true});
  rows.push_back({"reference settings, each impact starting at its exact first contact", options.reference, false});
  const std::vector<double> speeds = {0.25, 0.5, 1, 2, 4, 8};
  const std::vector<double> random_speeds = {0.5, 2, 8};
  std::ostringstream s;
  s << "Face-down cube (" << box.source << "), normal incidence, no gravity: rebound V+_z / |V-| and spin |W+| L / |V-|"
    << " (restitution " << num(options.reference.restitution) << "); the last columns: the mean V+_z/|V-| over 200"
    << " random orientations (the same at every speed) at normal incidence.\n\n| settings |";
  for (double v : speeds) s << " " << num(v) << " m/s |";
  for (double v : random_speeds) s << " random, " << num(v) << " m/s |";
  s << "\n|---|";
  for (std::size_t i = 0; i < speeds.size() + random_speeds.size(); ++i) s << "---|";
  s << "\n";
  for (const Row& row : rows) {
    Reference ref(box, row.s);
    s << "| " << row.name << " |";
    for (double u : speeds) {
      RigidState st;
      st.velocity = Eigen::Vector3d(0, 0, -u);
      const double gap = row.start_gap ? 0.5 * u * row.s.dt : -1e-7;
      st.position = Eigen::Vector3d(0, 0, 0.1 + gap);
      const ImpactResult ir = ref.impact(st, 2.0);
      s << " " << fmt("%.3f", ir.after.velocity.z() / u) << " / " << fmt("%.3f", ir.after.spin.norm() * box.bounding_radius / u)
        << " |";
    }
    for (double u : random_speeds) {
      double mean = 0.0;
      const int n = 200;
      for (int k = 0; k < n; ++k) {
        TrialRng rng(options.seed, kCheckStream + 1, static_cast<std::uint64_t>(k));
        RigidState st;
        st.orientation = rng.rotation();
        st.velocity = Eigen::Vector3d(0, 0, -u);
        const double gap = row.start_gap ? u * row.s.dt * rng.uniform() : -1e-7;
        st.position = Eigen::Vector3d(0, 0, -lowest_point(box.hull, st) + gap);
        mean += ref.impact(st, 2.0).after.velocity.z() / u;
      }
      s << " " << fmt("%.3f", mean / n) << " |";
    }
    s << "\n";
  }
  return s.str();
}

}  // namespace statsim::tools::ref3d
