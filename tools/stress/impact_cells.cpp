// Stress cells of impacts and time steps: fast impacts, a large time step, small time steps.
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

// 1. fast impact ---------------------------------------------------------------------------------------
void Matrix::fast_impact()
{
  const int side = opt_.quick ? 3 : 5;
  const double dt = 1.0 / 60, T = 1.5;
  const int steps = static_cast<int>(std::lround(T / dt));
  for (const double speed : {5.0, 20.0, 50.0}) {
    const std::string scene = printf_string("fast impact %.0f m/s", speed);
    // Tunnelled: the centre ever more than R below the ground, or below it at the end.
    const std::string criterion = printf_string("tunnelled (centre ever below -R, or below 0 at the end) = 0 and max "
                                      "penetration <= 0.25 R (%.1f cm)",
                                      25 * R());
    std::vector<scenes::BodyState3> states;
    scenes::SceneRng rng(11);
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j) {
        scenes::BodyState3 s;
        s.position = Eigen::Vector3d((i - (side - 1) / 2.0) * 5 * R(), (j - (side - 1) / 2.0) * 5 * R(), 0.5);
        s.orientation = random_q(rng);
        s.linear_velocity = Eigen::Vector3d(0, 0, -speed);
        s.angular_velocity = Eigen::Vector3d(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
        states.push_back(s);
      }
    for (const std::string& m : methods3()) {
      auto sim = sim3(m, Setup3{}, states, dt);
      double pen = 0;
      std::vector<bool> through(states.size(), false);
      for (int k = 0; k < steps; ++k) {
        sim->step();
        for (std::size_t i = 0; i < sim->body_count(); ++i) {
          pen = std::max(pen, -sim->lowest(i));
          const Eigen::Vector3d x = sim->body_state(i).position;
          if (!finite3(x) || x.z() < -R()) through[i] = true;
        }
      }
      int tunnelled = 0;
      for (std::size_t i = 0; i < sim->body_count(); ++i)
        tunnelled += through[i] || sim->body_state(i).position.z() < 0;
      add(scene, m, tunnelled == 0 && pen <= 0.25 * R(),
          printf_string("tunnelled %d/%zu, max penetration %.1f cm", tunnelled, states.size(), 100 * pen), criterion);
    }
    // 2D: unit squares (R = 0.707 m).
    std::vector<scenes::BodyState2> states2;
    for (int i = 0; i < side; ++i) {
      scenes::BodyState2 s;
      s.position = Eigen::Vector2d((i - (side - 1) / 2.0) * 3.0, 1.5);
      s.angle = rng.uniform(0, 6.283185307179586);
      s.linear_velocity = Eigen::Vector2d(0, -speed);
      s.angular_velocity = rng.uniform(-2, 2);
      states2.push_back(s);
    }
    const double r2 = 0.70710678118654752;
    for (const std::string& m : kMethods2) {
      if (!want(m)) continue;
      std::unique_ptr<Sim2> sim;
      if (m == "polygon")
        sim = std::make_unique<Box2dSim>(states2, double(tables::square2d.mass),
                                         double(tables::square2d.material.restitution),
                                         double(tables::square2d.material.friction));
      else
        sim = std::make_unique<StatsimSim2>(states2, contacts(), ground_hulls());
      double pen = 0;
      std::vector<bool> through(states2.size(), false);
      for (int k = 0; k < steps; ++k) {
        sim->step(dt);
        for (std::size_t i = 0; i < sim->size(); ++i) {
          const State2 s = sim->state(i);
          pen = std::max(pen, -s.lowest);
          if (!std::isfinite(s.x.y()) || s.x.y() < -r2) through[i] = true;
        }
      }
      int tunnelled = 0;
      for (std::size_t i = 0; i < sim->size(); ++i) tunnelled += through[i] || sim->state(i).x.y() < 0;
      add(scene + " (2D)", m, tunnelled == 0 && pen <= 0.25 * r2,
          printf_string("tunnelled %d/%zu, max penetration %.1f cm", tunnelled, states2.size(), 100 * pen),
          printf_string("tunnelled (centre ever below -R, or below 0 at the end) = 0 and max penetration <= 0.25 R "
              "(%.1f cm)",
              25 * r2));
    }
  }
}

