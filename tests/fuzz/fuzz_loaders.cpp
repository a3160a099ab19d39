// libFuzzer target: what the host tools and the runtime read from outside.
//
// The host tools read meshes from OBJ files (tools/mesh: load_obj / parse_obj, then the mass
// properties); the signature tables are compiled in (tables/*.hpp), so the runtime's loader is
// add_shape(SignatureView), which takes pointers and sizes from the caller. The first byte picks:
//  - OBJ text (the rest of the input): parse_obj must not crash; a mesh it accepts must have
//    finite, positive volume and finite mass properties;
//  - a 2D or 3D signature built from the input (sizes, layout, material, every table number,
//    float or 16-bit storage): add_shape must not crash; if it accepts the signature, bodies of
//    that shape dropped on a plane and stepped stay finite.
#include "fuzz_input.hpp"

#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace statsim::fuzz {
namespace {

void fuzz_obj(const std::uint8_t* data, std::size_t size)
{
  const std::string text(reinterpret_cast<const char*>(data), size);
  tools::TriMesh mesh;
  tools::MeshError error;
  if (!tools::parse_obj(text, "fuzz.obj", mesh, error)) {
    if (error.message.empty()) fail("rejected mesh without a message");
    return;
  }
  const tools::MassProperties mp = tools::compute_mass_properties(mesh);
  if (!(mp.volume > 0) || !std::isfinite(mp.volume) || !mp.com.allFinite() || !mp.inertia.allFinite())
    fail("accepted mesh with bad mass properties");
}

/// Storage for a signature read from the input.
template <int D>
struct Tables {
  std::vector<Scalar> height_axis, height_mean, height_stddev, axes[max_response_axes], mean, stddev, normals,
      heights, frequencies;
  std::vector<std::int16_t> mean16, stddev16;
};

template <int D>
void fuzz_signature(Input& in)
{
  constexpr std::uint32_t components = D == 3 ? 6 : 3;
  Tables<D> t;
  SignatureView<D> v;
  v.name = "fuzz";
  v.length = in.value(1);
  v.bounding_radius = in.value(1);
  v.mass = in.value(10);
  v.material.restitution = in.value(1.2f);
  v.material.friction = in.value(1.5f);
  v.material.rolling_resistance = in.value(0.2f);
  v.restitution_threshold = in.value(1);
  v.layout = in.below(2) ? ResponseLayout::with_speed : ResponseLayout::scaled;
  // Axis sizes and the axis count are read, not derived, so malformed views are tried too.
  const std::uint32_t nh = in.below(5);
  for (std::uint32_t i = 0; i < nh; ++i) {
    t.height_axis.push_back(in.value(16));
    t.height_mean.push_back(in.value(1));
    t.height_stddev.push_back(in.value(0.2f));
  }
  v.height.spin_ratio = AxisView{nh ? t.height_axis.data() : nullptr, nh};
  v.height.mean = ValuesView(t.height_mean);
  v.height.stddev = ValuesView(t.height_stddev);
  v.response.axis_count = in.below(max_response_axes + 1);
  v.response.components = in.below(8) ? components : in.below(8);
  std::uint32_t cells = 1;
  for (std::uint32_t a = 0; a < max_response_axes; ++a) {
    const std::uint32_t n = a < v.response.axis_count ? in.below(4) : 1;
    for (std::uint32_t i = 0; i < n; ++i) t.axes[a].push_back(in.value(16));
    v.response.axes[a] = AxisView{n ? t.axes[a].data() : nullptr, n};
    cells *= n;
  }
  // Any model byte (3 is none); the spread's size is its model's, or any, as a hand-made view's
  // may be. Tables hold cells x that many values, as a generated table does (lookups must stay
  // inside).
  v.response.model = ResponseModel(in.below(4));
  v.response.spread_per_cell = in.below(8) ? response_spread_size(v.response.model, components, 1 + in.below(3))
                                           : in.below(64);
  const std::uint32_t values = cells * components;
  const std::uint32_t spreads = cells * v.response.spread_per_cell;
  const bool q16 = in.below(2) != 0;
  for (std::uint32_t i = 0; i < values; ++i) {
    if (q16) t.mean16.push_back(std::int16_t(in.byte() << 8 | in.byte()));
    else t.mean.push_back(in.value(4));
  }
  for (std::uint32_t i = 0; i < spreads; ++i) {
    if (q16) t.stddev16.push_back(std::int16_t(in.byte() << 8 | in.byte()));
    else t.stddev.push_back(in.value(1));
  }
  if (q16) {
    v.response.mean = ValuesView{Span<const std::int16_t>(t.mean16), in.value(0.01f), in.value(1)};
    v.response.spread = ValuesView{Span<const std::int16_t>(t.stddev16), in.value(0.01f), in.value(1)};
  } else {
    v.response.mean = ValuesView(t.mean);
    v.response.spread = ValuesView(t.stddev);
  }
  const std::uint32_t nr = in.below(4);
  for (std::uint32_t i = 0; i < nr; ++i) {
    for (int k = 0; k < D; ++k) t.normals.push_back(in.value(1));
    t.heights.push_back(in.value(1));
    t.frequencies.push_back(in.value(1));
  }
  v.rest.count = nr;
  v.rest.normals = t.normals;
  v.rest.heights = ValuesView(t.heights);
  v.rest.frequencies = t.frequencies;
  const bool ordinary = !in.special();

  World<D, 8, 2, 32, 2> world;
  const Added<ShapeId> shape = world.add_shape(v);
  if (!shape.ok()) {
    if (world.shape_count() != 0) fail("a rejected signature was added");
    return;
  }
  using Vec = typename Space<D>::Vec;
  if (!world.add_plane(Vec::Unit(Space<D>::up_axis), 0).ok()) fail("the ground plane was rejected");
  for (int i = 0; i < 8; ++i) {
    BodyDef<D> b;
    b.shape = shape.id;
    for (int k = 0; k < D; ++k) b.position[k] = in.value(1);
    b.position[Space<D>::up_axis] = std::fabs(b.position[Space<D>::up_axis]) * 2;
    for (int k = 0; k < D; ++k) b.linear_velocity[k] = in.value(20);
    if constexpr (D == 3) b.angular_velocity = Vector3(in.value(100), in.value(100), in.value(100));
    else b.angular_velocity = in.value(100);
    if (!world.add_body(b).ok()) return;  // special values in the state: rejected, nothing to step
  }
  const bool ordinary_bodies = ordinary && !in.special();
  for (int s = 0; s < 60; ++s) {
    if (world.step(1.0f / 60).status != Status::ok) fail("a step with a valid dt was rejected");
    if (!ordinary_bodies) continue;
    for (std::uint32_t i = 0; i < world.body_count(); ++i) {
      const Body<D>& b = world.body(i);
      if (!detail::finite(b.position) || !detail::finite(b.linear_velocity) || !detail::finite(b.orientation) ||
          !detail::finite(b.angular_velocity) || !std::isfinite(b.radius))
        fail("a body of an accepted signature became non-finite");
    }
  }
}

}  // namespace
}  // namespace statsim::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  if (size == 0) return 0;
  switch (data[0] % 3) {
    case 0: statsim::fuzz::fuzz_obj(data + 1, size - 1); break;
    case 1: {
      statsim::fuzz::Input in(data + 1, size - 1);
      statsim::fuzz::fuzz_signature<3>(in);
      break;
    }
    default: {
      statsim::fuzz::Input in(data + 1, size - 1);
      statsim::fuzz::fuzz_signature<2>(in);
      break;
    }
  }
  return 0;
}
