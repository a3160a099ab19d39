// A signature view carries each array with its length, and add_shape refuses a view whose counts
// run past its arrays with `invalid_shape` before it reads one element past them. The tables
// here are copied to the heap, every array exactly as long as the table's own, so that a read
// past one is a heap-buffer-overflow under AddressSanitizer (the sanitizer build runs this file),
// not a quiet read of the next array of a static table.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/signature_scale.hpp"
#include "statsim/tables/box.hpp"
#include "statsim/tables/bunny.hpp"
#include "statsim/tables/lshape2d.hpp"
#include "statsim/tables/square2d.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

using namespace statsim;

namespace view_lengths {

/// 16-bit values on the heap, named as `Quantized16` names them.
struct HeapQ16 {
  Scalar scale = 1;
  Scalar offset = 0;
  std::vector<std::int16_t> q;
};

template <std::size_t N>
std::vector<Scalar> on_heap(const std::array<Scalar, N>& a)
{
  return {a.begin(), a.end()};
}
template <std::size_t N>
HeapQ16 on_heap(const Quantized16<N>& a)
{
  return {a.scale, a.offset, {a.q.begin(), a.q.end()}};
}

template <class T>
auto support_on_heap(const T& t)
{
  if constexpr (detail::has_contact_data<T>::value) return on_heap(t.contact.support);
  else return std::vector<Scalar>{};
}

/// A table's arrays on the heap, named as `BasicSignature` names its parts (as a host tool's
/// growable storage is), so that `signature_view` makes the view and gives each array its length.
template <int D, class Means, class Spreads, class Support>
struct HeapTable {
  const char* name = "";
  Scalar length = 0, bounding_radius = 0, mass = 0;
  std::array<Scalar, 3> unit_inertia{};
  Material material{};
  Scalar restitution_threshold = 0;
  ResponseLayout layout = ResponseLayout::scaled;
  ResponseModel model = ResponseModel::independent_gaussian;
  std::uint32_t axis_count = 0;
  std::vector<Scalar> height_axis, height_mean, height_stddev, axis0, axis1, axis2, axis3;
  Means response_mean;
  Spreads response_spread;
  std::vector<Scalar> rest_normals, rest_heights, rest_frequencies, mesh_frame;
  struct {
    std::uint32_t support_size = 0;
    std::vector<Scalar> pair_mean, pair_stddev;
    Support support;
    std::vector<Scalar> faces;
    std::array<Scalar, 3> packing_mean{}, packing_stddev{};
  } contact;
  struct {
    Scalar hop = 0;
    std::vector<Scalar> cos_theta, spin_ratio, froude, probability;
  } landing;
  struct {
    std::vector<Scalar> time;
  } settle;

