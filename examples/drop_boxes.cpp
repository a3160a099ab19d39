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
  // 100 boxes from a cylinder of radius 0.3 m, from 0.3 m up, one every 2 cm of height.
  return demo::drop_main(argc, argv, world, {"drop_boxes", statsim::tables::box.view(), {100, 0.3f, 0.3f, 0.02f}});
}
