#pragma once
/// @file
/// A shape's statistical signature (paper 3.2): the collision-height table, the response tables
/// and the rest poses, as generated into `tables/NAME.hpp` by `statsim gather` / `gather2d`.
///
/// Generated tables are `Signature<D, ...>` objects whose array sizes are template arguments;
/// the world keeps a capacity-erased `SignatureView<D>` per shape (pointers and sizes), so one
/// compiled step serves every table size.
///
/// Parametrisation. The tables never need an angle, only cosines and ratios, which the runtime
/// computes with + - * / and sqrt (portable bit for bit):
///  - spin ratio s = |w| L / |v|, L = `length` (the bounding radius): how fast the farthest point
///    moves from spin, relative to the linear speed. Dimensionless.
///  - incidence: cos(theta) = -v.n / |v|, theta the angle of V- to the inverse normal (1 = head-on).
///  - 3D spin angle: cos(phi) = v.w / (|v| |w|).
///  - 2D signed spin: the spin ratio with the sign of the spin as seen in the canonical frame.
///  - speed |v| (m/s), on tables that keep the paper's speed axis.
/// Responses are stored normalised: W+ L / |V-| and (V_rigid+ - V_particle+) / |V-|, in the
/// canonical frame (paper Figure 4a): normal = last axis (z in 3D, y in 2D), V- in the plane of
/// the first and last axes with a non-negative first component.

#include "statsim/config.hpp"
#include "statsim/response.hpp"

#include <array>
#include <cstdint>

namespace statsim {

/// Numbers of a table: stored as floats, or as 16-bit integers with value = offset + scale * q.
struct ValuesView {
  const Scalar* f32 = nullptr;
  const std::int16_t* i16 = nullptr;
  Scalar scale = 1;
  Scalar offset = 0;
  Scalar operator[](std::uint32_t i) const { return f32 ? f32[i] : offset + scale * Scalar(i16[i]); }
};

/// A sampled axis: `size` strictly increasing values.
struct AxisView {
  const Scalar* values = nullptr;
  std::uint32_t size = 0;
};

/// Where x falls on an axis: between sample `index` and `index + 1`, at fraction `t` in [0, 1].
/// Outside the axis it clamps to the end (t = 0 at the first sample, t = 1 at the last).
struct AxisPoint {
  std::uint32_t index;
  Scalar t;
};

/// Locates x on the axis by binary search; NaN lands on the first sample.
inline AxisPoint locate(const AxisView& axis, Scalar x)
{
  STATSIM_ASSERT(axis.size >= 1);
  if (axis.size == 1 || !(x > axis.values[0])) return {0, 0};
  const std::uint32_t last = axis.size - 1;
  if (x >= axis.values[last]) return {last - 1, 1};
  std::uint32_t lo = 0, hi = last;  // values[lo] < x < values[hi]... or equal to values[lo]
  while (hi - lo > 1) {
    const std::uint32_t mid = (lo + hi) / 2;
    if (axis.values[mid] <= x) lo = mid;
    else hi = mid;
  }
  return {lo, (x - axis.values[lo]) / (axis.values[hi] - axis.values[lo])};
}

/// Collision height h_coll against spin ratio (paper 3.2.1).
struct HeightTableView {
  AxisView spin_ratio;
  ValuesView mean;    ///< m, one per axis sample
  ValuesView stddev;  ///< m
  /// Mean height at spin ratio s, linearly interpolated and clamped.
  Scalar mean_at(Scalar s) const
  {
    const AxisPoint p = locate(spin_ratio, s);
    if (spin_ratio.size == 1) return mean[0];
    return mean[p.index] + (mean[p.index + 1] - mean[p.index]) * p.t;
  }
  /// Mean height at the nearest sample.
  Scalar nearest_at(Scalar s) const
  {
    const AxisPoint p = locate(spin_ratio, s);
    if (spin_ratio.size == 1) return mean[0];
    return p.t < Scalar(0.5) ? mean[p.index] : mean[p.index + 1];
  }
};

/// Largest number of axes of a response table (the paper's 4D layout).
constexpr std::uint32_t max_response_axes = 4;

/// Response statistics on a grid (paper 3.2.2): `components` means and standard deviations per
/// cell, cells in row-major order of the axes (the first axis varies slowest).
struct ResponseTableView {
  std::array<AxisView, max_response_axes> axes{};
  std::uint32_t axis_count = 0;
  std::uint32_t components = 0;
  ValuesView mean;
  ValuesView stddev;

