// The body-body data of a table being written, as the runtime will read it from the header
// (floats, or the support map at 16 bits), and the packing sample of a touching reference pair
// measured on it. Shared by `statsim gather` (3D) and `statsim gather2d` (2D): a packing ratio
// is d over the distance the runtime's own hull search finds on the table's own numbers.
#pragma once

#include "common/body_contacts.hpp"
#include "common/stored_values.hpp"
#include "statsim/detail/hull.hpp"
#include "statsim/detail/shape_setup.hpp"
#include "statsim/signature.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace statsim::tools {

/// A statistical Shape<D> whose body-body data is `c`'s, stored as the header stores it. Holds
/// the arrays the shape points into: neither copied nor moved.
template <int D>
class TableContactShape {
public:
  TableContactShape(const BodyContactData& c, bool i16)
  {
    for (double v : c.support) support_.push_back(static_cast<float>(v) + 0.0f);
    if (i16) q_ = quantize(support_);
    for (double v : c.faces) faces_.push_back(static_cast<float>(v) + 0.0f);
    SignatureView<D> view{};
    view.contact.support_size = static_cast<std::uint32_t>(c.support_size);
    view.contact.support = i16 ? ValuesView{Span<const std::int16_t>(q_.q), q_.scale, q_.offset} : ValuesView(support_);
    view.contact.faces = faces_;
    view.contact.face_count = static_cast<std::uint32_t>(c.face_count());
    shape_.statistical = true;
    shape_.signature = view;
    shape_.support_floor = statsim::detail::support_bounds(view.contact).floor;
  }
  TableContactShape(const TableContactShape&) = delete;
  TableContactShape& operator=(const TableContactShape&) = delete;

  const Shape<D>& shape() const { return shape_; }

private:
  std::vector<float> support_, faces_;
  Quantized q_;
  Shape<D> shape_{};
};

/// d / (the runtime's contact distance along the line of centres) of a touching pair of bodies
/// of `shape` with orientations a and b, centre b - centre a = `ab`: the least candidate
/// distance that `find_hull_witness` finds, packing 1; with the candidate it found.
template <int D>
PackingSample packing_sample(const Shape<D>& shape, const Body<D>& a, const Body<D>& b,
                             const Eigen::Matrix<double, D, 1>& ab)
{
  const typename Space<D>::Vec e = ab.normalized().template cast<Scalar>();
  // Distance 0 is below any positive reach, so the search always names its best candidate.
  std::uint32_t k = statsim::detail::find_hull_witness(shape, a, shape, b, e, Scalar(0), Scalar(1));
  if (k == statsim::detail::no_witness) k = 0;
  const statsim::detail::HullCandidate<D> h = statsim::detail::hull_candidate(shape, a, shape, b, e, k);
  PackingSample p;
  p.ratio = ab.norm() / (static_cast<double>(h.reach) / static_cast<double>(h.normal.dot(e)));
  p.up = ab[D - 1] / ab.norm();
  p.witness = k;
  return p;
}

}  // namespace statsim::tools