// 2. large time step -----------------------------------------------------------------------------------
void Matrix::large_time_step()
{
  scenes::DropOptions o;
  o.count = 50;
  o.bounding_radius = R();
  const scenes::DropScene3 scene = scenes::drop_scene3(o);
  double top = 0, v0 = 0;
  for (const auto& s : scene.bodies) {
    top = std::max(top, s.position.z());
    v0 = std::max(v0, s.linear_velocity.norm());
  }
  for (const double hz : {30.0, 15.0}) {
    const double dt = 1 / hz, T = 10;
    const int steps = static_cast<int>(std::lround(T / dt));
    const double bound = 1.25 * (std::sqrt(v0 * v0 + 2 * kG * top) + kG * dt);
    const std::string name = printf_string("large dt 1/%.0f, 50-bunny drop", hz);
    const std::string criterion =
        printf_string("lost = 0 and max speed <= 1.25 (free-fall speed + g dt) = %.1f m/s", bound);
    for (const std::string& m : methods3()) {
      auto sim = sim3(m, Setup3{}, scene.bodies, dt);
      double vmax = 0;
      for (int k = 0; k < steps; ++k) {
        sim->step();
        vmax = max_speed(*sim, vmax);
      }
      int lost = 0;
      for (std::size_t i = 0; i < sim->body_count(); ++i) {
        const Eigen::Vector3d x = sim->body_state(i).position;
        lost += !finite3(x) || x.z() < -R() || std::fabs(x.x()) > 50 || std::fabs(x.y()) > 50;
      }
      add(name, m, lost == 0 && vmax <= bound, printf_string("max speed %.2f m/s, lost %d/50", vmax, lost), criterion);
    }
  }
}

// 9. small time steps ----------------------------------------------------------------------------------
// The 50-bunny drop of the large-step scene at 240 and 1000 Hz: what depends on dt (sleep by the
// distance moved in a step, thresholds against |g| dt, the shock pass's corrections) must still
// bring the bodies to rest, in the ground's reach.
void Matrix::small_time_step()
{
  scenes::DropOptions o;
  o.count = 50;
  o.bounding_radius = R();
  const scenes::DropScene3 scene = scenes::drop_scene3(o);
  for (const double hz : {240.0, 1000.0}) {
    const double dt = 1 / hz, T = 10;
    const long steps = std::lround(T / dt);
    const std::string name = printf_string("small dt 1/%.0f, 50-bunny drop, 10 s", hz);
    const std::string criterion = printf_string("lost = 0, asleep >= 95%% at the end, deepest point of the method's "
                                      "geometry below the ground <= 0.25 R (%.1f cm) after each step",
                                      25 * R());
    for (const std::string& m : methods3()) {
      const Clock::time_point t0 = Clock::now();
      auto sim = sim3(m, Setup3{}, scene.bodies, dt);
      double pen = 0;
      long done = 0;
      for (; done < steps; ++done) {
        sim->step();
        for (std::size_t i = 0; i < sim->body_count(); ++i) pen = std::max(pen, -sim->lowest(i));
        if (m != "statistical" && seconds_since(t0) > budget()) {
          ++done;
          break;
        }
      }
      int lost = 0;
      for (std::size_t i = 0; i < sim->body_count(); ++i) {
        const Eigen::Vector3d x = sim->body_state(i).position;
        lost += !finite3(x) || x.z() < -R() || std::fabs(x.x()) > 50 || std::fabs(x.y()) > 50;
      }
      const double asleep = double(sim->asleep()) / double(sim->body_count());
      std::string figure = printf_string("lost %d/50, asleep %.0f%%, deepest %.2f cm", lost, 100 * asleep, 100 * pen);
      bool pass = lost == 0 && asleep >= 0.95 && pen <= 0.25 * R();
      if (done < steps) {
        figure += printf_string("; stopped at %.1f s simulated (budget %.0f s wall)", double(done) * dt, budget());
        pass = false;
      }
      add(name, m, pass, figure, criterion);
    }
  }
}

}  // namespace statsim::tools::stress