  SignatureView<D> view() const { return signature_view<D>(*this); }
};

template <int D, class T>
auto copy_to_heap(const T& t)
{
  HeapTable<D, decltype(on_heap(t.response_mean)), decltype(on_heap(t.response_spread)), decltype(support_on_heap(t))> h;
  h.name = t.name;
  h.length = t.length;
  h.bounding_radius = t.bounding_radius;
  h.mass = t.mass;
  h.unit_inertia = t.unit_inertia;
  h.material = t.material;
  h.restitution_threshold = t.restitution_threshold;
  h.layout = t.layout;
  h.model = t.model;
  h.axis_count = t.axis_count;
  h.height_axis = on_heap(t.height_axis);
  h.height_mean = on_heap(t.height_mean);
  h.height_stddev = on_heap(t.height_stddev);
  h.axis0 = on_heap(t.axis0);
  h.axis1 = on_heap(t.axis1);
  h.axis2 = on_heap(t.axis2);
  h.axis3 = on_heap(t.axis3);
  h.response_mean = on_heap(t.response_mean);
  h.response_spread = on_heap(t.response_spread);
  h.rest_normals = on_heap(t.rest_normals);
  h.rest_heights = on_heap(t.rest_heights);
  h.rest_frequencies = on_heap(t.rest_frequencies);
  h.mesh_frame = on_heap(t.mesh_frame);
  if constexpr (detail::has_contact_data<T>::value) {
    h.contact.support_size = t.contact.support_size;
    h.contact.pair_mean = on_heap(t.contact.pair_mean);
    h.contact.pair_stddev = on_heap(t.contact.pair_stddev);
    h.contact.support = on_heap(t.contact.support);
    h.contact.faces = on_heap(t.contact.faces);
    h.contact.packing_mean = t.contact.packing_mean;
    h.contact.packing_stddev = t.contact.packing_stddev;
  }
  if constexpr (detail::has_landing_data<T>::value) {
    h.landing.hop = t.landing.hop;
    h.landing.cos_theta = on_heap(t.landing.cos_theta);
    h.landing.spin_ratio = on_heap(t.landing.spin_ratio);
    h.landing.froude = on_heap(t.landing.froude);
    h.landing.probability = on_heap(t.landing.probability);
  }
  if constexpr (detail::has_settle_data<T>::value) h.settle.time = on_heap(t.settle.time);
  return h;
}

void drop_last(std::vector<Scalar>& v) { v.pop_back(); }
void drop_last(HeapQ16& v) { v.q.pop_back(); }

template <int D>
using Count = std::pair<std::string, std::function<void(SignatureView<D>&)>>;

/// Every count of a view, one too many in turn; the arrays stay as they are.
template <int D>
std::vector<Count<D>> counts_one_too_many(const SignatureView<D>& valid)
{
  std::vector<Count<D>> m;
  m.push_back({"rest count", [](SignatureView<D>& v) { v.rest.count += 1; }});
  m.push_back({"height table size", [](SignatureView<D>& v) { v.height.spin_ratio.size += 1; }});
  for (std::uint32_t a = 0; a < valid.response.axis_count; ++a)
    m.push_back({"response axis size " + std::to_string(a), [a](SignatureView<D>& v) { v.response.axes[a].size += 1; }});
  if (valid.response.model == ResponseModel::empirical)  // one more outcome a cell: a size the model allows
    m.push_back({"outcomes per cell", [](SignatureView<D>& v) { v.response.spread_per_cell += v.response.components; }});
  if (valid.contact.present()) {
    m.push_back({"support size", [](SignatureView<D>& v) { v.contact.support_size += 1; }});
    m.push_back({"face count", [](SignatureView<D>& v) { v.contact.face_count += 1; }});
  }
  return m;
}

/// The world as it was: the same shapes and the same state, bit for bit.
template <class World>
struct Unchanged {
  const World& world;
  std::uint32_t shapes = world.shape_count();
  std::uint64_t hash = world.state_hash();
  bool operator()() const { return world.shape_count() == shapes && world.state_hash() == hash; }
};

/// A world with a shape and a body already in it, so that "unchanged" covers more than emptiness.
template <int D, class World>
void populate(World& w)
{
  const Added<ShapeId> ball = w.add_shape(ShapeDef{});
  REQUIRE(ball.ok());
  BodyDef<D> body;
  body.shape = ball.id;
  REQUIRE(w.add_body(body).ok());
}

/// Each count of `table`'s view one too many, then each array that a count reaches one element
/// short: all refused with the world unchanged; the view of the heap copy as it is, accepted, adds
/// the shape the table's own view adds (the same hash).
template <int D, class World, class T>
void expect_overstated_counts_refused(const T& table)
{
  World w;
  populate<D>(w);
  const auto heap = copy_to_heap<D>(table);
  const SignatureView<D> valid = heap.view();
  for (const Count<D>& c : counts_one_too_many<D>(valid)) {
    CAPTURE(c.first);
    SignatureView<D> v = valid;
    c.second(v);
    const Unchanged<World> unchanged{w};
    CHECK(w.add_shape(v).status == Status::invalid_shape);
    CHECK(unchanged());
  }
  using Heap = std::decay_t<decltype(heap)>;
  std::vector<std::pair<std::string, std::function<void(Heap&)>>> short_arrays = {
      {"height mean", [](Heap& h) { drop_last(h.height_mean); }},
      {"height stddev", [](Heap& h) { drop_last(h.height_stddev); }},
      {"response mean", [](Heap& h) { drop_last(h.response_mean); }},
      {"response spread", [](Heap& h) { drop_last(h.response_spread); }},
      {"rest normals", [](Heap& h) { drop_last(h.rest_normals); }},
      {"rest frequencies", [](Heap& h) { drop_last(h.rest_frequencies); }},
  };
  if (valid.contact.present()) {
    short_arrays.push_back({"pair distance mean", [](Heap& h) { drop_last(h.contact.pair_mean); }});
    short_arrays.push_back({"pair distance stddev", [](Heap& h) { drop_last(h.contact.pair_stddev); }});
    short_arrays.push_back({"support map", [](Heap& h) { drop_last(h.contact.support); }});
  }
  if (valid.landing.present())
    short_arrays.push_back({"landing probabilities", [](Heap& h) { drop_last(h.landing.probability); }});
  if (valid.settle.present()) short_arrays.push_back({"settling times", [](Heap& h) { drop_last(h.settle.time); }});
  for (const auto& s : short_arrays) {
    CAPTURE(s.first);
    Heap spoilt = heap;
    s.second(spoilt);
    const Unchanged<World> unchanged{w};
    CHECK(w.add_shape(spoilt.view()).status == Status::invalid_shape);
    CHECK(unchanged());
  }
  const Added<ShapeId> added = w.add_shape(valid);
  REQUIRE(added.ok());
  World own;
  populate<D>(own);
  REQUIRE(own.add_shape(table.view()).ok());
  CHECK(w.state_hash() == own.state_hash());
}

constexpr auto box_f32 = dequantize(tables::box);  // float responses, 16-bit support map
constexpr auto square2d_q16 = quantize16(tables::square2d);

}  // namespace view_lengths

