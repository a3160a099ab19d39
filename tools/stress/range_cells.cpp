// Stress cells beyond the tables' range: states out of range, bad input through the public API,
// bodies from 1 cm to 10 m.
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

// 11. sizes ---------------------------------------------------------------------------------------------
/// `body` `s` times its size: lengths times s, mass (same density) s^3, inertia s^5.
Body3 scaled_body(const Body3& body, double s)
{
  Body3 b = body;
  for (auto& v : b.full_vertices) v *= s;
  for (auto& v : b.low_vertices) v *= s;
  for (auto& sp : b.spheres) sp *= s;  // centre and radius
  for (auto& box : b.boxes) {
    box.centre *= s;
    box.half_extents *= s;
  }
  b.bounding_radius *= s;
  b.sphere_radius *= s;
  b.mass *= s * s * s;
  b.inertia *= s * s * s * s * s;
  return b;
}

// 7. bad input -----------------------------------------------------------------------------------------
template <int D>
void bad_input_dim(Matrix& mx, const SignatureView<D>& sig, const char* method)
{
  using Vec = typename Space<D>::Vec;
  using Rot = typename Space<D>::Rot;
  const Scalar nan = std::numeric_limits<Scalar>::quiet_NaN(), inf = std::numeric_limits<Scalar>::infinity();
  const auto make = [&sig](World<D, 4, 2, 16, 2>& w) {
    const auto shape = w.add_shape(sig);
    bool set_up = shape.ok() && w.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok();
    for (int i = 0; i < 3; ++i) {
      BodyDef<D> b;
      b.shape = shape.id;
      b.position = Vec::Unit(Space<D>::up_axis) * Scalar(1 + i);
      set_up = set_up && w.add_body(b).ok();
    }
    if (!set_up || w.step(Scalar(1) / 60).status != Status::ok) throw std::runtime_error("bad input: scene set-up failed");
  };
  Rot zero_q, long_q;
  if constexpr (D == 3) {
    zero_q = Quaternion(0, 0, 0, 0);
    long_q = Quaternion(1.01f, 0, 0, 0);
  } else {
    zero_q = Rot2{0, 0};
    long_q = Rot2{1.01f, 0};
  }
  struct Case {
    const char* name;
    Status expected;
    std::function<Status(World<D, 4, 2, 16, 2>&)> call;
  };
  const auto body_with = [](auto edit) {
    return [edit](World<D, 4, 2, 16, 2>& w) {
      BodyDef<D> b;
      b.position = Vec::Unit(Space<D>::up_axis);
      edit(b);
      return w.add_body(b).status;
    };
  };
  std::vector<Case> cases = {
      {"NaN position", Status::non_finite, body_with([&](BodyDef<D>& b) { b.position[0] = nan; })},
      {"infinite position", Status::non_finite, body_with([&](BodyDef<D>& b) { b.position[1] = inf; })},
      {"NaN velocity", Status::non_finite, body_with([&](BodyDef<D>& b) { b.linear_velocity[0] = nan; })},
      {"infinite velocity", Status::non_finite, body_with([&](BodyDef<D>& b) { b.linear_velocity[0] = -inf; })},
      {"zero quaternion", Status::zero_quaternion, body_with([&](BodyDef<D>& b) { b.orientation = zero_q; })},
      {"non-unit quaternion (1.01)", Status::non_unit_quaternion,
       body_with([&](BodyDef<D>& b) { b.orientation = long_q; })},
      {"negative mass", Status::invalid_mass, body_with([](BodyDef<D>& b) { b.mass = -1; })},
      {"unknown shape", Status::invalid_shape, body_with([](BodyDef<D>& b) { b.shape = ShapeId(7); })},
      {"position beyond limits (1e7 m)", Status::out_of_range,
       body_with([](BodyDef<D>& b) { b.position[0] = Scalar(1e7); })},
      {"adding past capacity", Status::capacity_exceeded,
       [](World<D, 4, 2, 16, 2>& w) {
         BodyDef<D> b;
         b.position = Vec::Unit(Space<D>::up_axis) * Scalar(5);
         (void)w.add_body(b);  // the 4th body fills the pool; the call under test is the next one
         return w.add_body(b).status;
       }},
      {"zero dt", Status::invalid_time_step, [](World<D, 4, 2, 16, 2>& w) { return w.step(0).status; }},
      {"negative dt", Status::invalid_time_step,
       [](World<D, 4, 2, 16, 2>& w) { return w.step(-Scalar(1) / 60).status; }},
      {"NaN dt", Status::invalid_time_step, [&](World<D, 4, 2, 16, 2>& w) { return w.step(nan).status; }},
      {"infinite dt", Status::invalid_time_step, [&](World<D, 4, 2, 16, 2>& w) { return w.step(inf).status; }},
      {"plane with zero normal", Status::invalid_plane,
       [](World<D, 4, 2, 16, 2>& w) { return w.add_plane(Vec::Zero(), 0).status; }},
      {"plane with NaN normal", Status::invalid_plane,
       [&](World<D, 4, 2, 16, 2>& w) { return w.add_plane(Vec::Constant(nan), 0).status; }},
      {"set_velocity NaN", Status::non_finite,
       [&](World<D, 4, 2, 16, 2>& w) { return w.set_velocity(0, Vec::Constant(nan), Space<D>::zero_spin()); }},
      {"set_transform zero quaternion", Status::zero_quaternion,
       [&](World<D, 4, 2, 16, 2>& w) { return w.set_transform(0, Vec::Unit(Space<D>::up_axis), zero_q); }},
      {"set_velocity unknown body", Status::invalid_body,
       [](World<D, 4, 2, 16, 2>& w) { return w.set_velocity(9, Vec::Zero(), Space<D>::zero_spin()); }},
  };
  for (const Case& c : cases) {
    auto w = std::make_unique<World<D, 4, 2, 16, 2>>();
    make(*w);
    // "Adding past capacity" fills the pool first; compare against the world just before the
    // rejected call.
    std::uint64_t before = w->state_hash();
    std::uint32_t bodies = w->body_count(), planes = w->plane_count();
    Status got;
    if (std::string(c.name) == "adding past capacity") {
      BodyDef<D> b;
      b.position = Vec::Unit(Space<D>::up_axis) * Scalar(5);
      (void)w->add_body(b);  // fills the pool; the call under test is the next one
      before = w->state_hash();
      bodies = w->body_count();
      BodyDef<D> b2 = b;
      got = w->add_body(b2).status;
    } else {
      got = c.call(*w);
    }
    const bool unchanged = w->state_hash() == before && w->body_count() == bodies && w->plane_count() == planes;
    mx.add(std::string("bad input: ") + c.name, method, got == c.expected && unchanged,
           printf_string("%s, world %s", to_string(got), unchanged ? "unchanged" : "CHANGED"),
           std::string("rejected with ") + to_string(c.expected) + ", state hash and counts unchanged");
  }
}

}  // namespace

