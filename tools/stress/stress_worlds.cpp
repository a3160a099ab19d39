// See stress_worlds.hpp: make_sim3, the 3D world of a method.
#include "stress/stress_worlds.hpp"

#include <stdexcept>

namespace statsim::tools::stress {

std::unique_ptr<bench::Sim> make_sim3(const Body3& body, const std::shared_ptr<bench::BulletShapes>& shapes,
                                      const std::string& method, const Setup3& setup,
                                      const std::vector<scenes::BodyState3>& states, double dt)
{
  if (method == "statistical") {
    if (states.size() <= 1024) return std::make_unique<StatsimSim3<1024>>(setup, states, dt);
    return std::make_unique<StatsimSim3<16384>>(setup, states, dt);
  }
  bullet::DropSettings s = bench::bullet_drop_settings(body, method, "dbvt", scenes::DropScene3{});
  s.planes = setup.planes;
  s.gravity = setup.gravity;
  if (setup.restitution >= 0) s.restitution = setup.restitution;
  if (setup.friction >= 0) s.friction = setup.friction;
  s.sleeping = setup.sleeping;
  // Bullet's default, with which the stress figures have been recorded (the benchmark skips the
  // AABBs of sleeping bodies, which changes the broad phase's order of pairs).
  s.update_all_aabbs = true;
  if (setup.mass_scale.empty()) return bench::make_bullet(shapes, method, s, states, dt);
  // One kind of body per mass scale: the same shape, mass and inertia scaled together.
  std::vector<std::shared_ptr<bench::BulletShapes>> kinds;
  std::vector<double> scales;
  std::vector<int> of_body;
  for (const double scale : setup.mass_scale) {
    auto at = std::find(scales.begin(), scales.end(), scale);
    if (at == scales.end()) {
      Body3 scaled = body;
      scaled.mass *= scale;
      scaled.inertia *= scale;
      kinds.push_back(scale == 1.0 ? shapes : bench::make_bullet_shapes(scaled));
      scales.push_back(scale);
      at = scales.end() - 1;
    }
    of_body.push_back(static_cast<int>(at - scales.begin()));
  }
  return bench::make_bullet_mixed(kinds, of_body, method, s, states, dt);
}

}  // namespace statsim::tools::stress
