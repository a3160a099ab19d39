#pragma once
/// @file
/// A signature's precision: `quantize16` turns a float table into its 16-bit form by the rule
/// every part of statsim uses, `dequantize` turns a 16-bit table back into floats as the runtime
/// reads it. Included by signature.hpp.

#include "statsim/signature.hpp"

#include <cstddef>
#include <cstdint>

namespace statsim {

namespace detail {
/// Nearest integer, ties to even (what std::nearbyint gives in the default rounding mode), for
/// |x| < 2^62; constexpr where std::nearbyint is not.
constexpr double round_half_even(double x)
{
  const double t = double(static_cast<long long>(x));  // truncated toward zero
  const double r = x - t;
  const bool odd = static_cast<long long>(t) % 2 != 0;
  if (r > 0.5 || (r == 0.5 && odd)) return t + 1;
  if (r < -0.5 || (r == -0.5 && odd)) return t - 1;
  return t;
}
}  // namespace detail

/// The 16-bit rule, the one every part of statsim uses (`statsim gather --precision i16`, the
/// firmware, JSON tables): offset = mid-range, scale = range / 65534 (1 for a constant table),
/// q = the nearest integer, ties to even, of (value - offset) / scale in double precision,
/// clamped to +-32767. Works on `n` values at `values`; constexpr, so a table can be quantised at
/// compile time and only its 16-bit form kept in flash.
constexpr void quantize16(const Scalar* values, std::size_t n, Scalar& scale, Scalar& offset, std::int16_t* q)
{
  if (n == 0) {
    scale = 1;
    offset = 0;
    return;
  }
  Scalar lo = values[0], hi = values[0];
  for (std::size_t i = 0; i < n; ++i) {
    lo = values[i] < lo ? values[i] : lo;
    hi = values[i] > hi ? values[i] : hi;
  }
  offset = Scalar(0.5) * (lo + hi);
  scale = hi > lo ? (hi - lo) / Scalar(65534) : Scalar(1);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = detail::round_half_even((double(values[i]) - double(offset)) / double(scale));
    q[i] = static_cast<std::int16_t>(r < -32767 ? -32767 : r > 32767 ? 32767 : r);
  }
}

/// The 16-bit form of a float signature, by the rule of `quantize16`: everything but the response
/// tables is copied (body-body data too, in the precision it has). `inline constexpr auto t16 = statsim::quantize16(tables::box);` keeps only
/// the 16-bit table in the program.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::size_t NM, std::size_t NS, class C>
constexpr BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C> quantize16(
    const BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C>& s)
{
  BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C> q{
      s.name,        s.length,      s.bounding_radius, s.mass,         s.unit_inertia, s.material,
      s.restitution_threshold,      s.layout,          s.model,        s.axis_count,   s.height_axis,
      s.height_mean, s.height_stddev, s.axis0,         s.axis1,        s.axis2,        s.axis3,
      {},            {},            s.rest_normals,    s.rest_heights, s.rest_frequencies,
      s.mesh_frame,  s.contact};
  quantize16(s.response_mean.data(), s.response_mean.size(), q.response_mean.scale, q.response_mean.offset,
             q.response_mean.q.data());
  quantize16(s.response_spread.data(), s.response_spread.size(), q.response_spread.scale,
             q.response_spread.offset, q.response_spread.q.data());
  return q;
}


/// A table already in 16-bit form stays as it is: `quantize16(tables::box)` holds whichever
/// precision the committed table was generated with.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::size_t NM, std::size_t NS, class C>
constexpr const BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C>& quantize16(
    const BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C>& s)
{
  return s;
}

/// The float form of a 16-bit signature: each response value is offset + scale * q, computed as
/// the runtime reads a 16-bit table, so both forms give a world the same values. For builds that
/// need float tables (a test of the float path) from a table committed in 16 bits.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::size_t NM, std::size_t NS, class C>
constexpr BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C> dequantize(
    const BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C>& s)
{
  BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C> f{
      s.name,        s.length,      s.bounding_radius, s.mass,         s.unit_inertia, s.material,
      s.restitution_threshold,      s.layout,          s.model,        s.axis_count,   s.height_axis,
      s.height_mean, s.height_stddev, s.axis0,         s.axis1,        s.axis2,        s.axis3,
      {},            {},            s.rest_normals,    s.rest_heights, s.rest_frequencies,
      s.mesh_frame,  s.contact};
  for (std::size_t i = 0; i < NM; ++i)
    f.response_mean[i] = s.response_mean.offset + s.response_mean.scale * Scalar(s.response_mean.q[i]);
  for (std::size_t i = 0; i < NS; ++i)
    f.response_spread[i] = s.response_spread.offset + s.response_spread.scale * Scalar(s.response_spread.q[i]);
  return f;
}

/// A float table stays as it is (see the 16-bit overload).
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::size_t NM, std::size_t NS, class C>
constexpr const BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C>& dequantize(
    const BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C>& s)
{
  return s;
}

}  // namespace statsim
