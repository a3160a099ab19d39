#pragma once
/// @file
/// Small math pieces shared by the 2D and 3D runtime: the per-dimension types, the 2D rotation,
/// orientation integration without trigonometry, and a portable logarithm.
///
/// Determinism: the runtime uses only + - * / and sqrt, which IEEE 754 rounds exactly, so the
/// same inputs give the same bits on every conforming target built with -ffp-contract=off.
/// Library transcendentals (logf, cosf) differ between C libraries by an ulp, so the one the
/// runtime needs (a logarithm, for Gaussian samples) is computed here from those operations.

#include "statsim/config.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace statsim {

using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
using Quaternion = Eigen::Quaternion<Scalar>;

/// A 2D rotation stored as the unit complex number (cos a, sin a), so that integrating and
/// applying it needs no trigonometry.
struct Rot2 {
  Scalar c = 1;  ///< cos of the angle
  Scalar s = 0;  ///< sin of the angle

  /// From an angle in radians (counter-clockwise). Uses std::cos/std::sin: call it when setting
  /// up a scene, not inside a deterministic step.
  static Rot2 from_angle(Scalar radians) { return {std::cos(radians), std::sin(radians)}; }
  /// The angle in radians, in (-pi, pi].
  Scalar angle() const { return std::atan2(s, c); }
  Vector2 operator*(const Vector2& v) const { return {c * v.x() - s * v.y(), s * v.x() + c * v.y()}; }
  Rot2 operator*(const Rot2& o) const { return {c * o.c - s * o.s, s * o.c + c * o.s}; }
  Scalar squared_norm() const { return c * c + s * s; }
};

/// Types of one dimension: D = 2 or 3.
template <int D>
struct Space;

template <>
struct Space<3> {
  using Vec = Vector3;
  using Rot = Quaternion;
  using Spin = Vector3;  ///< angular velocity, rad/s, world frame
  static constexpr int up_axis = 2;
  /// Moment of inertia of a solid sphere over m r^2.
  static constexpr Scalar inertia_factor = Scalar(0.4);
  static Spin zero_spin() { return Spin::Zero(); }
  static Rot identity() { return Rot::Identity(); }
};

template <>
struct Space<2> {
  using Vec = Vector2;
  using Rot = Rot2;
  using Spin = Scalar;  ///< angular velocity, rad/s, counter-clockwise positive
  static constexpr int up_axis = 1;
  /// Moment of inertia of a solid disc over m r^2.
  static constexpr Scalar inertia_factor = Scalar(0.5);
  static Spin zero_spin() { return Scalar(0); }
  static Rot identity() { return Rot{}; }
};

