// The demos' drop pattern (paper Figures 1, 5, 6 and 7): bodies dropped from a vertical cylinder
// above the ground plane z = 0, stacked in height, with random orientations, small sideways
// velocities and spins, all drawn from the runtime's own Pcg32 in float. The examples drop their
// bodies with it, and the tests that must see what a demo sees build the same scene with it.
//
// Header-only, runtime only: no allocation, no exceptions (the examples are built without them).
#pragma once

#include "statsim/world3.hpp"

#include <cmath>
#include <cstdint>

namespace statsim::tools::scenes {

/// Where bodies are dropped from: a vertical cylinder around the z axis, one body per `rise`
/// of height (body i starts at a height in [base + i rise, base + (i + 1) rise)).
struct CylinderDrop {
  long count = 1;      ///< number of bodies
  float radius = 0;    ///< m, radius of the cylinder
  float base = 0;      ///< m, height of the lowest body's slot
  float rise = 0;      ///< m, height of one body's slot
};

/// Adds `drop.count` bodies of `shape` to `w`, each drawn from `rng`: a point uniform in the
/// cylinder's disc (radius r sqrt(u)), a height in its slot, a turn of up to pi about a random
/// axis, a horizontal velocity with each component in [-0.5, 0.5] m/s and a spin with each
/// component in [-5, 5] rad/s. Returns ok, or the first status of add_body that is not ok (the
/// bodies before it stay in the world).
inline Status drop_cylinder(WorldCore3& w, ShapeId shape, const CylinderDrop& drop, Pcg32& rng)
{
  for (long i = 0; i < drop.count; ++i) {
    BodyDef3 b;
    b.shape = shape;
    b.mass = 1;  // kg, every body alike (the figures measured with these scenes used 1 kg)
    const float a = rng.uniform(0, 6.2831853f);
    const float r = drop.radius * std::sqrt(rng.uniform());
    const float z = drop.base + drop.rise * float(i) + rng.uniform(0, drop.rise);
    b.position = Vector3(r * std::cos(a), r * std::sin(a), z);
    const float ax = rng.uniform(-1, 1), ay = rng.uniform(-1, 1), az = rng.uniform(-1, 1);
    const float angle = rng.uniform(0, 3.14159265f);
    const Vector3 axis = Vector3(ax, ay, az).norm() > 1e-3f ? Vector3(ax, ay, az).normalized() : Vector3(0, 0, 1);
    b.orientation = Quaternion(Eigen::AngleAxisf(angle, axis));
    const float vx = rng.uniform(-0.5f, 0.5f), vy = rng.uniform(-0.5f, 0.5f);
    b.linear_velocity = Vector3(vx, vy, 0);
    const float wx = rng.uniform(-5, 5), wy = rng.uniform(-5, 5), wz = rng.uniform(-5, 5);
    b.angular_velocity = Vector3(wx, wy, wz);
    const Status s = w.add_body(b).status;
    if (s != Status::ok) return s;
  }
  return Status::ok;
}

/// The demos' scene in an empty world `w`: configured with `def`, `sig` as its one shape, the
/// ground plane z = 0, and the bodies of `drop` drawn from the stream Pcg32(def.seed, stream).
/// Returns the shape's id, or the first status that is not ok.
inline Added<ShapeId> drop_on_ground(WorldCore3& w, const WorldDef3& def, const SignatureView<3>& sig,
                                     const CylinderDrop& drop, std::uint64_t stream = 0)
{
  Status s = w.configure(def);
  if (s != Status::ok) return {s, ShapeId{}};
  const Added<ShapeId> shape = w.add_shape(sig);
  if (!shape.ok()) return shape;
  s = w.add_plane(Vector3(0, 0, 1), 0).status;
  if (s != Status::ok) return {s, shape.id};
  Pcg32 rng(def.seed, stream);
  return {drop_cylinder(w, shape.id, drop, rng), shape.id};
}

}  // namespace statsim::tools::scenes
