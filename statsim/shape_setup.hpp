#pragma once
/// @file
/// `detail::statistical_shape`: the shape data a world derives from a signature when it is added
/// (radii the broad phase must hold, the radius at rest on other bodies, the hull's bounds).

#include "statsim/hull_contact.hpp"
#include "statsim/signature.hpp"
#include "statsim/world_data.hpp"
#include "statsim/world_def.hpp"

namespace statsim {
namespace detail {

/// Fills `shape` from a signature that passed `check_signature`, all but its rest-pose basins.
template <int D>
void statistical_shape(const SignatureView<D>& sig, Shape<D>& shape)
{
  // The broad phase must hold every radius a body can take: the largest h_coll and h_rest.
  Scalar largest = sig.bounding_radius, rest_max = 0;
  for (std::uint32_t i = 0; i < sig.height.spin_ratio.size; ++i)
    largest = sig.height.mean[i] > largest ? sig.height.mean[i] : largest;
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    largest = sig.rest.heights[i] > largest ? sig.rest.heights[i] : largest;
    rest_max = sig.rest.heights[i] > rest_max ? sig.rest.heights[i] : rest_max;
  }
  // The radius of a body at rest on other bodies: the rest heights weighted by how often the
  // reference came to rest in each pose; without frequencies, the largest rest height (h_coll
  // at spin 0 without rest poses).
  Scalar weighted = 0, weight = 0;
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    weighted += sig.rest.frequencies[i] * sig.rest.heights[i];
    weight += sig.rest.frequencies[i];
  }
  const Scalar mean_rest = weight > 0 ? weighted / weight : (rest_max > 0 ? rest_max : sig.height.mean[0]);
  // With body-body data a body also touches others as far out as its support map reaches,
  // times the largest packing ratio.
  Scalar floor = 0, packing = 1;
  shape = Shape<D>{0,         largest, sig.material, true, sig, {}, mean_rest, detail::signature_hash(sig),
                   floor,     packing, sig.mass};
  if (sig.contact.present()) {
    const detail::SupportBounds sb = detail::support_bounds(sig.contact);
    packing = detail::largest_packing(shape);
    const Scalar reach = sb.ceiling * (packing > 1 ? packing : Scalar(1));
    shape.bounding_radius = reach > largest ? reach : largest;
    shape.support_floor = sb.floor;
    shape.largest_packing = packing;
  }
}

}  // namespace detail
}  // namespace statsim