namespace detail {

inline bool finite(Scalar x) { return std::isfinite(x); }
template <int R>
bool finite(const Eigen::Matrix<Scalar, R, 1>& v)
{
  for (int i = 0; i < R; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}
inline bool finite(const Quaternion& q) { return finite(q.coeffs()); }
inline bool finite(const Rot2& r) { return std::isfinite(r.c) && std::isfinite(r.s); }

/// Written out in the order of Eigen's scalar reduction of (x, y, z, w): its SSE reduction adds
/// in another order, and a build with vectorisation would round differently from one without
/// (a Cortex-M build, say).
inline Scalar squared_norm(const Quaternion& q)
{
  return (q.x() * q.x() + q.y() * q.y()) + (q.z() * q.z() + q.w() * q.w());
}
inline Scalar squared_norm(const Rot2& r) { return r.squared_norm(); }
inline Scalar squared_norm(Scalar w) { return w * w; }
template <int R>
Scalar squared_norm(const Eigen::Matrix<Scalar, R, 1>& v)
{
  return v.squaredNorm();
}

/// omega x r: in 2D, omega is the scalar z component and the result lies in the plane.
inline Vector3 cross(const Vector3& w, const Vector3& r) { return w.cross(r); }
inline Vector2 cross(Scalar w, const Vector2& r) { return {-w * r.y(), w * r.x()}; }
/// r x j: in 2D the scalar z component.
inline Vector3 moment(const Vector3& r, const Vector3& j) { return r.cross(j); }
inline Scalar moment(const Vector2& r, const Vector2& j) { return r.x() * j.y() - r.y() * j.x(); }

/// The Hamilton product a b, written out for the same reason as squared_norm(Quaternion): the
/// terms in the order of Eigen's scalar product, whatever the build vectorises.
inline Quaternion product(const Quaternion& a, const Quaternion& b)
{
  return Quaternion(a.w() * b.w() - a.x() * b.x() - a.y() * b.y() - a.z() * b.z(),
                    a.w() * b.x() + a.x() * b.w() + a.y() * b.z() - a.z() * b.y(),
                    a.w() * b.y() + a.y() * b.w() + a.z() * b.x() - a.x() * b.z(),
                    a.w() * b.z() + a.z() * b.w() + a.x() * b.y() - a.y() * b.x());
}

/// Rescales a rotation to unit length (sqrt is exactly rounded, so this is portable).
inline Quaternion normalized(const Quaternion& q)
{
  const Scalar inv = Scalar(1) / std::sqrt(squared_norm(q));
  return Quaternion(q.w() * inv, q.x() * inv, q.y() * inv, q.z() * inv);
}
inline Rot2 normalized(const Rot2& r)
{
  const Scalar inv = Scalar(1) / std::sqrt(r.squared_norm());
  return {r.c * inv, r.s * inv};
}

/// One explicit step of dq/dt = 1/2 (0, w) q, renormalised. Written out component by component
/// so that no vectorised product (which rounds differently from the scalar one) is involved.
inline Quaternion integrate(const Quaternion& q, const Vector3& w, Scalar dt)
{
  const Scalar h = Scalar(0.5) * dt;
  const Scalar wx = w.x() * h, wy = w.y() * h, wz = w.z() * h;
  const Quaternion r(q.w() - wx * q.x() - wy * q.y() - wz * q.z(),
                     q.x() + wx * q.w() + wy * q.z() - wz * q.y(),
                     q.y() - wx * q.z() + wy * q.w() + wz * q.x(),
                     q.z() + wx * q.y() - wy * q.x() + wz * q.w());
  return normalized(r);
}
/// d(c, s)/dt = w (-s, c), renormalised.
inline Rot2 integrate(const Rot2& r, Scalar w, Scalar dt)
{
  const Scalar a = w * dt;
  return normalized(Rot2{r.c - a * r.s, r.s + a * r.c});
}

/// Natural logarithm of x > 0 from + - * / only, accurate to about 1 ulp of float.
/// x = m 2^e with m in [sqrt(1/2), sqrt(2)); ln m = 2 atanh(t), t = (m-1)/(m+1), |t| < 0.172,
/// and the odd series 2(t + t^3/3 + ... + t^11/11) leaves a remainder below 1e-10.
inline float portable_log(float x)
{
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  int e = int((bits >> 23) & 0xffu) - 127;
  bits = (bits & 0x007fffffu) | 0x3f800000u;  // mantissa in [1, 2)
  float m;
  std::memcpy(&m, &bits, sizeof m);
  if (m > 1.41421356f) {
    m *= 0.5f;
    e += 1;
  }
  const float t = (m - 1.0f) / (m + 1.0f);
  const float t2 = t * t;
  const float series = t * (2.0f + t2 * (2.0f / 3 + t2 * (2.0f / 5 + t2 * (2.0f / 7 + t2 * (2.0f / 9 + t2 * (2.0f / 11))))));
  return float(e) * 0.693147180559945f + series;
}

/// FNV-1a over the bit patterns of values, for state hashes.
struct Fnv1a {
  std::uint64_t value = 0xcbf29ce484222325ull;
  void add_bytes(const void* data, std::size_t n)
  {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) value = (value ^ p[i]) * 0x100000001b3ull;
  }
  template <class T>
  void add(T x)
  {
    add_bytes(&x, sizeof x);
  }
  /// add() of each argument, left to right.
  template <class... T>
  void add_all(T... x)
  {
    (add(x), ...);
  }
  template <int R>
  void add_vec(const Eigen::Matrix<Scalar, R, 1>& v)
  {
    for (int i = 0; i < R; ++i) add(v[i]);
  }
  void add_rot(const Quaternion& q) { add_vec(Eigen::Matrix<Scalar, 4, 1>(q.coeffs())); }
  void add_rot(const Rot2& r)
  {
    add(r.c);
    add(r.s);
  }
  void add_spin(const Vector3& w) { add_vec(w); }
  void add_spin(Scalar w) { add(w); }
};

}  // namespace detail
}  // namespace statsim
