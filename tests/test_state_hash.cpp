// state_hash covers everything that determines a world's future: two worlds that would step
// differently never hash alike, even before their first step.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

using namespace statsim;

namespace {
/// A small 3D scene of plain spheres and statistical cubes, built from `def` and `ball`.
std::uint64_t scene_hash(const WorldDef3& def, const ShapeDef& ball, const SignatureView<3>& sig, int steps)
{
  auto w = std::make_unique<World3<16>>(def);
  REQUIRE(w->construction_status() == Status::ok);
  const Added<ShapeId> sphere = w->add_shape(ball);
  const Added<ShapeId> cube = w->add_shape(sig);
  REQUIRE(sphere.ok());
  REQUIRE(cube.ok());
  REQUIRE(w->add_plane(Vector3(0, 0, 1), 0).ok());
  for (int i = 0; i < 8; ++i) {
    BodyDef3 b;
    b.shape = i % 2 == 0 ? sphere.id : cube.id;
    b.position = Vector3(0.3f * float(i), 0, 0.5f + 0.3f * float(i));
    REQUIRE(w->add_body(b).ok());
  }
  for (int i = 0; i < steps; ++i) REQUIRE(w->step(1.0f / 60).status == Status::ok);
  return w->state_hash();
}
}  // namespace

TEST_CASE("state_hash differs for worlds that differ in any parameter, material or signature")
{
  const WorldDef3 def;
  const ShapeDef ball;
  const SignatureView<3> sig = testing::cube_synthetic.view();
  for (const int steps : {0, 3}) {
    CAPTURE(steps);
    const std::uint64_t base = scene_hash(def, ball, sig, steps);
    REQUIRE(scene_hash(def, ball, sig, steps) == base);  // deterministic
    using DefChange = std::pair<std::string, std::function<void(WorldDef3&)>>;
    const std::vector<DefChange> def_changes = {
        {"gravity", [](WorldDef3& d) { d.gravity = Vector3(0, 0, -9.8f); }},
        {"seed", [](WorldDef3& d) { d.seed = 7; }},
        {"restitution_threshold", [](WorldDef3& d) { d.restitution_threshold = 0.6f; }},
        {"table_restitution_threshold", [](WorldDef3& d) { d.table_restitution_threshold = false; }},
        {"settle_speed", [](WorldDef3& d) { d.settle_speed = 0.6f; }},
        {"sleep_speed", [](WorldDef3& d) { d.sleep_speed = 0.06f; }},
        {"sleep_time", [](WorldDef3& d) { d.sleep_time = 0.6f; }},
        {"wake_speed", [](WorldDef3& d) { d.wake_speed = 0.6f; }},
        {"linear_damping", [](WorldDef3& d) { d.linear_damping = 0.1f; }},
        {"angular_damping", [](WorldDef3& d) { d.angular_damping = 0.1f; }},
        {"support_iterations", [](WorldDef3& d) { d.support_iterations = 5; }},
        {"shock_propagation", [](WorldDef3& d) { d.shock_propagation = false; }},
        {"position_iterations", [](WorldDef3& d) { d.position_iterations = 3; }},
        {"allowed_overlap", [](WorldDef3& d) { d.allowed_overlap = 0.02f; }},
        {"overlap_correction", [](WorldDef3& d) { d.overlap_correction = 0.5f; }},
        {"spin_ratio_speed_floor", [](WorldDef3& d) { d.spin_ratio_speed_floor = 0.6f; }},
        {"nearest_radius", [](WorldDef3& d) { d.nearest_radius = true; }},
        {"pair_response", [](WorldDef3& d) { d.pair_response = PairResponse::independent; }},
        {"rest_conditions", [](WorldDef3& d) { d.rest_conditions = false; }},
        {"pile_rest", [](WorldDef3& d) { d.pile_rest = true; }},
        {"rest_blend_time", [](WorldDef3& d) { d.rest_blend_time = 0.2f; }},
        {"rest_turn_time", [](WorldDef3& d) { d.rest_turn_time = 0.2f; }},
        {"rest_snap_cosine", [](WorldDef3& d) { d.rest_snap_cosine = 0.99f; }},
        {"ground_cosine", [](WorldDef3& d) { d.ground_cosine = 0.8f; }},
        {"broad_phase", [](WorldDef3& d) { d.broad_phase = BroadPhase::grid; }},
        {"grid_above_bodies", [](WorldDef3& d) { d.grid_above_bodies = 4; }},
        {"sweep_axis", [](WorldDef3& d) { d.sweep_axis = 1; }},
        {"impact_threshold", [](WorldDef3& d) { d.impact_threshold = 2; }},
    };
    for (const DefChange& c : def_changes) {
      CAPTURE(c.first);
      WorldDef3 changed = def;
      c.second(changed);
      CHECK(scene_hash(changed, ball, sig, steps) != base);
    }
    // The material of a plain sphere, each coefficient.
    for (int k = 0; k < 3; ++k) {
      CAPTURE(k);
      ShapeDef other = ball;
      (k == 0 ? other.material.restitution : k == 1 ? other.material.friction : other.material.rolling_resistance) +=
          0.05f;
      CHECK(scene_hash(def, other, sig, steps) != base);
    }
    // The signature: a scalar, a response value, a rest frequency.
    SignatureView<3> other = sig;
    other.material.rolling_resistance = 0.06f;
    CHECK(scene_hash(def, ball, other, steps) != base);
    other = sig;
    other.restitution_threshold = 0.4f;
    CHECK(scene_hash(def, ball, other, steps) != base);
    static constexpr auto cube16 = quantize16(testing::cube_synthetic);
    CHECK(scene_hash(def, ball, cube16.view(), steps) != base);  // the same tables, rounded
    std::vector<Scalar> freq(sig.rest.frequencies.values, sig.rest.frequencies.values + sig.rest.count);
    freq[0] = 0.5f;
    other = sig;
    other.rest.frequencies = freq;
    CHECK(scene_hash(def, ball, other, steps) != base);
  }
}
