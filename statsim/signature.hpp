#pragma once
/// @file
/// A shape's statistical signature (paper 3.2): the collision-height table, the response tables
/// and the rest poses, as generated into `tables/NAME.hpp` by `statsim gather` / `gather2d`.
///
/// Generated tables are `Signature<D, ...>` objects whose array sizes are template arguments;
/// the world keeps a capacity-erased `SignatureView<D>` per shape (each array as a `Span`: its
/// pointer and its length), so one compiled step serves every table size.
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
///
/// Each cell holds the mean of its C response components (3D: 6, 2D: 3) and a spread whose form
/// the table's `ResponseModel` names (see there): C standard deviations (the paper's model), a
/// Cholesky factor of the C x C covariance, or K stored outcomes.

#include "statsim/config.hpp"
#include "statsim/detail/response.hpp"
#include "statsim/signature_contact.hpp"
#include "statsim/signature_landing.hpp"
#include "statsim/signature_settle.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>

namespace statsim {

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
  ValuesView mean;    ///< m, one per axis sample (at least `spin_ratio.size` values)
  ValuesView stddev;  ///< m, as many
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

/// Most response components (3D: w_xyz, dv_xyz).
constexpr std::uint32_t max_response_components = 6;

/// Most stored outcomes per cell of an `empirical` table.
constexpr std::uint32_t max_empirical_outcomes = 64;

/// How a response table describes the spread of a cell's outcomes about its mean; chosen at
/// gathering (`statsim gather --response-model`). C is the number of components (3D: 6, 2D: 3).
enum class ResponseModel : std::uint8_t {
  /// The paper's model (3.2.2): C standard deviations per cell, each component drawn from its
  /// own Gaussian. Keeps means and spreads, drops the correlations between components and
  /// any cell with two outcomes.
  independent_gaussian,
  /// C (C + 1) / 2 numbers per cell: the lower triangle, row by row, of a Cholesky factor L of
  /// the cell's covariance (L L^T = covariance). A draw is mean + L z, z standard normal, so the
  /// correlations between components (an impact that gains spin loses rebound) are kept.
  correlated_gaussian,
  /// K C numbers per cell: K outcomes of the reference's trials, each stored as its offset from
  /// the cell's mean. A draw is the interpolated mean plus one stored offset of one corner cell
  /// (the corner picked with its interpolation weight), so a cell with two outcomes keeps both.
  empirical,
};

/// The number of spread values per cell of `model` with `components` components and, for
/// `empirical`, `outcomes` stored outcomes.
constexpr std::uint32_t response_spread_size(ResponseModel model, std::uint32_t components, std::uint32_t outcomes = 0)
{
  return model == ResponseModel::independent_gaussian  ? components
         : model == ResponseModel::correlated_gaussian ? components * (components + 1) / 2
                                                       : components * outcomes;
}

/// A cell of a response table and its weight in a multilinear interpolation.
struct CellWeight {
  std::uint32_t cell;
  Scalar weight;
};

/// Response statistics on a grid (paper 3.2.2): per cell, `components` means and
/// `spread_per_cell` spread values (their form: `model`), cells in row-major order of the axes
/// (the first axis varies slowest). `mean` and `spread` hold at least that many values for the
/// product of the axes' sizes.
struct ResponseTableView {
  std::array<AxisView, max_response_axes> axes{};
  std::uint32_t axis_count = 0;
  std::uint32_t components = 0;
  ResponseModel model = ResponseModel::independent_gaussian;
  std::uint32_t spread_per_cell = 0;  ///< see `response_spread_size`
  ValuesView mean;
  ValuesView spread;

  /// The cells around `x` (one coordinate per axis, clamped at the table's edges) with their
  /// multilinear weights, those of weight 0 left out; returns how many (at most
  /// 2^axis_count). An axis of one sample contributes weight 1 at index 0.
  std::uint32_t corners(const Scalar* x, CellWeight* out) const
  {
    STATSIM_ASSERT(axis_count >= 1 && axis_count <= max_response_axes);
    AxisPoint p[max_response_axes];
    std::uint32_t stride[max_response_axes];
    std::uint32_t s = 1;
    for (std::uint32_t a = axis_count; a-- > 0;) {
      p[a] = locate(axes[a], x[a]);
      stride[a] = s;
      s *= axes[a].size;
    }
    std::uint32_t n = 0;
    for (std::uint32_t corner = 0; corner < (1u << axis_count); ++corner) {
      Scalar w = 1;
      std::uint32_t cell = 0;
      for (std::uint32_t a = 0; a < axis_count; ++a) {
        const bool upper = (corner >> a) & 1u;
        if (axes[a].size == 1) {
          if (upper) w = 0;
          continue;
        }
        w *= upper ? p[a].t : 1 - p[a].t;
        cell += (p[a].index + (upper ? 1u : 0u)) * stride[a];
      }
      if (w == 0) continue;
      out[n++] = {cell, w};
    }
    return n;
  }

