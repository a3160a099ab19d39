// Paper Figure 6: N bunnies (default 10,000) dropped onto the ground and piling up, simulated
// with the bunny's signature (tables/bunny.hpp). After the run it checks that the pile holds:
// the share asleep, whether any sphere ends below the ground and, where bodies touch at their
// collision spheres (`--spheres`; the default is at their hulls, whose spheres overlap by design),
// the deepest overlap of two spheres relative to the smaller radius.
//   bunnies [N] [--frames FILE.csv] [--every K] [--steps S] [--seed S] [--spheres]
#include "demo.hpp"
#include "tables/bunny.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace {
constexpr std::uint32_t capacity = 20000;
statsim::World3<capacity> world;

// Deepest overlap of two collision spheres, as a fraction of the smaller radius, through the
// runtime's own broad phase ordering: a sweep along x over all bodies.
float deepest_overlap(const statsim::WorldCore3& w)
{
  std::vector<std::uint32_t> order(w.body_count());
  for (std::uint32_t i = 0; i < w.body_count(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return w.body(a).position.x() < w.body(b).position.x(); });
  float widest = 0;
  for (std::uint32_t i = 0; i < w.body_count(); ++i) widest = std::max(widest, 2 * w.body(i).radius);
  float deepest = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const statsim::Body3& a = w.body(order[i]);
    for (std::size_t j = i + 1; j < order.size(); ++j) {
      const statsim::Body3& b = w.body(order[j]);
      if (b.position.x() - a.position.x() > widest) break;
      const float gap = (a.position - b.position).norm() - a.radius - b.radius;
      if (gap < 0) deepest = std::max(deepest, -gap / std::min(a.radius, b.radius));
    }
  }
  return deepest;
}
}  // namespace

int main(int argc, char** argv)
{
  demo::Options o;
  o.n = 10000;
  o.stop_when_asleep = false;  // the pile is judged after 20 simulated seconds
  // The first argument may be N on its own, as in `bunnies 10000`.
  if (argc > 1 && argv[1][0] != '-') {
    o.n = std::strtol(argv[1], nullptr, 10);
    --argc;
    ++argv;
  }
  if (!demo::parse(argc, argv, o, "bunnies [N<=20000] [--frames FILE.csv] [--every K] [--steps S] [--seed S] [--spheres]"))
    return 2;
  if (o.n < 1 || o.n > long(capacity)) {
    std::fprintf(stderr, "bunnies: N must be 1..%u\n", capacity);
    return 2;
  }
  const statsim::WorldDef3 def = demo::demo_def(o);
  // A cylinder wide enough for a low pile: radius grows with sqrt(N).
  const float radius = 0.1f * std::sqrt(float(o.n));
  statsim::ShapeId shape{};
  if (!demo::drop("bunnies", world, def, statsim::tables::bunny.view(), {o.n, radius, 0.3f, 2.0f / float(o.n) + 0.0004f},
                  0, shape))
    return 1;
  int steps = 0;
  const double ms = demo::run(world, o, steps);
  if (ms < 0) return 1;
  demo::summary("bunnies", world, shape, steps, ms);
  float lowest = 1e9f;
  std::uint32_t below = 0;  // spheres reaching more than 1 mm into the ground
  for (std::uint32_t i = 0; i < world.body_count(); ++i) {
    const float bottom = world.body(i).position.z() - world.body(i).radius;
    lowest = std::min(lowest, bottom);
    below += bottom < -0.001f;
  }
  std::printf("  after %.1f s: %.1f%% asleep, lowest sphere bottom %+.5f m (%u below the ground)", double(steps) / 60,
              100.0 * world.count(statsim::MotionState::asleep) / double(world.body_count()), double(lowest), below);
  if (world.def().body_contacts == statsim::BodyContacts::collision_spheres)
    std::printf(", deepest sphere overlap %.1f%% of the radius", 100.0 * double(deepest_overlap(world)));
  std::printf("\n");
  return 0;
}
