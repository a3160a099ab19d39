// A table statsim_add_tables() generated in this build from tests/meshes/block.gltf, through the
// in-tree tool (the way a project that adds statsim with add_subdirectory uses it), in the
// namespace given by NAMESPACE.
#include <statsim/tables/block.hpp>
#include <statsim/world3.hpp>

#include <cstdio>

static statsim::World3<4> world;

int main()
{
  const auto block = world.add_shape(own::tables::block.view());
  if (!block.ok()) return 1;
  statsim::BodyDef3 b;
  b.shape = block.id;
  const auto body = world.add_body(b);
  if (!body.ok() || world.body(body.id).inv_mass != 1 / own::tables::block.mass) return 1;
  std::printf("own table: block, %.4f kg\n", double(own::tables::block.mass));
  return 0;
}
