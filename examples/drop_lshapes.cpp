// Paper Figure 1: 300 L-shapes dropped from a cylinder pattern onto the ground, simulated with the
// L-shape's signature (tables/lshape.hpp).
//   drop_lshapes [--n N] [--frames FILE.csv] [--every K] [--steps S] [--seed S]
#include "demo.hpp"
#include "tables/lshape.hpp"

#include <cstdio>

namespace {
statsim::World3<2000> world;
}

int main(int argc, char** argv)
{
  // 300 L-shapes from a cylinder of radius 0.4 m, from 0.3 m up, one every 12 mm of height.
  return demo::drop_main(argc, argv, world,
                         {"drop_lshapes", statsim::tables::lshape.view(), {300, 0.4f, 0.3f, 0.012f}});
}