// 5. out-of-range states -------------------------------------------------------------------------------
void Matrix::out_of_range()
{
  const SignatureView<3> sig = tables::bunny.view();
  const double s_max = double(sig.height.spin_ratio.values[sig.height.spin_ratio.size - 1]);
  const double L = double(sig.length);
  struct Case {
    std::string name;
    std::vector<scenes::BodyState3> states;
    double T;
    double speed_bound;
    bool at_rest;
    bool energy = false;  ///< judge by total energy (kinetic with spin + potential), not speed
  };
  std::vector<Case> cases;
  scenes::SceneRng rng(31);
  {
    // Speed 10x the fastest impacts of the drop scenes (~10 m/s), spin ratio 100x the table's last.
    Case c{"spin 100x, speed 10x", {}, 3.0, 0, false};
    const double v = 100, w = 100 * s_max * v / L;
    for (int i = 0; i < 9; ++i) {
      scenes::BodyState3 s;
      s.position = Eigen::Vector3d((i % 3 - 1) * 6 * R(), (i / 3 - 1) * 6 * R(), 1.0);
      s.orientation = random_q(rng);
      const Eigen::Vector3d dir = Eigen::Vector3d(rng.uniform(-1, 1), rng.uniform(-1, 1), -1).normalized();
      s.linear_velocity = v * dir;
      s.angular_velocity = w * Eigen::Vector3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)).normalized();
      c.states.push_back(s);
    }
    c.speed_bound = v + kG * c.T;
    c.energy = true;  // a spinning body may rightly turn spin into speed at an impact
    c.name += printf_string(" (|v| = %.0f m/s, |w| = %.3g rad/s)", v, w);
    cases.push_back(c);
  }
  {
    Case c{"interpenetrating start (27 at 0.3 R spacing)", {}, 5.0, 0, false};
    for (int i = 0; i < 27; ++i) {
      scenes::BodyState3 s;
      s.position = Eigen::Vector3d((i % 3 - 1) * 0.3 * R(), (i / 3 % 3 - 1) * 0.3 * R(), 1.0 + (i / 9 - 1) * 0.3 * R());
      s.orientation = random_q(rng);
      c.states.push_back(s);
    }
    c.speed_bound = std::sqrt(2 * kG * 1.2) + 2;
    cases.push_back(c);
  }
  {
    Case c{"exactly at rest on the ground (each rest pose)", {}, 10.0, 2.0, true};
    for (std::uint32_t k = 0; k < sig.rest.count; ++k) {
      scenes::BodyState3 s;
      const Eigen::Vector3d n = sig.rest.normal(k).cast<double>().normalized();
      s.orientation = Eigen::Quaterniond::FromTwoVectors(n, Eigen::Vector3d::UnitZ());
      s.position = Eigen::Vector3d((double(k) - 2) * 5 * R(), 0, 0);  // z per method below
      c.states.push_back(s);
    }
    cases.push_back(c);
  }
  {
    Case c{"two bodies at the same position (x2)", {}, 5.0, 0, false};
    scenes::BodyState3 a;
    a.position = Eigen::Vector3d(0, 0, 1);
    a.orientation = random_q(rng);
    scenes::BodyState3 b = a;
    b.position = Eigen::Vector3d(1, 0, 0.1);
    c.states = {a, a, b, b};
    c.speed_bound = std::sqrt(2 * kG * 1.2) + 2;
    cases.push_back(c);
  }
  const double dt = 1.0 / 60;
  for (Case& c : cases) {
    for (const std::string& m : methods3()) {
      std::vector<scenes::BodyState3> states = c.states;
      if (c.at_rest)
        for (std::size_t k = 0; k < states.size(); ++k)
          states[k].position.z() = m == "statistical" ? double(sig.rest.heights[k])
                                                      : -bench::lowest_offset(body_, m, states[k].orientation);
      auto sim = sim3(m, Setup3{}, states, dt);
      const int steps = static_cast<int>(std::lround(c.T / dt));
      double vmax = 0, displaced = 0;
      const double mass = m == "statistical" ? double(sig.mass) : body_.mass;
      const auto total_energy = [&]() {
        double e = sim->kinetic_energy();
        for (std::size_t i = 0; i < sim->body_count(); ++i) e += mass * kG * sim->body_state(i).position.z();
        return e;
      };
      const double e0 = total_energy();
      double emax = e0;
      int nan = 0;
      for (int k = 0; k < steps; ++k) {
        sim->step();
        vmax = max_speed(*sim, vmax);
        if (c.energy) {
          const double e = total_energy();
          emax = std::isfinite(e) ? std::max(emax, e) : kInf;
        }
      }
      int lost = 0;
      for (std::size_t i = 0; i < sim->body_count(); ++i) {
        const scenes::BodyState3 s = sim->body_state(i);
        const bool bad = !finite3(s.position) || !finite3(s.linear_velocity) || !finite3(s.angular_velocity) ||
                         !std::isfinite(s.orientation.norm());
        nan += bad;
        lost += !bad && s.position.z() < -R();
        if (!bad) displaced = std::max(displaced, (s.position - states[i].position).norm());
      }
      std::string figure = printf_string("non-finite %d, lost %d, max speed %.3g m/s", nan, lost, vmax);
      std::string criterion = printf_string("no non-finite state, nothing below the ground, max speed <= %.3g m/s",
                                  c.speed_bound);
      bool pass = nan == 0 && lost == 0 && vmax <= c.speed_bound;
      if (c.energy) {
        figure += printf_string(", total energy max %+.3g%% of its start %.4g J", 100 * (emax / e0 - 1), e0);
        criterion = "no non-finite state, nothing below the ground, total energy (kinetic with spin + potential) "
                    "never above its start (+0.1%)";
        pass = nan == 0 && lost == 0 && emax <= e0 * 1.001;
      }
      if (c.at_rest) {
        figure += printf_string(", final displacement %.2f cm", 100 * displaced);
        criterion += ", final displacement <= 0.25 R";
        pass = pass && displaced <= 0.25 * R();
      }
      if (c.name.rfind("two bodies", 0) == 0) {
        const double sep1 = (sim->body_state(0).position - sim->body_state(1).position).norm();
        const double sep2 = (sim->body_state(2).position - sim->body_state(3).position).norm();
        figure += printf_string(", final separations %.3f and %.3f m", sep1, sep2);
      }
      add("out of range: " + c.name, m, pass, figure, criterion);
    }
  }
}

