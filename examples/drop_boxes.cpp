// Paper Figure 5: 100 boxes dropped onto the ground, simulated with the box's signature
// (tables/box.hpp).
//   drop_boxes [--n N] [--frames FILE.csv] [--every K] [--steps S] [--seed S]
#include "demo.hpp"
#include "tables/box.hpp"

#include <cstdio>

namespace {
statsim::World3<2000> world;
}

int main(int argc, char** argv)
{
  demo::Options o;
  o.n = 100;
  if (!demo::parse(argc, argv, o, "drop_boxes [--n N<=2000] [--frames FILE.csv] [--every K] [--steps S] [--seed S]"))
    return 2;
  if (o.n < 1 || o.n > 2000) return 2;
  statsim::WorldDef3 def;
  def.seed = o.seed;
  const statsim::Status configured = world.configure(def);
  const statsim::Added<statsim::ShapeId> added = world.add_shape(statsim::tables::box.view());
  const statsim::Added<statsim::PlaneId> ground = world.add_plane(statsim::Vector3(0, 0, 1), 0);
  if (configured != statsim::Status::ok || !added.ok() || !ground.ok()) {
    std::fprintf(stderr, "drop_boxes: world set-up failed\n");
    return 1;
  }
  const statsim::ShapeId shape = added.id;
  statsim::Pcg32 rng(o.seed, 0);
  if (!demo::drop_cylinder(world, shape, o.n, 0.3f, 0.3f, 0.02f, rng)) return 1;
  int steps = 0;
  const double ms = demo::run(world, o, steps);
  if (ms < 0) return 1;
  demo::summary("drop_boxes", world, shape, steps, ms);
  return 0;
}
