// add_shape checks every pointer of a signature it will read and every number: a hand-built view
// with a pointer missing, or a number out of its range, is rejected with `invalid_shape` and the
// world is left as it was.
#include <doctest/doctest.h>

#include "scenes/synthetic_signatures.hpp"

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

using namespace statsim;

namespace {

template <int D>
using Mutation = std::pair<std::string, std::function<void(SignatureView<D>&)>>;

/// Every pointer of a view the world reads, each one cleared in turn.
template <int D>
std::vector<Mutation<D>> missing_pointers(const SignatureView<D>& valid)
{
  std::vector<Mutation<D>> m;
  m.push_back({"height axis", [](SignatureView<D>& v) { v.height.spin_ratio.values = nullptr; }});
  m.push_back({"height axis size", [](SignatureView<D>& v) { v.height.spin_ratio.size = 0; }});
  m.push_back({"height mean", [](SignatureView<D>& v) { v.height.mean.f32 = nullptr; v.height.mean.i16 = nullptr; }});
  m.push_back({"height stddev", [](SignatureView<D>& v) { v.height.stddev.f32 = nullptr; v.height.stddev.i16 = nullptr; }});
  for (std::uint32_t a = 0; a < valid.response.axis_count; ++a) {
    m.push_back({"response axis " + std::to_string(a), [a](SignatureView<D>& v) { v.response.axes[a].values = nullptr; }});
    m.push_back({"response axis size " + std::to_string(a), [a](SignatureView<D>& v) { v.response.axes[a].size = 0; }});
  }
  m.push_back({"response mean", [](SignatureView<D>& v) { v.response.mean.f32 = nullptr; v.response.mean.i16 = nullptr; }});
  m.push_back({"response stddev", [](SignatureView<D>& v) { v.response.spread.f32 = nullptr; v.response.spread.i16 = nullptr; }});
  m.push_back({"rest normals", [](SignatureView<D>& v) { v.rest.normals = nullptr; }});
  m.push_back({"rest heights", [](SignatureView<D>& v) { v.rest.heights = nullptr; }});
  m.push_back({"rest frequencies", [](SignatureView<D>& v) { v.rest.frequencies = nullptr; }});
  return m;
}

template <int D, class World>
void expect_all_rejected(World& w, const SignatureView<D>& valid, const std::vector<Mutation<D>>& mutations)
{
  for (const Mutation<D>& m : mutations) {
    CAPTURE(m.first);
    SignatureView<D> v = valid;
    m.second(v);
    const std::uint32_t shapes = w.shape_count();
    CHECK(w.add_shape(v).status == Status::invalid_shape);
    CHECK(w.shape_count() == shapes);
  }
  // The valid view itself is accepted: the rejections above are the mutations' doing.
  const Added<ShapeId> ok = w.add_shape(valid);
  CHECK(ok.ok());
}

}  // namespace

TEST_CASE("add_shape rejects a signature view with any pointer missing (2D, 3D, 16-bit responses)")
{
  {
    World2<4> w;
    const SignatureView<2> valid = testing::square2d_synthetic.view();
    REQUIRE(valid.rest.count > 0);
    expect_all_rejected<2>(w, valid, missing_pointers<2>(valid));
  }
  {
    World3<4> w;
    const SignatureView<3> valid = testing::cube_synthetic.view();
    REQUIRE(valid.rest.count > 0);
    expect_all_rejected<3>(w, valid, missing_pointers<3>(valid));
  }
  {
    World3<4> w;
    static constexpr auto cube16 = quantize16(testing::cube_synthetic);
    const SignatureView<3> valid = cube16.view();
    REQUIRE(valid.response.mean.i16 != nullptr);
    expect_all_rejected<3>(w, valid, missing_pointers<3>(valid));
  }
}