  /// Multilinear interpolation of mean and stddev at `x` (one coordinate per axis), clamped at
  /// the table's edges. Writes `components` values to each output.
  void lookup(const Scalar* x, Scalar* mean_out, Scalar* stddev_out) const
  {
    STATSIM_ASSERT(axis_count >= 1 && axis_count <= max_response_axes);
    AxisPoint p[max_response_axes];
    std::uint32_t stride[max_response_axes];
    std::uint32_t s = components;
    for (std::uint32_t a = axis_count; a-- > 0;) {
      p[a] = locate(axes[a], x[a]);
      stride[a] = s;
      s *= axes[a].size;
    }
    for (std::uint32_t c = 0; c < components; ++c) mean_out[c] = stddev_out[c] = 0;
    // Visit the 2^axis_count corners; an axis of one sample contributes weight 1 at index 0.
    for (std::uint32_t corner = 0; corner < (1u << axis_count); ++corner) {
      Scalar w = 1;
      std::uint32_t offset = 0;
      for (std::uint32_t a = 0; a < axis_count; ++a) {
        const bool upper = (corner >> a) & 1u;
        if (axes[a].size == 1) {
          if (upper) w = 0;
          continue;
        }
        w *= upper ? p[a].t : 1 - p[a].t;
        offset += (p[a].index + (upper ? 1u : 0u)) * stride[a];
      }
      if (w == 0) continue;
      for (std::uint32_t c = 0; c < components; ++c) {
        mean_out[c] += w * mean[offset + c];
        stddev_out[c] += w * stddev[offset + c];
      }
    }
  }
};

/// Rest poses (paper 3.2.3): body-frame up vectors, centre heights and frequencies.
template <int D>
struct RestPosesView {
  const Scalar* normals = nullptr;      ///< D numbers per pose, unit, body frame
  const Scalar* heights = nullptr;      ///< m, centre of mass above the plane at rest
  const Scalar* frequencies = nullptr;  ///< fraction of reference drops that ended in the pose
  std::uint32_t count = 0;
  typename Space<D>::Vec normal(std::uint32_t i) const
  {
    typename Space<D>::Vec n;
    for (int k = 0; k < D; ++k) n[k] = normals[i * D + k];
    return n;
  }
};

/// Which axes a response table has, in order (the generator writes one of these).
enum class ResponseLayout : std::uint8_t {
  /// 3D: cos(theta), cos(phi), spin ratio. 2D: cos(theta), signed spin ratio.
  scaled,
  /// 3D: cos(theta), cos(phi), speed, spin ratio (the paper's four axes).
  /// 2D: cos(theta), signed spin ratio, speed.
  with_speed,
};

/// Everything the runtime knows about a shape.
template <int D>
struct SignatureView {
  const char* name = "";
  Scalar length = 0;           ///< L, m: the characteristic length of spin ratios
  Scalar bounding_radius = 0;  ///< m: farthest point of the shape from its centre of mass
  Scalar mass = 0;             ///< kg, of the reference body (responses do not depend on it)
  /// Principal moments of inertia over mass, m^2, about the body axes (2D: the first only).
  std::array<Scalar, 3> unit_inertia{};
  Material material{};         ///< restitution and friction the reference used, and V_particle+ uses
  Scalar restitution_threshold = 0;  ///< m/s, of V_particle+ (as the world's)
  ResponseLayout layout = ResponseLayout::scaled;
  HeightTableView height;
  ResponseTableView response;  ///< components: 2D w, dv_x, dv_y; 3D w_xyz, dv_xyz
  RestPosesView<D> rest;
};

/// Storage of a generated signature; sizes are template arguments. Aggregate-initialised by the
/// generated header, read by the runtime through `view()`.
///   NH: height samples; A0..A3: response axis sizes (unused axes 1); NR: rest poses.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR>
struct Signature {
  static constexpr std::uint32_t components = D == 3 ? 6 : 3;
  static constexpr std::uint32_t cells = A0 * A1 * A2 * A3;
  static_assert(NH >= 1 && A0 >= 1 && A1 >= 1 && A2 >= 1 && A3 >= 1, "every axis needs a sample");

