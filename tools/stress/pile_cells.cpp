// Stress cells of piles and long runs: a deep pile, energy in a closed elastic box, a long run,
// a mass ratio of 1000 in a column, bodies spawned and removed for an hour.
#include "scenes/body_def.hpp"
#include "statsim/queries.hpp"
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

namespace {

// 4. energy --------------------------------------------------------------------------------------------
std::vector<scenes::BodyState3> box_states(int n, double half, double speed, std::uint64_t seed)
{
  scenes::SceneRng rng(seed);
  std::vector<scenes::BodyState3> out;
  const int side = static_cast<int>(std::ceil(std::cbrt(double(n))));
  const double cell = 2 * (half - 0.25) / side;
  for (int k = 0; k < n; ++k) {
    const int i = k % side, j = (k / side) % side, l = k / (side * side);
    scenes::BodyState3 s;
    s.position = Eigen::Vector3d(-half + 0.25 + (i + 0.5) * cell, -half + 0.25 + (j + 0.5) * cell,
                                 -half + 0.25 + (l + 0.5) * cell);
    s.orientation = random_q(rng);
    s.linear_velocity =
        Eigen::Vector3d(rng.uniform(-speed, speed), rng.uniform(-speed, speed), rng.uniform(-speed, speed));
    s.angular_velocity = Eigen::Vector3d(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
    out.push_back(s);
  }
  return out;
}

std::vector<bullet::Plane> closed_box(double half)
{
  std::vector<bullet::Plane> p;
  for (int a = 0; a < 3; ++a)
    for (const double sgn : {1.0, -1.0}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[a] = sgn;
      p.push_back({n, -half});
    }
  return p;
}

}  // namespace

// 3. deep pile -----------------------------------------------------------------------------------------
void Matrix::deep_pile()
{
  scenes::DropOptions o;
  o.count = opt_.quick ? 1000 : 10000;
  o.bounding_radius = R();
  const scenes::DropScene3 scene = scenes::drop_scene3(o);
  Setup3 setup;
  const double wall = scene.region.radius + R();
  setup.planes.push_back({Eigen::Vector3d(1, 0, 0), -wall});
  setup.planes.push_back({Eigen::Vector3d(-1, 0, 0), -wall});
  setup.planes.push_back({Eigen::Vector3d(0, 1, 0), -wall});
  setup.planes.push_back({Eigen::Vector3d(0, -1, 0), -wall});
  const double dt = 1.0 / 60, T = 20;
  const int steps = static_cast<int>(std::lround(T / dt));
  const std::string name = printf_string("deep pile %d bunnies, 5 planes", o.count);
  const double ke_per_body = 1e-3;
  for (const std::string& m : methods3()) {
    const bool stat = m == "statistical";
    const std::string criterion =
        printf_string("after 20 s: asleep >= 95%%, kinetic energy <= %.0e J per body, ", ke_per_body) +
        (stat ? std::string(opt_.hull_contacts ? "max hull overlap <= 20% of the separation the hulls touch at"
                                                : "max sphere overlap <= 20% of the radius sum") +
                     " (each second of the last 5 s)"
              : printf_string("max contact penetration <= 0.2 R = %.1f cm (each second of the last 5 s)", 20 * R()));
    const Clock::time_point t0 = Clock::now();
    auto sim = sim3(m, setup, scene.bodies, dt);
    const double build_s = seconds_since(t0);
    double overlap = 0, overlap_all = 0;
    int done = 0;
    double step_s = 0;
    for (; done < steps; ++done) {
      const Clock::time_point s0 = Clock::now();
      sim->step();
      step_s += seconds_since(s0);
      // Once per simulated second (the statsim measure visits every pair of bodies).
      if ((done + 1) % 60 == 0) {
        const double now = sim->overlap();
        overlap_all = std::max(overlap_all, now);
        if ((done + 1) * dt > T - 5) overlap = std::max(overlap, now);
      }
      if (!stat && step_s + build_s > budget()) {
        ++done;
        break;
      }
      if (opt_.progress && (done + 1) % 300 == 0)
        std::fprintf(stderr, "stress: deep pile %s: %.0f s simulated, %.1f ms/step\n", m.c_str(), (done + 1) * dt,
                     1e3 * step_s / (done + 1));
    }
    std::size_t asleep = 0;
    for (std::size_t i = 0; i < sim->body_count(); ++i) asleep += sim->body_asleep(i);
    const double ke = sim->kinetic_energy();
    const double frac = double(asleep) / double(sim->body_count());
    const double ms = 1e3 * step_s / std::max(done, 1);
    std::string figure = printf_string("KE %.3g J (%.2g J/body), asleep %.1f%%, ", ke, ke / double(sim->body_count()), 100 * frac) +
                         (stat ? printf_string(opt_.hull_contacts ? "max overlap %.1f%% of the hulls' reach (whole run %.1f%%)"
                                                       : "max overlap %.1f%% of radius sum (whole run %.1f%%)",
                                     100 * overlap,
                                     100 * overlap_all)
                               : printf_string("max penetration %.2f cm (whole run %.2f cm)", 100 * overlap,
                                     100 * overlap_all)) +
                         printf_string(", %.2f ms/step", ms);
    bool pass = frac >= 0.95 && ke <= ke_per_body * double(sim->body_count()) && overlap <= (stat ? 0.2 : 0.2 * R());
    if (done < steps) {
      figure += printf_string("; stopped at %.1f s simulated (budget %.0f s wall)", done * dt, budget());
      pass = false;
    }
    if (stat) {
      const auto* s = dynamic_cast<const StatsimSim3<16384>*>(sim.get());
      const auto* s1 = dynamic_cast<const StatsimSim3<1024>*>(sim.get());
      const std::uint32_t dropped = s ? s->pairs_dropped() : (s1 ? s1->pairs_dropped() : 0);
      if (dropped) figure += printf_string("; pair buffer overflow (up to %u dropped)", dropped);
    }
    add(name, m, pass, figure, criterion);
  }
}

void Matrix::energy()
{
  const int n = opt_.quick ? 50 : 100;
  const int steps = opt_.quick ? 2000 : 10000;
  const double dt = 1.0 / 60, half = 1.0;
  const auto states = box_states(n, half, 3.0, 21);
  Setup3 setup;
  setup.planes = closed_box(half);
  setup.gravity = Eigen::Vector3d::Zero();
  setup.sleeping = false;
  setup.restitution = 1;
  setup.friction = 0;
  const std::string criterion = "kinetic energy never above its start (relative tolerance 1e-5)";
  auto run = [&](const std::string& scene, const std::string& label, std::unique_ptr<bench::Sim> sim, bool statsim) {
    const double ke0 = sim->kinetic_energy();
    double hi = ke0;
    int done = 0;
    const Clock::time_point t0 = Clock::now();
    for (; done < steps; ++done) {
      sim->step();
      const double ke = sim->kinetic_energy();
      hi = std::isfinite(ke) ? std::max(hi, ke) : kInf;
      if (!statsim && seconds_since(t0) > budget()) {
        ++done;
        break;
      }
    }
    const double ke1 = sim->kinetic_energy();
    std::string figure = printf_string("KE0 %.4g J; max %+.3g%%, end %+.3g%% (drift)", ke0, 100 * (hi / ke0 - 1),
                             100 * (ke1 / ke0 - 1));
    bool pass = hi <= ke0 * (1 + 1e-5);
    if (done < steps) {
      figure += printf_string("; stopped after %d of %d steps (budget)", done, steps);
      pass = false;
    }
    add(scene, label, pass, figure, criterion);
  };
  const std::string scene = printf_string("energy, elastic box, %d steps", steps);
  for (const std::string& m : methods3()) {
    Setup3 s = setup;
    s.particle = m == "statistical";
    run(scene, m == "statistical" ? "statistical" : m, sim3(m, s, states, dt), m == "statistical");
  }
  if (want("statistical"))
    run(printf_string("energy, statistical responses, %d steps", steps), "statistical",
        sim3("statistical", setup, states, dt), true);
}

// 6. long run ------------------------------------------------------------------------------------------
void Matrix::long_run()
{
  if (!want("statistical")) return;
  scenes::DropOptions o;
  o.count = 1000;
  o.bounding_radius = R();
  const scenes::DropScene3 scene = scenes::drop_scene3(o);
  const double dt = 1.0 / 60, T = opt_.quick ? 120.0 : 3600.0, snapshot = 60.0;
  const long steps = std::lround(T / dt), snap_step = std::lround(snapshot / dt);
  std::uint64_t hashes[2] = {0, 0};
  int nan = 0;
  double sleeper_drift = 0, creep = 0, ms = 0;
  std::size_t awake_end = 0;
  for (int run = 0; run < 2; ++run) {
    StatsimSim3<1024> sim(with_contacts(Setup3{}), scene.bodies, dt);
    std::vector<Eigen::Vector3d> at_snap;
    std::vector<bool> slept(sim.body_count(), false);
    const Clock::time_point t0 = Clock::now();
    for (long k = 1; k <= steps; ++k) {
      sim.step();
      if (k == snap_step) {
        for (std::size_t i = 0; i < sim.body_count(); ++i) {
          at_snap.push_back(sim.body_state(i).position);
          slept[i] = sim.body_asleep(i);
        }
      } else if (k > snap_step) {
        // A body counts as a sleeper if it has been asleep at every step since the snapshot.
        for (std::size_t i = 0; i < sim.body_count(); ++i)
          if (slept[i] && !sim.body_asleep(i)) slept[i] = false;
      }
      if (opt_.progress && k % 36000 == 0)
        std::fprintf(stderr, "stress: long run %d: %.0f s simulated, %.3f ms/step\n", run + 1, double(k) * dt,
                     1e3 * seconds_since(t0) / double(k));
    }
    ms = 1e3 * seconds_since(t0) / double(steps);
    hashes[run] = sim.hash();
    if (run == 0) {
      for (std::size_t i = 0; i < sim.body_count(); ++i) {
        const scenes::BodyState3 s = sim.body_state(i);
        if (!finite3(s.position) || !finite3(s.linear_velocity)) {
          ++nan;
          continue;
        }
        const double d = (s.position - at_snap[i]).norm();
        creep = std::max(creep, d);
        if (slept[i]) sleeper_drift = std::max(sleeper_drift, d);
        awake_end += !sim.body_asleep(i);
      }
    }
  }
  add(printf_string("long run %.0f s, 1000 bunnies", T), "statistical",
      nan == 0 && sleeper_drift <= 1e-6 && hashes[0] == hashes[1],
      printf_string("non-finite %d, drift of sleepers %.3g m, largest move since %.0f s %.3g m, awake at end %zu, hashes "
          "%016llx %s, %.3f ms/step",
          nan, sleeper_drift, snapshot, creep, awake_end, static_cast<unsigned long long>(hashes[0]),
          hashes[0] == hashes[1] ? "equal" : "DIFFER", ms),
      "no non-finite state, bodies asleep since 60 s moved <= 1e-6 m, equal final state hash on two runs");
}

// 10. mass ratio ---------------------------------------------------------------------------------------
// A column of three cubes of 0.2 m placed face to face on the ground, the top one 1000 times as
// heavy as the two below: it must stand as the same column of equal masses does (with each
// method's own idea of how tall that is), asleep, the bottom cube not driven into the ground.
void Matrix::mass_ratio()
{
  const Body3 box = bench::load_body3("box", dir_);
  const std::shared_ptr<bench::BulletShapes> shapes = bench::make_bullet_shapes(box);
  const SignatureView<3> sig = tables::box.view();
  const double half = box.boxes.at(0).half_extents.z(), ratio = 1000, dt = 1.0 / 60, T = 10;
  const int n = 3;
  std::vector<scenes::BodyState3> states(n);
  for (int i = 0; i < n; ++i) states[i].position = Eigen::Vector3d(0, 0, half * (2 * i + 1));
  const std::string name = printf_string("mass ratio %.0f, column of 3 cubes", ratio);
  const std::string criterion = printf_string("after %.0f s: top within 2%% of its height with equal masses, all asleep, "
                                    "bottom centre >= 0.5 half side above the ground",
                                    T);
  for (const std::string& m : methods3()) {
    double top[2] = {0, 0}, bottom = 0;
    std::size_t asleep = 0;
    bool finite = true;
    for (int r = 0; r < 2; ++r) {
      Setup3 setup;
      setup.signature = &sig;
      setup.mass_scale = {1, 1, r == 1 ? ratio : 1};
      std::unique_ptr<bench::Sim> sim;
      try {
        sim = make_sim3(box, shapes, m, with_contacts(setup), states, dt);
      } catch (const std::runtime_error&) {
        break;  // the box has no such Bullet representation
      }
      for (long k = 0; k < std::lround(T / dt); ++k) sim->step();
      for (int i = 0; i < n; ++i) finite = finite && finite3(sim->body_state(std::size_t(i)).position);
      top[r] = sim->body_state(n - 1).position.z();
      if (r == 1) {
        bottom = sim->body_state(0).position.z();
        asleep = sim->asleep();
      }
    }
    if (top[0] == 0) continue;
    const bool pass = finite && std::fabs(top[1] - top[0]) <= 0.02 * top[0] && asleep == std::size_t(n) &&
                      bottom >= 0.5 * half;
    add(name, m, pass,
        printf_string("top %.3f m (equal masses %.3f m, %+.1f%%), bottom %.3f m, asleep %zu/%d%s", top[1], top[0],
            100 * (top[1] / top[0] - 1), bottom, asleep, n, finite ? "" : ", NON-FINITE"),
        criterion);
  }
}

// 10. spawn and remove --------------------------------------------------------------------------------
// An hour of simulated time (--quick: 10 minutes) in which every step removes a random body of a
// small walled pile and drops a new one onto it, and tries ids removed earlier. statsim only (the
// Bullet methods have no row): it is the id and slot bookkeeping that is under test. Each removal
// advances its slot's generation; a slot is retired after 4095 (`retired_generation`), so the
// world needs room for the live bodies plus the slots retired in the run.
void Matrix::spawn_remove()
{
  if (!want("statistical")) return;
  constexpr std::uint32_t kCap = 256;
  using W = World3<kCap, 8, kCap * 32, 2>;
  const int live_target = 24;
  const double dt = 1.0 / 60, settle_s = 20, hours = opt_.quick ? 1.0 / 6 : 1.0;
  const long steps = std::lround(hours * 3600 / dt);
  WorldDef3 def;
  def.body_contacts = contacts();
  def.ground_hulls = ground_hulls();
  auto w = std::make_unique<W>(def);
  const Added<ShapeId> shape = w->add_shape(tables::bunny.view());
  const Scalar r = Scalar(R()), wall = 4 * r;
  bool set_up = shape.ok() && w->add_plane(Vector3(0, 0, 1), 0).ok();
  for (const Vector3& n : {Vector3(1, 0, 0), Vector3(-1, 0, 0), Vector3(0, 1, 0), Vector3(0, -1, 0)})
    set_up = set_up && w->add_plane(n, -wall).ok();
  if (!set_up) throw std::runtime_error("spawn-remove: set-up failed");
  // Above the pile of 24 (about 5 R high), where no body is: a body dropped every step at one
  // height would land in the one dropped a step before (it has fallen g dt^2 / 2, 1.4 mm).
  const Scalar drop_low = 10 * r, drop = 18 * r;
  Pcg32 g(2026, 1);
  scenes::SceneRng qrng(2026);
  std::vector<BodyId> live, stale;
  long add_failures = 0, remove_failures = 0, stale_accepted = 0, stale_tries = 0, non_finite = 0, no_room = 0;
  const auto spawn = [&](Scalar z) {
    BodyDef3 b;
    b.shape = shape.id;
    for (int tries = 0; tries < 100; ++tries) {
      b.position = Vector3(g.uniform(-wall + r, wall - r), g.uniform(-wall + r, wall - r),
                           z > 0 ? z : g.uniform(drop_low, drop));
      bool free = true;
      // Collision spheres apart: a query of radius R (>= the new body's) about the new centre.
      if (overlap_sphere(*w, b.position, r, [&free](const QueryHit<3>& h) { return free = h.body == no_body; }) !=
          Status::ok)
        free = false;
      if (free) break;
      if (tries == 99) ++no_room;
    }
    b.orientation = random_q(qrng).cast<Scalar>();
    const Added<BodyId> a = w->add_body(b);
    if (a.ok()) live.push_back(a.id);
    else add_failures += a.status == Status::capacity_exceeded && w->live_body_count() < kCap;
  };
  for (int i = 0; i < live_target; ++i) spawn(r * Scalar(2 + 2 * i));
  // The first pile is a column released from up to 48 R, higher than any later drop: it settles
  // before the hour begins, so that the speed bound is that of the drops the hour makes.
  for (long k = 0; k < std::lround(settle_s / dt); ++k)
    if (w->step(Scalar(dt)).status != Status::ok) ++non_finite;
  double vmax = 0;
  std::uint32_t slots_used = 0;
  const auto check = [&]() {
    for (std::uint32_t i = 0; i < w->body_count(); ++i) {
      if (w->id_of(i) == no_body) continue;
      const Body<3>& b = detail::CoreAccess::data(*w).bodies[i];
      const double v = double(b.linear_velocity.norm());
      if (!std::isfinite(v) || !finite3(b.position.cast<double>())) ++non_finite;
      else vmax = std::max(vmax, v);
    }
  };
  const Clock::time_point t0 = Clock::now();
  for (long k = 0; k < steps; ++k) {
    const std::size_t at = g.next_u32() % live.size();
    if (w->remove_body(live[at]) != Status::ok) ++remove_failures;
    stale.push_back(live[at]);
    live[at] = live.back();
    live.pop_back();
    spawn(0);
    // A removed id, from any time in the run, stays refused (also once its slot is reused).
    const BodyId old = stale[g.next_u32() % stale.size()];
    ++stale_tries;
    stale_accepted += w->alive(old) || w->remove_body(old) != Status::invalid_body ||
                      w->set_velocity(old, Vector3::Zero(), Vector3::Zero()) != Status::invalid_body;
    if (w->step(Scalar(dt)).status != Status::ok) ++non_finite;
    check();
    slots_used = std::max(slots_used, w->body_count());
  }
  const double run_s = seconds_since(t0);
  for (long k = 0; k < std::lround(settle_s / dt); ++k)
    if (w->step(Scalar(dt)).status != Status::ok) ++non_finite;
  check();
  std::uint32_t retired = 0;
  for (std::uint32_t i = 0; i < w->body_count(); ++i) retired += detail::CoreAccess::data(*w).slots.generation[i] == detail::retired_generation;
  std::size_t asleep = 0, n = 0;
  double overlap = 0, lowest = kInf;
  for (std::uint32_t i = 0; i < w->body_count(); ++i) {
    if (w->id_of(i) == no_body) continue;
    const Body<3>& a = detail::CoreAccess::data(*w).bodies[i];
    ++n;
    asleep += a.state == MotionState::asleep;
    lowest = std::min(lowest, double(a.position.z() - a.radius) / R());
    for (std::uint32_t j = i + 1; j < w->body_count(); ++j) {
      if (w->id_of(j) == no_body) continue;
      const Body<3>& b = detail::CoreAccess::data(*w).bodies[j];
      const double sum = double(a.radius) + double(b.radius);
      overlap = std::max(overlap, (sum - double((a.position - b.position).norm())) / sum);
    }
  }
  const double vbound = 1.25 * (std::sqrt(2 * kG * double(drop)) + kG * dt);
  const bool pass = add_failures == 0 && remove_failures == 0 && no_room == 0 && stale_accepted == 0 && non_finite == 0 && n == std::size_t(live_target) &&
                    vmax <= vbound && asleep * 100 >= 95 * n && overlap <= 0.2 && lowest >= -0.1;
  add(printf_string("spawn-remove %.0f min, pile of %d bunnies", hours * 60, live_target), "statistical", pass,
      printf_string("%ld removals; slots used %u of %u, %u retired (%.0f per hour); add/remove failures %ld/%ld; no room %ld; stale ids accepted "
          "%ld/%ld; non-finite %ld; max speed %.2f m/s; after %.0f s: asleep %zu/%zu, max sphere overlap %.1f%%, "
          "lowest sphere point %+.3f R; %.1f s",
          steps, slots_used, kCap, retired, retired / hours, add_failures, remove_failures, no_room, stale_accepted, stale_tries, non_finite,
          vmax, settle_s, asleep, n, 100 * overlap, lowest, run_s),
      printf_string("every step one body removed and one dropped from %.2f to %.2f m clear of collision spheres, in a "
          "%u-slot world: no add_body failure "
          "while live < capacity, every stale id refused, no non-finite state, max speed <= 1.25 (free-fall "
          "speed + g dt) = %.2f m/s; %.0f s after the last drop: asleep >= 95%%, max sphere overlap <= 20%% of "
          "the radius sum, no sphere below the ground by more than 0.1 R",
          double(drop_low), double(drop), kCap, vbound, settle_s));
}

}  // namespace statsim::tools::stress
