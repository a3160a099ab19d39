// Must not compile with -Werror: the step's result (an overflow, a refused dt) is ignored.
#include "statsim/world3.hpp"

int main()
{
  static statsim::World3<4> world;
  world.step(1.0f / 60);
  return 0;
}