TEST_CASE("add_shape refuses a view whose counts run past its arrays (heap copies of the tables)")
{
  using namespace view_lengths;
  SUBCASE("bunny, 16-bit") { expect_overstated_counts_refused<3, World3<8>>(tables::bunny); }
  SUBCASE("box, float responses") { expect_overstated_counts_refused<3, World3<8>>(box_f32); }
  SUBCASE("L-shape 2D, float") { expect_overstated_counts_refused<2, World2<8>>(tables::lshape2d); }
  SUBCASE("square 2D, 16-bit responses") { expect_overstated_counts_refused<2, World2<8>>(square2d_q16); }
  SUBCASE("empirical responses") { expect_overstated_counts_refused<3, World3<8>>(testing::cube_empirical_synthetic); }
}

// A view is never made from a bare pointer: every way into a view names the length.
static_assert(!std::is_constructible<Span<const Scalar>, const Scalar*>::value, "a pointer alone has no length");
static_assert(!std::is_convertible<const Scalar*, ValuesView>::value, "a pointer alone has no length");
static_assert(!std::is_constructible<Span<const Scalar>, std::vector<Scalar>&&>::value, "a temporary outlives no view");

TEST_CASE("a table's view takes every length from its arrays, a shape of another size keeps them")
{
  using T = std::decay_t<decltype(tables::bunny)>;
  const SignatureView<3> own = tables::bunny.view();
  for (const SignatureView<3>& v : {own, scaled_view(own, 2.5f)}) {
    CHECK(v.height.spin_ratio.size == std::tuple_size<decltype(T::height_axis)>::value);
    CHECK(v.height.mean.count() == v.height.spin_ratio.size);
    CHECK(v.height.stddev.count() == v.height.spin_ratio.size);
    CHECK(v.response.mean.count() == T::cells * T::components);
    CHECK(v.response.spread.count() == T::cells * v.response.spread_per_cell);
    CHECK(v.rest.normals.size == 3 * v.rest.count);
    CHECK(v.rest.heights.count() == v.rest.count);
    CHECK(v.rest.frequencies.size == v.rest.count);
    CHECK(v.mesh_frame.size == 12);
    CHECK(v.contact.support.count() == v.contact.support_count());
    CHECK(v.contact.pair_mean.count() == v.height.spin_ratio.size);
    CHECK(v.contact.pair_stddev.count() == v.height.spin_ratio.size);
    CHECK(v.contact.faces.size == face_values(3) * v.contact.face_count);
  }
}

TEST_CASE("a view built by hand from containers is accepted as the table's own, and refused with an array short")
{
  // The hand-built way (statsim/README.md): each array from a container, which gives its length.
  const auto& t = tables::lshape2d;
  const std::vector<Scalar> mesh_frame(t.mesh_frame.begin(), t.mesh_frame.end());
  const std::vector<Scalar> faces(t.contact.faces.begin(), t.contact.faces.end());
  SignatureView<2> by_hand = t.view();
  by_hand.mesh_frame = mesh_frame;
  by_hand.contact.faces = faces;
  World2<4> own, w;
  REQUIRE(own.add_shape(t.view()).ok());
  REQUIRE(w.add_shape(by_hand).ok());
  CHECK(w.state_hash() == own.state_hash());

  const view_lengths::Unchanged<World2<4>> unchanged{w};
  SignatureView<2> v = by_hand;
  v.mesh_frame = Span<const Scalar>(mesh_frame.data(), mesh_frame.size() - 1);
  CHECK(w.add_shape(v).status == Status::invalid_shape);
  v = by_hand;
  v.contact.faces = Span<const Scalar>(faces.data(), faces.size() - 1);  // the last face one number short
  CHECK(w.add_shape(v).status == Status::invalid_shape);
  CHECK(unchanged());
}
