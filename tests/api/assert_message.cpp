// Reads past the last body with assertions on and the default handler: the handler must name
// the file, the line and the failed expression before it stops the program (CTest matches the
// message).
#undef NDEBUG
#define STATSIM_ENABLE_ASSERT 1
#include "statsim/world3.hpp"

#include <cstdio>

int main()
{
  static statsim::World3<4> world;
  std::printf("%f\n", double(world.body(3).position.x()));
  return 0;
}
