// Drops spheres into an open box and lets them pile up, with the particle response (no shape
// tables): the runtime core on its own. Prints progress and a summary.
//
//   sphere_pile [N]        N spheres, at most 4000 (default 1000)
#include "statsim/world3.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>

namespace {
constexpr std::uint32_t capacity = 4000;
statsim::World3<capacity> world;  // about 0.5 MB: static storage, not the stack
}  // namespace

int main(int argc, char** argv)
{
  using namespace statsim;
  const long n = argc > 1 ? std::strtol(argv[1], nullptr, 10) : 1000;
  if (n < 1 || n > long(capacity)) {
    std::fprintf(stderr, "sphere_pile: N must be 1..%u\n", capacity);
    return 2;
  }

  ShapeDef ball;
  ball.radius = 0.1f;  // 20 cm spheres
  ball.material.restitution = 0.4f;
  ball.material.friction = 0.5f;
  const Added<ShapeId> added = world.add_shape(ball);
  bool set_up = added.ok() && world.add_plane(Vector3(0, 0, 1), 0).ok();  // ground
  for (int k = 0; k < 2; ++k)  // four walls 1.5 m from the centre
    set_up = set_up && world.add_plane(Vector3::Unit(k), -1.5f).ok() && world.add_plane(-Vector3::Unit(k), -1.5f).ok();
  if (!set_up) {
    std::fprintf(stderr, "sphere_pile: world set-up failed\n");
    return 1;
  }
  const ShapeId shape = added.id;

  // A column of bodies above the box, with random sideways velocities and spins.
  Pcg32 rng(2024, 0);
  for (long i = 0; i < n; ++i) {
    BodyDef3 b;
    b.shape = shape;
    const float x = rng.uniform(-1.2f, 1.2f);
    const float y = rng.uniform(-1.2f, 1.2f);
    const float z = rng.uniform(0.5f, 0.5f + 0.02f * float(n));
    b.position = Vector3(x, y, z);
    const float vx = rng.uniform(-1, 1);
    const float vy = rng.uniform(-1, 1);
    b.linear_velocity = Vector3(vx, vy, 0);
    const float wz = rng.uniform(-5, 5);
    b.angular_velocity = Vector3(0, 0, wz);
    const Status s = world.add_body(b).status;
    if (s != Status::ok) {
      std::fprintf(stderr, "sphere_pile: add_body failed: %s\n", to_string(s));
      return 1;
    }
  }

  const float dt = 1.0f / 60;
  const int steps = 60 * 20;
  double seconds = 0;
  std::uint32_t worst_overflow = 0;
  for (int i = 1; i <= steps; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const StepResult r = world.step(dt);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (r.overflow) worst_overflow = r.pairs_dropped > worst_overflow ? r.pairs_dropped : worst_overflow;
    if (i % 300 == 0)
      std::printf("t = %4.1f s: %u moving, %u settling, %u asleep, %u contacts\n", double(i) * double(dt),
                  world.count(MotionState::moving), world.count(MotionState::settling),
                  world.count(MotionState::asleep), r.contacts);
  }

  float lowest = 1e9f, highest = 0;
  for (std::uint32_t i = 0; i < world.body_count(); ++i) {
    const float z = world.body(i).position.z();
    lowest = z < lowest ? z : lowest;
    highest = z > highest ? z : highest;
  }
  std::printf("sphere_pile: %ld spheres, %d steps of %.4f s, %.4f ms per step\n", n, steps, double(dt),
              1e3 * seconds / steps);
  std::printf("  asleep %u of %u; centre heights %.3f to %.3f m (radius %.2f m)\n", world.count(MotionState::asleep),
              world.body_count(), double(lowest), double(highest), double(ball.radius));
  if (worst_overflow) std::printf("  pair buffer overflowed (up to %u pairs dropped): raise MaxPairs\n", worst_overflow);
  return 0;
}
