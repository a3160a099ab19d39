// Built with floating-point contraction on (and FMA instructions): the world must say so.
#include "statsim/world3.hpp"

#include <cstdio>

int main()
{
  static statsim::World3<4> world;
  std::printf("construction_status: %s\n", statsim::to_string(world.construction_status()));
  return world.construction_status() == statsim::Status::float_contraction ? 0 : 1;
}
