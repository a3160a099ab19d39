#pragma once
/// @file
/// The body-body data of a signature (table format 2.1): the view the runtime reads
/// (`ContactView`) and the storage generated tables hold (`BasicContactData`), with the storage
/// of table numbers both use (`Span`, `ValuesView`, `AxisView`, `Quantized16`). Included by
/// signature.hpp.

#include "statsim/config.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>

namespace statsim {

/// An array a view reads and its length: `size` elements of T at `values`. Every array of a
/// view is held so, so that `add_shape` checks each count against the array it counts before it
/// reads one element (a count that runs past its array is `Status::invalid_shape`); the length
/// itself is the one number a view takes on trust. Made from a container (anything with `data()`
/// and `size()`: `std::array`, `std::vector`), which gives the length, or from a pointer and a
/// length; never from a bare pointer. Reads as the pointer it holds (`s[i]`, `s + k`, `s ==
/// nullptr`), so code that read a table through a pointer reads it through a span alike.
template <class T>
struct Span {
  T* values = nullptr;
  std::uint32_t size = 0;  ///< elements of T at `values`
  constexpr Span() = default;
  constexpr Span(std::nullptr_t) {}
  /// A length beyond 32 bits is kept as 2^32 - 1: less than the array holds, never more. (A
  /// shift, not a comparison, which a 32-bit size_t would make always false: a warning there.)
  constexpr Span(T* p, std::size_t n)
      : values(p), size(std::uint64_t(n) >> 32 ? 0xffffffffu : static_cast<std::uint32_t>(n))
  {
  }
  template <class U, std::enable_if_t<std::is_convertible<U*, T*>::value, int> = 0>
  constexpr Span(const Span<U>& s) : values(s.values), size(s.size)
  {
  }
  /// The whole of a container; lvalues only, as a view outlives the expression that makes it.
  template <class C, std::enable_if_t<std::is_convertible<decltype(std::declval<C&>().data()), T*>::value, int> = 0>
  constexpr Span(C& c) : Span(c.data(), c.size())
  {
  }
  /// The whole of a built-in array.
  template <class U, std::size_t N, std::enable_if_t<std::is_convertible<U*, T*>::value, int> = 0>
  constexpr Span(U (&a)[N]) : Span(a, N)
  {
  }
  constexpr operator T*() const { return values; }
};
template <class C>
Span(C&) -> Span<std::remove_pointer_t<decltype(std::declval<C&>().data())>>;
template <class U, std::size_t N>
Span(U (&)[N]) -> Span<U>;

/// Numbers of a table: stored as floats, value = scale * f32[i], or as 16-bit integers, value =
/// offset + scale * i16[i]; `count()` of them. A table's own view of floats has scale 1 (x * 1 is
/// x, bit for bit); a shape of another size (`scaled_view`) multiplies scale, and offset, by its
/// size factor. Compares equal to nullptr when it holds no values.
struct ValuesView {
  Span<const Scalar> f32;
  Span<const std::int16_t> i16;
  Scalar scale = 1;
  Scalar offset = 0;
  constexpr ValuesView() = default;
  constexpr ValuesView(std::nullptr_t) {}
  /// Floats, read as they are (scale 1).
  constexpr ValuesView(Span<const Scalar> f) : f32(f) {}
  /// 16-bit integers q, read as offset + scale * q.
  constexpr ValuesView(Span<const std::int16_t> q, Scalar s, Scalar o) : i16(q), scale(s), offset(o) {}
  /// Values that can be read: the length of the storage in use (floats when there are any).
  constexpr std::uint32_t count() const { return f32.values ? f32.size : i16.size; }
  /// Value i (any integer index, as a pointer takes).
  template <class Index>
  Scalar operator[](Index i) const
  {
    return f32.values ? f32.values[i] * scale : offset + scale * Scalar(i16.values[i]);
  }
  friend constexpr bool operator==(const ValuesView& v, std::nullptr_t) { return !v.f32.values && !v.i16.values; }
  friend constexpr bool operator!=(const ValuesView& v, std::nullptr_t) { return v.f32.values || v.i16.values; }
};

/// A sampled axis: `size` strictly increasing values.
using AxisView = Span<const Scalar>;

/// 16-bit storage of N table values: value = offset + scale * Scalar(q[i]).
template <std::size_t N>
struct Quantized16 {
  Scalar scale;
  Scalar offset;
  std::array<std::int16_t, N> q;
};

/// Body-body data of a shape (optional: `support_size` 0 when the table has none), from
/// `statsim gather`'s pair runs (tools/ref3d/README.md, "Body-body statistics"):
///  - the pair distance: centre distance of two bodies of the shape at their first contact,
///    thrown head-on at uniform random orientations, mean and spread on the h_coll axis: the
///    pair counterpart of h_coll;
///  - the support map of the convex hull, s(u) = max over hull points p of u.p in body
///    direction u: on each face of the cube |x|_inf = 1 (3D; the square's sides in 2D),
///    S x S (2D: S) samples of s at p = (+-1, a, b), axes cyclic, a, b = -1 + 2 i / (S - 1);
///    face f = 2 m + (u_m < 0) for u's largest component m (the first of equals), value
///    (f S + i) S + j (2D: f S + i). It is never below the hull's support, so two bodies placed
///    by it never overlap their hulls;
///  - the hull's largest faces (2D: edges), largest first: outward unit normal in the body frame,
///    its distance from the centre of mass (m), and the packing ratio of contacts along it;
///  - packing: centre distance of touching neighbours in reference piles over the distance
///    their hulls allow along the line of centres (1 for convex shapes; below 1 where concave
///    shapes nest). Per face, over the pairs whose hull contact is along that face (a face of
///    the shape itself holds a neighbour at its hull, ratio 1; a hull face across a hollow lets
///    it in); and, for pairs touching along their line of centres, mean and standard deviation
///    for lines of centres 0-30, 30-60 and 60-90 degrees from the vertical.
/// Numbers stored per hull face: D of the unit normal, the offset, the packing ratio.
constexpr std::uint32_t face_values(int d) { return std::uint32_t(d) + 2; }

/// Most support map nodes a side that the runtime takes (65: a 3D map of 25,350 values).
constexpr std::uint32_t max_support_size = 65;
/// Most hull faces a table may give for body-body contacts; each is a candidate normal, so
/// they bound the cost of a contact.
constexpr std::uint32_t max_contact_faces = 32;

template <int D>
struct ContactView {
  std::uint32_t support_size = 0;  ///< S, >= 2; 0: no body-body data
  ValuesView support;              ///< m, exactly `support_count()` values: 6 S^2 (2D: 4 S)
  ValuesView pair_mean;    ///< m, one per h_coll axis sample (at least); or none
  ValuesView pair_stddev;  ///< m, as many
  /// `face_values(D)` numbers per face: unit normal, offset (m, times `offset_scale`), packing
  /// ratio; at least `face_count` faces
  Span<const Scalar> faces;
  std::uint32_t face_count = 0;
  /// Factor on the stored face offsets: 1 for the table's own size, its size factor for a
  /// shape of another size (`scaled_view`).
  Scalar offset_scale = 1;
  /// Offset of face i, m.
  Scalar face_offset(std::uint32_t i) const { return faces.values[i * face_values(D) + D] * offset_scale; }
  std::array<Scalar, 3> packing_mean{};    ///< ratio, by angle of the line of centres
  std::array<Scalar, 3> packing_stddev{};  ///< ratio
  bool present() const { return support_size >= 2; }
  /// Number of support values: 6 S^2 in 3D, 4 S in 2D.
  std::uint32_t support_count() const { return D == 3 ? 6 * support_size * support_size : 4 * support_size; }
};

/// Body-body data of a generated signature (see `ContactView`); sizes are template arguments.
///   NH: samples of the h_coll axis (the pair distance's axis); S: support map nodes per side;
///   K: hull faces; `Support`: `std::array<Scalar, N>` or `Quantized16<N>`,
///   N = `support_values(D, S)`.
template <int D, std::uint32_t NH, std::uint32_t S, std::uint32_t K, class Support>
struct BasicContactData {
  static_assert(S >= 2, "a support map needs at least 2 nodes a side");
  std::uint32_t support_size;
  std::array<Scalar, NH> pair_mean;    ///< m
  std::array<Scalar, NH> pair_stddev;  ///< m
  Support support;                     ///< m
  std::array<Scalar, K * face_values(D)> faces;
  std::array<Scalar, 3> packing_mean;
  std::array<Scalar, 3> packing_stddev;
};

/// Values of a support map with S nodes a side: 6 S^2 in 3D, 4 S in 2D.
constexpr std::uint32_t support_values(int d, std::uint32_t s) { return d == 3 ? 6 * s * s : 4 * s; }

template <int D, std::uint32_t NH, std::uint32_t S, std::uint32_t K>
using ContactData = BasicContactData<D, NH, S, K, std::array<Scalar, support_values(D, S)>>;
template <int D, std::uint32_t NH, std::uint32_t S, std::uint32_t K>
using ContactDataQ16 = BasicContactData<D, NH, S, K, Quantized16<support_values(D, S)>>;

/// The `contact` of a table without body-body data (tables of format 2.0).
struct NoContactData {};

}  // namespace statsim