TEST_CASE("add_shape reads 16-bit height tables and rejects them when missing")
{
  // Heights as 16-bit integers: value = offset + scale * q.
  const SignatureView<2> f32 = testing::square2d_synthetic.view();
  static const std::int16_t mean_q[3] = {-100, 0, 100};
  static const std::int16_t stddev_q[3] = {10, 20, 30};
  SignatureView<2> valid = f32;
  valid.height.mean = ValuesView{Span<const std::int16_t>(mean_q), 0.001f, 0.66f};
  valid.height.stddev = ValuesView{Span<const std::int16_t>(stddev_q), 0.001f, 0.0f};
  World2<4> w;
  expect_all_rejected<2>(w, valid, missing_pointers<2>(valid));
}

TEST_CASE("add_shape rejects rest frequencies that are not finite or outside [0, 1]")
{
  const SignatureView<3> valid = testing::cube_synthetic.view();
  const std::uint32_t n = valid.rest.count;
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -0.25f,
                          1.5f}) {
    CAPTURE(bad);
    std::vector<Scalar> freq(valid.rest.frequencies.values, valid.rest.frequencies.values + n);
    freq[n - 1] = bad;
    SignatureView<3> v = valid;
    v.rest.frequencies = freq;
    World3<4> w;
    CHECK(w.add_shape(v).status == Status::invalid_shape);
    CHECK(w.shape_count() == 0);
  }
}

TEST_CASE("add_shape rejects response-model data that does not fit its model, with the world unchanged")
{
  const SignatureView<3> paper = testing::cube_synthetic.view();
  const SignatureView<3> correlated = testing::cube_correlated_synthetic.view();
  const SignatureView<3> empirical = testing::cube_empirical_synthetic.view();
  std::vector<Mutation<3>> m;
  m.push_back({"unknown model", [](SignatureView<3>& v) { v.response.model = ResponseModel(3); }});
  m.push_back({"model byte 255", [](SignatureView<3>& v) { v.response.model = ResponseModel(255); }});
  m.push_back({"no spread values", [](SignatureView<3>& v) { v.response.spread_per_cell = 0; }});
  m.push_back({"another model's spread size", [](SignatureView<3>& v) {
                 v.response.spread_per_cell = v.response.model == ResponseModel::correlated_gaussian ? 6 : 21;
               }});
  m.push_back({"a spread that is not a whole number of outcomes", [](SignatureView<3>& v) {
                 if (v.response.model == ResponseModel::empirical) v.response.spread_per_cell = 23;
                 else v.response.spread_per_cell += 1;
               }});
  World3<4> w;
  expect_all_rejected<3>(w, paper, m);
  expect_all_rejected<3>(w, correlated, m);
  expect_all_rejected<3>(w, empirical, m);
  // An empirical table of more outcomes than the runtime's limit.
  SignatureView<3> many = empirical;
  many.response.spread_per_cell = 6 * (max_empirical_outcomes + 1);
  const std::uint32_t shapes = w.shape_count();
  CHECK(w.add_shape(many).status == Status::invalid_shape);
  CHECK(w.shape_count() == shapes);

  // A value that is not finite in the spread of either new model.
  for (const SignatureView<3>* valid : {&correlated, &empirical}) {
    const std::uint32_t n = 8 * valid->response.spread_per_cell;
    std::vector<Scalar> spread(valid->response.spread.f32.values, valid->response.spread.f32.values + n);
    spread[n / 2] = std::numeric_limits<Scalar>::quiet_NaN();
    SignatureView<3> v = *valid;
    v.response.spread = ValuesView(spread);
    World3<4> w2;
    CHECK(w2.add_shape(v).status == Status::invalid_shape);
    CHECK(w2.shape_count() == 0);
  }
  // The 16-bit forms of both are accepted.
  static constexpr auto correlated16 = quantize16(testing::cube_correlated_synthetic);
  static constexpr auto empirical16 = quantize16(testing::cube_empirical_synthetic);
  World3<4> w3;
  CHECK(w3.add_shape(correlated16.view()).ok());
  CHECK(w3.add_shape(empirical16.view()).ok());
}
