// Paper Figure 1: 300 L-shapes dropped from a cylinder pattern onto the ground, simulated with the
// L-shape's signature (tables/lshape.hpp).
//   drop_lshapes [--n N] [--frames FILE.csv] [--every K] [--steps S] [--seed S]
#include "demo.hpp"
#include "tables/lshape.hpp"

namespace {
statsim::World3<2000> world;
}

int main(int argc, char** argv)
{
  demo::Options o;
  o.n = 300;
  if (!demo::parse(argc, argv, o, "drop_lshapes [--n N<=2000] [--frames FILE.csv] [--every K] [--steps S] [--seed S]"))
    return 2;
  if (o.n < 1 || o.n > 2000) return 2;
  statsim::WorldDef3 def;
  def.seed = o.seed;
  world.configure(def);
  const statsim::ShapeId shape = world.add_shape(statsim::tables::lshape.view()).id;
  world.add_plane(statsim::Vector3(0, 0, 1), 0);
  statsim::Pcg32 rng(o.seed, 0);
  if (!demo::drop_cylinder(world, shape, o.n, 0.4f, 0.3f, 0.012f, rng)) return 1;
  int steps = 0;
  const double ms = demo::run(world, o, steps);
  if (ms < 0) return 1;
  demo::summary("drop_lshapes", world, shape, steps, ms);
  return 0;
}
