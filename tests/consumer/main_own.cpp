// A table statsim_add_tables() generated from tests/meshes/block.ply at build time.
#include <statsim/tables/block.hpp>
#include <statsim/world3.hpp>

#include <cstdio>

static statsim::World3<16> world;

int main()
{
  const auto block = world.add_shape(statsim::tables::block.view());
  if (!block.ok() || !world.add_plane(statsim::Vector3(0, 0, 1), 0).ok()) return 1;
  statsim::Pcg32 rng(1, 2);
  for (int i = 0; i < 16; ++i) {
    statsim::BodyDef3 b;  // the table's mass
    b.shape = block.id;
    b.position = statsim::Vector3(0.1f * float(i % 4), 0.1f * float(i / 4), 0.2f);
    b.orientation = statsim::random_orientation<3>(rng);
    if (!world.add_body(b).ok()) return 1;
  }
  for (int i = 0; i < 300; ++i)
    if (!world.step(1.0f / 60).ok()) return 1;
  const bool mass = world.body(0).inv_mass == 1 / statsim::tables::block.mass;
  std::printf("consumer_own: %s (mass %.4f kg, %u of 16 asleep)\n", mass ? "ok" : "wrong mass",
              double(statsim::tables::block.mass), world.count(statsim::MotionState::asleep));
  return mass ? 0 : 1;
}