  const char* name;
  Scalar length;
  Scalar bounding_radius;
  Scalar mass;
  std::array<Scalar, 3> unit_inertia;
  Material material;
  Scalar restitution_threshold;
  ResponseLayout layout;
  std::uint32_t axis_count;
  std::array<Scalar, NH> height_axis;
  std::array<Scalar, NH> height_mean;
  std::array<Scalar, NH> height_stddev;
  std::array<Scalar, A0> axis0;
  std::array<Scalar, A1> axis1;
  std::array<Scalar, A2> axis2;
  std::array<Scalar, A3> axis3;
  std::array<Scalar, cells * components> response_mean;
  std::array<Scalar, cells * components> response_stddev;
  std::array<Scalar, NR * D> rest_normals;
  std::array<Scalar, NR> rest_heights;
  std::array<Scalar, NR> rest_frequencies;

  constexpr SignatureView<D> view() const
  {
    SignatureView<D> v;
    v.name = name;
    v.length = length;
    v.bounding_radius = bounding_radius;
    v.mass = mass;
    v.unit_inertia = unit_inertia;
    v.material = material;
    v.restitution_threshold = restitution_threshold;
    v.layout = layout;
    v.height.spin_ratio = AxisView{height_axis.data(), NH};
    v.height.mean.f32 = height_mean.data();
    v.height.stddev.f32 = height_stddev.data();
    v.response.axes = {AxisView{axis0.data(), A0}, AxisView{axis1.data(), A1}, AxisView{axis2.data(), A2},
                       AxisView{axis3.data(), A3}};
    v.response.axis_count = axis_count;
    v.response.components = components;
    v.response.mean.f32 = response_mean.data();
    v.response.stddev.f32 = response_stddev.data();
    v.rest.normals = rest_normals.data();
    v.rest.heights = rest_heights.data();
    v.rest.frequencies = rest_frequencies.data();
    v.rest.count = NR;
    return v;
  }
};

/// A signature whose response tables are 16-bit integers (value = offset + scale * q, one
/// scale and offset per table), for firmware where flash is tight. Everything else as in
/// `Signature`.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR>
struct SignatureQ16 {
  static constexpr std::uint32_t components = D == 3 ? 6 : 3;
  static constexpr std::uint32_t cells = A0 * A1 * A2 * A3;
  static_assert(NH >= 1 && A0 >= 1 && A1 >= 1 && A2 >= 1 && A3 >= 1, "every axis needs a sample");

  const char* name;
  Scalar length;
  Scalar bounding_radius;
  Scalar mass;
  std::array<Scalar, 3> unit_inertia;
  Material material;
  Scalar restitution_threshold;
  ResponseLayout layout;
  std::uint32_t axis_count;
  std::array<Scalar, NH> height_axis;
  std::array<Scalar, NH> height_mean;
  std::array<Scalar, NH> height_stddev;
  std::array<Scalar, A0> axis0;
  std::array<Scalar, A1> axis1;
  std::array<Scalar, A2> axis2;
  std::array<Scalar, A3> axis3;
  Scalar mean_scale, mean_offset;
  std::array<std::int16_t, cells * components> response_mean;
  Scalar stddev_scale, stddev_offset;
  std::array<std::int16_t, cells * components> response_stddev;
  std::array<Scalar, NR * D> rest_normals;
  std::array<Scalar, NR> rest_heights;
  std::array<Scalar, NR> rest_frequencies;

  constexpr SignatureView<D> view() const
  {
    SignatureView<D> v;
    v.name = name;
    v.length = length;
    v.bounding_radius = bounding_radius;
    v.mass = mass;
    v.unit_inertia = unit_inertia;
    v.material = material;
    v.restitution_threshold = restitution_threshold;
    v.layout = layout;
    v.height.spin_ratio = AxisView{height_axis.data(), NH};
    v.height.mean.f32 = height_mean.data();
    v.height.stddev.f32 = height_stddev.data();
    v.response.axes = {AxisView{axis0.data(), A0}, AxisView{axis1.data(), A1}, AxisView{axis2.data(), A2},
                       AxisView{axis3.data(), A3}};
    v.response.axis_count = axis_count;
    v.response.components = components;
    v.response.mean = ValuesView{nullptr, response_mean.data(), mean_scale, mean_offset};
    v.response.stddev = ValuesView{nullptr, response_stddev.data(), stddev_scale, stddev_offset};
    v.rest.normals = rest_normals.data();
    v.rest.heights = rest_heights.data();
    v.rest.frequencies = rest_frequencies.data();
    v.rest.count = NR;
    return v;
  }
};

}  // namespace statsim
