#include <statsim/statsim.hpp>
#include <statsim/tables/box.hpp>

#include <cstdio>

int main()
{
  statsim::World3<8> world;
  if (world.construction_status() != statsim::Status::ok) return 1;
  if (!world.add_shape(statsim::ShapeDef{}).ok() || !world.add_plane(statsim::Vector3(0, 0, 1), 0).ok()) return 1;
  if (!world.add_shape(statsim::tables::box.view()).ok()) return 1;
  statsim::BodyDef3 b;
  b.position = statsim::Vector3(0, 0, 1);
  if (!world.add_body(b).ok()) return 1;
  for (int i = 0; i < 600; ++i)
    if (!world.step(1.0f / 60).ok()) return 1;
  const bool rested = world.body(0).state == statsim::MotionState::asleep;
  std::printf("consumer: %s (z = %.4f)\n", rested ? "ok" : "body did not rest", double(world.body(0).position.z()));
  return rested ? 0 : 1;
}
