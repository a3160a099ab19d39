// Single drops of `statsim fidelity`: each run's initial state, the run to rest in one method,
// and its rest configuration, travel, bounces and first-collision state.
#include "fidelity/stages.hpp"
#include "statsim/world_def.hpp"

#include <algorithm>
#include <cmath>

namespace statsim::tools::fidelity {

namespace {

constexpr double kGravity = 9.81;
constexpr double kOtherDegrees = 15.0;

}  // namespace

int classify(const Eigen::Quaterniond& q, const SignatureView<3>& sig)
{
  const Eigen::Vector3d up = q.normalized().toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ();
  const double cos_other = std::cos(kOtherDegrees * M_PI / 180.0);
  int best = -1;
  double best_dot = -2;
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    const Eigen::Vector3d n(double(sig.rest.normals[3 * i]), double(sig.rest.normals[3 * i + 1]),
                            double(sig.rest.normals[3 * i + 2]));
    const double d = up.dot(n.normalized());
    if (d > best_dot) best_dot = d, best = static_cast<int>(i);
  }
  return best >= 0 && best_dot >= cos_other ? best : static_cast<int>(sig.rest.count);
}

scenes::BodyState3 drop_state(std::uint64_t stream, double radius)
{
  scenes::SceneRng rng(stream);
  double w, x, y, z, n2;
  do {
    w = rng.uniform(-1, 1), x = rng.uniform(-1, 1), y = rng.uniform(-1, 1), z = rng.uniform(-1, 1);
    n2 = w * w + x * x + y * y + z * z;
  } while (n2 > 1 || n2 < 1e-6);
  const double inv = 1.0 / std::sqrt(n2);
  scenes::BodyState3 s;
  s.orientation = Eigen::Quaterniond(w * inv, x * inv, y * inv, z * inv);
  s.angular_velocity = Eigen::Vector3d(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
  s.linear_velocity = Eigen::Vector3d(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), 0.0);
  s.position = Eigen::Vector3d(0, 0, rng.uniform(radius + 0.2, radius + 1.0));
  return s;
}

double speed(const scenes::BodyState3& s, double radius)
{
  return std::max(s.linear_velocity.norm(), s.angular_velocity.norm() * radius);
}

DropRun run_single(const Setup& setup, const MethodSpec& m, std::uint64_t stream, double dt, double limit,
                   std::uint64_t world_seed)
{
  const double R = setup.radius;
  scenes::DropScene3 scene;
  scene.options.count = 1;
  scene.options.bounding_radius = R;
  scene.bodies.push_back(drop_state(stream, R));
  scene.bounds_lo = Eigen::Vector3d(-50, -50, -1);
  scene.bounds_hi = Eigen::Vector3d(50, 50, 10);
  std::unique_ptr<bench::Sim> sim = build(setup, m, scene, world_seed, dt);

  DropRun out;
  const scenes::BodyState3 start = scene.bodies[0];
  scenes::BodyState3 s = sim->body_state(0);
  const double hysteresis = std::max(0.01, 0.05 * R);
  FlightTop top(dt, hysteresis, kGravity);
  top.add(s.linear_velocity, s.angular_velocity);
  bool rising = false;
  double low = 0, high = 0;
  double still_since = -1, quiet_since = -1;
  const long steps = static_cast<long>(std::ceil(limit / dt - 1e-9));
  double t = 0;
  bool rested = false;
  const double settle_speed = double(WorldDef<3>{}.settle_speed);
  for (long k = 1; k <= steps; ++k) {
    sim->step();
    t = static_cast<double>(k) * dt;
    s = sim->body_state(0);
    while (t >= static_cast<double>(out.profile_speed.size() + 1) * kProfileStep - 1e-9) {
      out.profile_speed.push_back(static_cast<float>(s.linear_velocity.norm()));
      out.profile_spin.push_back(static_cast<float>(s.angular_velocity.norm() * R));
      out.profile_height.push_back(static_cast<float>(s.position.z()));
    }
    const bool contact = top.contact();
    top.add(s.linear_velocity, s.angular_velocity);
    if (!contact && top.contact()) low = s.position.z();
    if (top.contact()) {
      const double z = s.position.z();
      if (!rising) {
        low = std::min(low, z);
        if (z >= low + hysteresis) rising = true, high = z, out.bounces += 1;
      } else {
        high = std::max(high, z);
        if (z <= high - hysteresis) rising = false, low = z;
      }
    }
    if (speed(s, R) >= settle_speed) out.settle_onset = t;
    const bool asleep = sim->body_asleep(0);
    const bool quiet = speed(s, R) < kQuietSpeed;
    if (asleep || quiet) {
      if (still_since < 0) still_since = t;
    } else {
      still_since = -1;
    }
    if (quiet) {
      if (quiet_since < 0) quiet_since = t;
    } else {
      quiet_since = -1;
    }
    if (asleep || (quiet_since >= 0 && t - quiet_since >= kQuietTime - 1e-9)) {
      rested = true;
      break;
    }
  }
  out.impact = top.contact();
  out.flight = top.found();
  out.flight_speed = top.speed();
  out.flight_spin = top.spin();
  out.impact_speed = top.impact_speed();
  out.impact_spin = top.impact_spin();
  out.responses = sim->statistical_responses();
  out.clamps = sim->energy_clamps();
  out.time_limited = !rested;
  out.rest_time = rested ? still_since : t;
  out.config = classify(s.orientation, setup.poses);
  out.rest_height = s.position.z() / R;
  out.travel = std::hypot(s.position.x() - start.position.x(), s.position.y() - start.position.y());
  return out;
}


}  // namespace statsim::tools::fidelity