  /// Multilinear interpolation at `x` of the means (`components` values to `mean_out`) and,
  /// when `spread_out` is given, of the spread values (`spread_per_cell` values), clamped at
  /// the table's edges. Interpolated standard deviations and Cholesky factors are again valid
  /// ones (a convex combination keeps the diagonal non-negative); stored outcomes are not
  /// interpolated this way by the runtime (see `ResponseModel::empirical`).
  void lookup(const Scalar* x, Scalar* mean_out, Scalar* spread_out = nullptr) const
  {
    CellWeight cw[1u << max_response_axes];
    interpolate(cw, corners(x, cw), mean_out, spread_out);
  }

  /// The weighted sum that `lookup` interpolates with, over `n` cells from `corners`.
  void interpolate(const CellWeight* cw, std::uint32_t n, Scalar* mean_out, Scalar* spread_out = nullptr) const
  {
    for (std::uint32_t c = 0; c < components; ++c) mean_out[c] = 0;
    if (spread_out)
      for (std::uint32_t c = 0; c < spread_per_cell; ++c) spread_out[c] = 0;
    for (std::uint32_t k = 0; k < n; ++k) {
      const Scalar w = cw[k].weight;
      const std::uint32_t m = cw[k].cell * components;
      for (std::uint32_t c = 0; c < components; ++c) mean_out[c] += w * mean[m + c];
      if (!spread_out) continue;
      const std::uint32_t o = cw[k].cell * spread_per_cell;
      for (std::uint32_t c = 0; c < spread_per_cell; ++c) spread_out[c] += w * spread[o + c];
    }
  }
};

/// Rest poses (paper 3.2.3): body-frame up vectors, centre heights and frequencies.
template <int D>
struct RestPosesView {
  Span<const Scalar> normals;      ///< D numbers per pose, unit, body frame
  ValuesView heights;              ///< m, centre of mass above the plane at rest
  Span<const Scalar> frequencies;  ///< fraction of reference drops that ended in the pose
  std::uint32_t count = 0;         ///< poses: at most what each of the three arrays holds
  typename Space<D>::Vec normal(std::uint32_t i) const
  {
    typename Space<D>::Vec n;
    for (int k = 0; k < D; ++k) n[k] = normals.values[i * D + k];
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

/// What the spin components of a response table measure (the generator writes one of these;
/// `statsim gather --response-spin`). |V-| is the speed the body struck with.
enum class ResponseSpin : std::uint8_t {
  /// W+ L / |V-|, in the contact frame: the paper's normalisation (3.3.2). The drawn spin does
  /// not depend on how the body is turned, so its kinetic energy does: on a thin shape a spin
  /// the reference made about the long axis, cheap there, may be drawn about a short one.
  length,
  /// K W+ / |V-|, in the contact frame, with K = R diag(sqrt(I_k / m)) R^T the body's radii of
  /// gyration about its principal axes at its orientation R. Half the squared length of the
  /// draw is the rotational kinetic energy over 1/2 m |V-|^2 whatever the orientation; the
  /// runtime takes W+ = R diag(sqrt(m / I_k)) R^T (draw) |V-| with the body's own R. 3D only.
  gyration,
  /// As `gyration`, and the table's spin-ratio coordinate measures the incoming spin by its
  /// energy too: |K W-| L / (k |V-|), k = sqrt((I_1 + I_2 + I_3) / 3m) the radius of gyration
  /// averaged over all axes (the gathering's trials are made at that ratio). With `gyration` a
  /// rod rolling fast about its long axis, cheap in energy, is looked up at a high ratio whose
  /// trials spun mostly about short axes, with up to (I_max / I_min) times the energy, and
  /// bounce as those do. For a body whose three moments are equal it is `gyration`. 3D only
  /// (format 2.5).
  energy,
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
  /// Of the response table's w components (format 2.4) and its spin-ratio coordinate (2.5)
  ResponseSpin spin = ResponseSpin::length;
  HeightTableView height;
  ResponseTableView response;  ///< components: 2D w, dv_x, dv_y; 3D w_xyz, dv_xyz
  RestPosesView<D> rest;
  /// Where the mesh the table was gathered from sits in the body frame: a mesh point m is the
  /// body point R (m - c), R (D x D, row by row) then c (m, mesh frame): D (D + 1) numbers, or
  /// none when the table does not record it (body frame = mesh frame).
  Span<const Scalar> mesh_frame;
  ContactView<D> contact;  ///< body-body data; absent (`present()` false) in older tables
  /// How often a body stays on the ground after an impact under gravity (3D tables of format
  /// 2.2); absent (`present()` false) in older tables and in 2D.
  LandingView landing;
  /// How long a body settles in each rest pose (3D tables of format 2.3); absent (`present()`
  /// false) in older tables and in 2D.
  SettleView settle;
  /// Size of the shape over the size the table was gathered at (`scaled_view`); 1 for the
  /// table's own view. Every length above already includes it; a mesh point m of the table's
  /// mesh is the body point scale R (m - c).
  Scalar scale = 1;
};

namespace detail {
template <class T, class = void>
struct is_quantized : std::false_type {};
template <class T>
struct is_quantized<T, std::void_t<decltype(std::declval<const T&>().q)>> : std::true_type {};

/// The view of a table's values: a contiguous array of Scalar, or a `Quantized16`-like object;
/// the length is the storage's own.
template <class Values>
constexpr ValuesView values_view(const Values& v)
{
  if constexpr (is_quantized<Values>::value) {
    return ValuesView{Span<const std::int16_t>(v.q), v.scale, v.offset};
  } else {
    return ValuesView{Span<const Scalar>(v)};
  }
}

template <class T, class = void>
struct has_contact_data : std::false_type {};
template <class T>
struct has_contact_data<T, std::void_t<decltype(std::declval<const T&>().contact.support)>> : std::true_type {};

template <class T, class = void>
struct has_landing_data : std::false_type {};
template <class T>
struct has_landing_data<T, std::void_t<decltype(std::declval<const T&>().landing.probability)>> : std::true_type {};

template <class T, class = void>
struct has_settle_data : std::false_type {};
template <class T>
struct has_settle_data<T, std::void_t<decltype(std::declval<const T&>().settle.time)>> : std::true_type {};

template <class T, class = void>
struct has_response_spin : std::false_type {};
template <class T>
struct has_response_spin<T, std::void_t<decltype(std::declval<const T&>().spin)>> : std::true_type {};

template <class T, class = void>
struct has_mesh_frame : std::false_type {};
template <class T>
struct has_mesh_frame<T, std::void_t<decltype(std::declval<const T&>().mesh_frame)>> : std::true_type {};

constexpr const char* c_str(const char* s) { return s; }
template <class S>
constexpr auto c_str(const S& s) -> decltype(s.c_str())
{
  return s.c_str();
}
}  // namespace detail

/// Builds the view of any signature storage that names its parts as `BasicSignature` does
/// (fixed-size arrays in generated tables, growable ones in host tools): every part is read
/// through `data()` and `size()`, which give each `Span` its length, and response values may be
/// Scalars or `Quantized16`-like. The one place where a table's view is filled.
template <int D, class S>
constexpr SignatureView<D> signature_view(const S& s)
{
  SignatureView<D> v;
  v.name = detail::c_str(s.name);
  v.length = s.length;
  v.bounding_radius = s.bounding_radius;
  v.mass = s.mass;
  v.unit_inertia = s.unit_inertia;
  v.material = s.material;
  v.restitution_threshold = s.restitution_threshold;
  v.layout = s.layout;
  if constexpr (detail::has_response_spin<S>::value) v.spin = s.spin;
  v.height.spin_ratio = AxisView(s.height_axis);
  v.height.mean = detail::values_view(s.height_mean);
  v.height.stddev = detail::values_view(s.height_stddev);
  v.response.axes = {{AxisView(s.axis0), AxisView(s.axis1), AxisView(s.axis2), AxisView(s.axis3)}};
  v.response.axis_count = s.axis_count;
  v.response.components = D == 3 ? 6u : 3u;
  v.response.model = s.model;
  // Spread values per cell from the stored count; a count that is not a whole number of cells
  // gives a size no model has, which `add_shape` rejects.
  std::uint32_t cells = 1;
  for (std::uint32_t a = 0; a < s.axis_count && a < max_response_axes; ++a) cells *= v.response.axes[a].size;
  v.response.mean = detail::values_view(s.response_mean);
  v.response.spread = detail::values_view(s.response_spread);
  const std::uint32_t spread_count = v.response.spread.count();
  v.response.spread_per_cell = cells > 0 && spread_count % cells == 0 ? spread_count / cells : 0;
  v.rest.normals = Span<const Scalar>(s.rest_normals);
  v.rest.heights = detail::values_view(s.rest_heights);
  v.rest.frequencies = Span<const Scalar>(s.rest_frequencies);
  v.rest.count = static_cast<std::uint32_t>(s.rest_heights.size());
  if constexpr (detail::has_mesh_frame<S>::value) {
    // A frame of another size (a host table's) reads as absent, as it always did.
    if (s.mesh_frame.size() == std::size_t(D * (D + 1))) v.mesh_frame = Span<const Scalar>(s.mesh_frame);
  }
  if constexpr (detail::has_contact_data<S>::value) {
    const auto& c = s.contact;
    v.contact.support_size = c.support_size;
    v.contact.support = detail::values_view(c.support);
    v.contact.pair_mean = c.pair_mean.size() > 0 ? detail::values_view(c.pair_mean) : ValuesView{};
    v.contact.pair_stddev = c.pair_stddev.size() > 0 ? detail::values_view(c.pair_stddev) : ValuesView{};
    if (c.faces.size() > 0) v.contact.faces = Span<const Scalar>(c.faces);
    v.contact.face_count = static_cast<std::uint32_t>(c.faces.size() / face_values(D));
    for (std::size_t k = 0; k < 3; ++k) {
      v.contact.packing_mean[k] = c.packing_mean[k];
      v.contact.packing_stddev[k] = c.packing_stddev[k];
    }
  }
  if constexpr (detail::has_landing_data<S>::value) {
    const auto& l = s.landing;
    if (l.probability.size() > 0) {
      v.landing.axes = {{AxisView(l.cos_theta), AxisView(l.spin_ratio), AxisView(l.froude)}};
      v.landing.probability = Span<const Scalar>(l.probability);
      v.landing.hop = l.hop;
    }
  }
  if constexpr (detail::has_settle_data<S>::value) {
    const auto& t = s.settle.time;
    if (t.size() > 0) {
      v.settle.time = Span<const Scalar>(t);
      v.settle.quantiles =
          v.rest.count > 0 && t.size() % v.rest.count == 0 ? static_cast<std::uint32_t>(t.size() / v.rest.count) : 0;
    }
  }
  return v;
}

namespace detail {
/// The identity mesh frame: R = I, c = 0.
template <int D>
constexpr std::array<Scalar, D*(D + 1)> identity_mesh_frame()
{
  std::array<Scalar, D*(D + 1)> f{};
  for (int k = 0; k < D; ++k) f[std::size_t(k * D + k)] = 1;
  return f;
}
}  // namespace detail

/// Storage of a generated signature; sizes are template arguments. Aggregate-initialised by the
/// generated header, read by the runtime through `view()`. `Means` and `Spreads` hold the
/// response tables: `std::array<Scalar, N>` (`Signature`) or `Quantized16<N>` (`SignatureQ16`).
///   NH: height samples; A0..A3: response axis sizes (unused axes 1); NR: rest poses;
///   `Contact`: `ContactData`/`ContactDataQ16`, or `NoContactData`;
///   `Landing`: `LandingData`, or `NoLandingData`; `Settle`: `SettleData`, or `NoSettleData`.
/// `mesh_frame` and `contact` are new in format 2.1, `landing` in 2.2, `settle` in 2.3 and
/// `spin` in 2.4; all have defaults, so an older table (which initialises everything before
/// them) still compiles and loads, without that data. `spin` belongs with `layout` and `model`
/// but comes last for that reason.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, class Means, class Spreads, class Contact = NoContactData, class Landing = NoLandingData,
          class Settle = NoSettleData>
struct BasicSignature {
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
  ResponseModel model;
  std::uint32_t axis_count;
  std::array<Scalar, NH> height_axis;
  std::array<Scalar, NH> height_mean;
  std::array<Scalar, NH> height_stddev;
  std::array<Scalar, A0> axis0;
  std::array<Scalar, A1> axis1;
  std::array<Scalar, A2> axis2;
  std::array<Scalar, A3> axis3;
  Means response_mean;
  Spreads response_spread;  ///< per cell: the spread values of `model`
  std::array<Scalar, NR * D> rest_normals;
  std::array<Scalar, NR> rest_heights;
  std::array<Scalar, NR> rest_frequencies;
  std::array<Scalar, D*(D + 1)> mesh_frame = detail::identity_mesh_frame<D>();  ///< see `SignatureView`
  Contact contact = {};
  Landing landing = {};
  Settle settle = {};
  ResponseSpin spin = ResponseSpin::length;  ///< see `SignatureView::spin`

  constexpr SignatureView<D> view() const { return signature_view<D>(*this); }
};

/// A signature with float response tables: what `statsim gather` and `gather2d` write.
/// S: spread values per cell (`response_spread_size` of the table's model; the default is the
/// paper's model, one standard deviation per component).
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::uint32_t S = (D == 3 ? 6u : 3u), class Contact = NoContactData,
          class Landing = NoLandingData, class Settle = NoSettleData>
using Signature = BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, A0 * A1 * A2 * A3 * (D == 3 ? 6u : 3u)>,
                                 std::array<Scalar, A0 * A1 * A2 * A3 * S>, Contact, Landing, Settle>;

/// A signature whose response tables are 16-bit integers (one scale and offset per table), for
/// firmware where flash is tight; made from a `Signature` by `quantize16`.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::uint32_t S = (D == 3 ? 6u : 3u), class Contact = NoContactData,
          class Landing = NoLandingData, class Settle = NoSettleData>
using SignatureQ16 = BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<A0 * A1 * A2 * A3 * (D == 3 ? 6u : 3u)>,
                                    Quantized16<A0 * A1 * A2 * A3 * S>, Contact, Landing, Settle>;

// A signature's precision: `quantize16` turns a float table into its 16-bit form by the rule
// every part of statsim uses, `dequantize` turns a 16-bit table back into floats as the runtime
// reads it.

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
          std::uint32_t NR, std::size_t NM, std::size_t NS, class C, class G, class T>
constexpr BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C, G, T> quantize16(
    const BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C, G, T>& s)
{
  BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C, G, T> q{
      s.name,        s.length,      s.bounding_radius, s.mass,         s.unit_inertia, s.material,
      s.restitution_threshold,      s.layout,          s.model,        s.axis_count,   s.height_axis,
      s.height_mean, s.height_stddev, s.axis0,         s.axis1,        s.axis2,        s.axis3,
      {},            {},            s.rest_normals,    s.rest_heights, s.rest_frequencies,
      s.mesh_frame,  s.contact,      s.landing,      s.settle,          s.spin};
  quantize16(s.response_mean.data(), s.response_mean.size(), q.response_mean.scale, q.response_mean.offset,
             q.response_mean.q.data());
  quantize16(s.response_spread.data(), s.response_spread.size(), q.response_spread.scale,
             q.response_spread.offset, q.response_spread.q.data());
  return q;
}


/// A table already in 16-bit form stays as it is: `quantize16(tables::box)` holds whichever
/// precision the committed table was generated with.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::size_t NM, std::size_t NS, class C, class G, class T>
constexpr const BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C, G, T>& quantize16(
    const BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C, G, T>& s)
{
  return s;
}

/// The float form of a 16-bit signature: each response value is offset + scale * q, computed as
/// the runtime reads a 16-bit table, so both forms give a world the same values. For builds that
/// need float tables (a test of the float path) from a table committed in 16 bits.
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::size_t NM, std::size_t NS, class C, class G, class T>
constexpr BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C, G, T> dequantize(
    const BasicSignature<D, NH, A0, A1, A2, A3, NR, Quantized16<NM>, Quantized16<NS>, C, G, T>& s)
{
  BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C, G, T> f{
      s.name,        s.length,      s.bounding_radius, s.mass,         s.unit_inertia, s.material,
      s.restitution_threshold,      s.layout,          s.model,        s.axis_count,   s.height_axis,
      s.height_mean, s.height_stddev, s.axis0,         s.axis1,        s.axis2,        s.axis3,
      {},            {},            s.rest_normals,    s.rest_heights, s.rest_frequencies,
      s.mesh_frame,  s.contact,      s.landing,      s.settle,          s.spin};
  for (std::size_t i = 0; i < NM; ++i)
    f.response_mean[i] = s.response_mean.offset + s.response_mean.scale * Scalar(s.response_mean.q[i]);
  for (std::size_t i = 0; i < NS; ++i)
    f.response_spread[i] = s.response_spread.offset + s.response_spread.scale * Scalar(s.response_spread.q[i]);
  return f;
}

/// A float table stays as it is (see the 16-bit overload).
template <int D, std::uint32_t NH, std::uint32_t A0, std::uint32_t A1, std::uint32_t A2, std::uint32_t A3,
          std::uint32_t NR, std::size_t NM, std::size_t NS, class C, class G, class T>
constexpr const BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C, G, T>& dequantize(
    const BasicSignature<D, NH, A0, A1, A2, A3, NR, std::array<Scalar, NM>, std::array<Scalar, NS>, C, G, T>& s)
{
  return s;
}

}  // namespace statsim