// The bunny and the box at 1 cm, 10 cm, 1 m and 10 m (bounding diameter), their tables scaled
// with `scaled_view` (what `add_shape(sig, scale)` adds) and Bullet's shapes from the scaled
// meshes: 27 bodies dropped into a walled square, the scene scaled with them (gravity unchanged;
// drop speeds by sqrt(s) and spins by 1/sqrt(s), so the drop looks the same in units of the body's
// size and sqrt(size / g); the run 20 sqrt(s) s long). The criteria are in those units too.
void Matrix::sizes()
{
  const double dt = 1.0 / 60;
  for (const char* name : {"bunny", "box"}) {
    const Body3 base = std::string(name) == "bunny" ? body_ : bench::load_body3("box", dir_);
    const SignatureView<3> table = std::string(name) == "bunny" ? tables::bunny.view() : tables::box.view();
    for (const double size : {0.01, 0.1, 1.0, 10.0}) {
      const double s = size / (2 * base.bounding_radius);
      const Body3 body = scaled_body(base, s);
      const SignatureView<3> sig = scaled_view(table, Scalar(s));
      const double R = body.bounding_radius, T = 20 * std::sqrt(s);
      scenes::DropOptions o;
      o.count = 27;
      o.bounding_radius = R;
      o.max_speed = 0.5 * std::sqrt(s);
      o.max_spin = 2 / std::sqrt(s);
      const scenes::DropScene3 scene = scenes::drop_scene3(o);
      double top = 0, v0 = 0;
      for (const auto& st : scene.bodies) {
        top = std::max(top, st.position.z());
        v0 = std::max(v0, st.linear_velocity.norm());
      }
      const double vbound = 1.25 * (std::sqrt(v0 * v0 + 2 * kG * top) + kG * dt);
      Setup3 setup;
      setup.signature = &sig;
      const double wall = scene.region.radius + R;
      setup.planes.push_back({Eigen::Vector3d(1, 0, 0), -wall});
      setup.planes.push_back({Eigen::Vector3d(-1, 0, 0), -wall});
      setup.planes.push_back({Eigen::Vector3d(0, 1, 0), -wall});
      setup.planes.push_back({Eigen::Vector3d(0, -1, 0), -wall});
      const std::shared_ptr<bench::BulletShapes> shapes = bench::make_bullet_shapes(body);
      const std::string scene_name = printf_string("size %g m %s, 27 dropped", size, name);
      for (const std::string& m : methods3()) {
        const bool stat = m == "statistical";
        std::unique_ptr<bench::Sim> sim;
        try {
          sim = make_sim3(body, shapes, m, with_contacts(setup), scene.bodies, dt);
        } catch (const std::runtime_error&) {
          continue;  // no such Bullet representation of the shape
        }
        const long steps = std::lround(T / dt);
        double vmax = 0, overlap = 0, lowest = kInf;
        const Clock::time_point t0 = Clock::now();
        long done = 0;
        for (long k = 0; k < steps; ++k, ++done) {
          if (!stat && seconds_since(t0) > budget()) break;
          sim->step();
          vmax = max_speed(*sim, vmax);
          if (double(k) * dt > T - 5 * std::sqrt(s) && k % 30 == 0) overlap = std::max(overlap, sim->overlap());
        }
        std::size_t asleep = 0;
        for (std::size_t i = 0; i < sim->body_count(); ++i) {
          asleep += sim->body_asleep(i);
          lowest = std::min(lowest, sim->lowest(i) / R);
        }
        const double over = stat ? overlap : overlap / R;  // statsim: of the radius sum; others: depth / R
        const bool pass =
            done == steps && asleep == sim->body_count() && over <= 0.2 && lowest >= -0.1 && vmax <= vbound;
        add(scene_name, m, pass,
            printf_string("asleep %zu/%zu, max overlap %.1f%% (last %.1f s), lowest point %+.3f R, max speed %.2f m/s "
                "(bound %.2f)%s",
                asleep, sim->body_count(), 100 * over, 5 * std::sqrt(s), lowest, vmax, vbound,
                done < steps ? printf_string("; stopped at %.1f s simulated (budget %.0f s wall)", double(done) * dt, budget()).c_str()
                             : ""),
            printf_string("after %.1f s: all asleep, max overlap <= 20%% (%s), lowest point >= -0.1 R, max speed <= 1.25 "
                "(free-fall speed + g dt)",
                T, stat ? "of the collision radius sum" : "penetration over R"));
      }
    }
  }
}

void Matrix::bad_input()
{
  if (want("statistical")) bad_input_dim<3>(*this, tables::bunny.view(), "statistical");
  if (want("statistical2d")) bad_input_dim<2>(*this, tables::square2d.view(), "statistical2d");
}

}  // namespace statsim::tools::stress
