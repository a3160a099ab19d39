// Spawns boxes (tables/box.hpp) above the ground, removes the oldest once twelve are in the
// world, kicks the box under a point found by a ray cast, and prints the impacts above 2 m/s
// that each step reports, as a game would play a sound for them.
//
//   spawn_and_kick         10 simulated seconds at 60 Hz
#include "statsim/queries.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"

#include <cstdio>

namespace {
/// A body id as slot.generation: the generation tells a box from the removed ones before it.
struct Name {
  char text[16];
  explicit Name(statsim::BodyId id)
  {
    std::snprintf(text, sizeof text, "%u.%u", statsim::body_index(id), statsim::body_generation(id));
  }
};
constexpr std::uint32_t most = 12;  // boxes in the world at once
// 16 bodies, 8 planes, 96 candidate pairs, 8 shapes, 16 impacts a step.
statsim::World3<16, 8, 96, 8, 16> world;
}  // namespace

int main()
{
  using namespace statsim;
  WorldDef3 def;
  def.impact_threshold = 2;  // m/s: the landings and hard kicks, not the rattle of a settling box
  const Added<ShapeId> box = world.add_shape(tables::box.view());
  if (world.configure(def) != Status::ok || !box.ok() || !world.add_plane(Vector3(0, 0, 1), 0).ok()) {
    std::fprintf(stderr, "spawn_and_kick: world set-up failed\n");
    return 1;
  }

  Pcg32 rng(21, 0);
  BodyId ring[most];  // the live boxes, oldest first from `oldest`
  std::uint32_t live = 0, oldest = 0, spawned = 0, removed = 0, kicks = 0, impacts = 0, dropped = 0;
  const float dt = 1.0f / 60;
  for (int step = 0; step < 600; ++step) {
    const float t = float(step) * dt;
    if (step % 20 == 0) {  // a new box every third of a second
      if (live == most) {
        if (world.remove_body(ring[oldest]) != Status::ok) return 1;
        std::printf("%6.2f s  removed box %s\n", double(t), Name(ring[oldest]).text);
        oldest = (oldest + 1) % most;
        --live;
        ++removed;
      }
      BodyDef3 b;
      b.shape = box.id;
      const float x = rng.uniform(-0.6f, 0.6f), y = rng.uniform(-0.6f, 0.6f);
      b.position = Vector3(x, y, 1.5f);
      b.orientation = random_orientation<3>(rng);
      const Added<BodyId> added = world.add_body(b);
      if (!added.ok()) {
        std::fprintf(stderr, "spawn_and_kick: add_body: %s\n", to_string(added.status));
        return 1;
      }
      ring[(oldest + live) % most] = added.id;
      ++live;
      ++spawned;
      std::printf("%6.2f s  spawned box %s\n", double(t), Name(added.id).text);
    }
    if (step % 60 == 45) {  // kick whatever lies under a point near a box, up and off its centre
      const Vector3 p = world.body(ring[(oldest + rng.next_u32() % live) % most]).position;
      const float dx = rng.uniform(-0.05f, 0.05f), dy = rng.uniform(-0.05f, 0.05f);
      QueryHit<3> hit;
      if (ray_cast(world, Vector3(p.x() + dx, p.y() + dy, 3), Vector3(0, 0, -1), 5, hit) == Status::ok &&
          hit.body != no_body) {
        const Body3& b = world.body(hit.body);
        const Scalar m = 1 / b.inv_mass;
        if (world.apply_impulse(hit.body, Vector3(0, 0, 4 * m), hit.point) != Status::ok) return 1;
        std::printf("%6.2f s  kicked box %s at (%.2f, %.2f, %.2f)\n", double(t), Name(hit.body).text, double(hit.point.x()),
                    double(hit.point.y()), double(hit.point.z()));
        ++kicks;
      }
    }
    const StepResult r = world.step(dt);
    if (r.status != Status::ok || (r.overflow & overflow_pairs)) return 1;
    dropped += r.impacts_dropped;
    for (std::uint32_t k = 0; k < world.impact_count(); ++k) {
      const Impact<3>& e = world.impacts()[k];
      if (e.b == no_body)
        std::printf("%6.2f s  impact: box %s on the ground at %.2f m/s\n", double(t + dt), Name(e.a).text,
                    double(e.approach_speed));
      else
        std::printf("%6.2f s  impact: box %s and box %s at %.2f m/s\n", double(t + dt), Name(e.a).text,
                    Name(e.b).text, double(e.approach_speed));
      ++impacts;
    }
  }
  std::printf("spawned %u, removed %u, kicked %u, %u impacts above %.1f m/s (%u not recorded), %u boxes "
              "left, %u asleep\n",
              spawned, removed, kicks, impacts, double(def.impact_threshold), dropped, world.live_body_count(),
              world.count(MotionState::asleep));
  return 0;
}
