#pragma once
/// @file
/// `detail::statistical_shape`: the shape data a world derives from a signature when it is added
/// (radii the broad phase must hold, the radius at rest on other bodies, the hull's bounds), and
/// `detail::support_bounds`, which the gatherers use too.

#include "statsim/detail/hull.hpp"
#include "statsim/detail/state_hash.hpp"
#include "statsim/detail/world_data.hpp"
#include "statsim/signature.hpp"
#include "statsim/world_def.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

namespace statsim {
namespace detail {

/// The least and the largest values the support map of `c` can return for a unit direction, m:
/// per cell of each face, the least corner value over the largest |u| of the cell's points on
/// the cube face (|u_m| = 1 / |p| for p = (1, a, b)), and the largest corner value over the
/// least. Bilinear interpolation stays within its corners, so no lookup of a unit direction
/// reads outside them. Computed once, by `add_shape`.
struct SupportBounds {
  Scalar floor;
  Scalar ceiling;
};

template <int D>
SupportBounds support_bounds(const ContactView<D>& c)
{
  const std::uint32_t s = c.support_size;
  const std::uint32_t faces = D == 3 ? 6u : 4u, rows = D == 3 ? s - 1 : 1u;
  const auto node = [s](std::uint32_t i) { return -1 + 2 * Scalar(i) / Scalar(s - 1); };
  const auto far = [&node](std::uint32_t i) {
    return std::fabs(node(i)) > std::fabs(node(i + 1)) ? std::fabs(node(i)) : std::fabs(node(i + 1));
  };
  // The node nearest the face's centre in [node(i), node(i+1)]: 0 when they straddle it.
  const auto near = [&node](std::uint32_t i) {
    const Scalar x = node(i), y = node(i + 1);
    return x <= 0 && y >= 0 ? Scalar(0) : (std::fabs(x) < std::fabs(y) ? std::fabs(x) : std::fabs(y));
  };
  SupportBounds out{std::numeric_limits<Scalar>::infinity(), 0};
  for (std::uint32_t f = 0; f < faces; ++f)
    for (std::uint32_t i = 0; i + 1 < s; ++i)
      for (std::uint32_t j = 0; j < rows; ++j) {
        Scalar lo, hi, far2, near2;
        if (D == 3) {
          const std::uint32_t k = (f * s + i) * s + j;
          const Scalar v[4] = {c.support[k], c.support[k + 1], c.support[k + s], c.support[k + s + 1]};
          lo = hi = v[0];
          for (Scalar x : v) {
            lo = x < lo ? x : lo;
            hi = x > hi ? x : hi;
          }
          far2 = far(i) * far(i) + far(j) * far(j);
          near2 = near(i) * near(i) + near(j) * near(j);
        } else {
          const std::uint32_t k = f * s + i;
          lo = c.support[k] < c.support[k + 1] ? c.support[k] : c.support[k + 1];
          hi = c.support[k] > c.support[k + 1] ? c.support[k] : c.support[k + 1];
          far2 = far(i) * far(i);
          near2 = near(i) * near(i);
        }
        // |u_m| lies in [1 / sqrt(1 + far2), 1 / sqrt(1 + near2)] over the cell, and is at most 1.
        const Scalar lo_u = lo > 0 ? lo / std::sqrt(1 + far2) : lo;
        const Scalar hi_u = hi > 0 ? hi / std::sqrt(1 + near2) : hi / std::sqrt(1 + far2);
        out.floor = lo_u < out.floor ? lo_u : out.floor;
        out.ceiling = hi_u > out.ceiling ? hi_u : out.ceiling;
      }
  return out;
}

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
