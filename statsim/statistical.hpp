#pragma once
/// @file
/// The statistical collision model of paper 3.3 as pure functions: the collision radius from the
/// height table, the canonical frame of a contact, the sampled response, and the rest-pose
/// helpers of paper 3.4. The world calls these; tests call them directly.

#include "statsim/random.hpp"
#include "statsim/signature.hpp"

#include <cmath>
#include <limits>
#include <type_traits>

namespace statsim {

/// Spin ratio s = |w| L / |v|, clamped to [0, max_ratio]. Never divides by a vanishing |v|:
/// when |w| L >= max_ratio |v| (which covers |v| = 0 with any spin) the result is max_ratio,
/// and a body without spin has s = 0.
template <int D>
Scalar spin_ratio(const typename Space<D>::Vec& v, const typename Space<D>::Spin& w, Scalar length, Scalar max_ratio)
{
  const Scalar spin = std::sqrt(detail::squared_norm(w)) * length;
  if (!(spin > 0)) return 0;
  const Scalar speed = v.norm();
  if (spin >= max_ratio * speed) return max_ratio;
  return spin / speed;
}

/// The collision radius of paper 3.3.1: the mean h_coll at the body's spin ratio, interpolated
/// (or from the nearest sample).
template <int D>
Scalar collision_radius(const SignatureView<D>& sig, const typename Space<D>::Vec& v,
                        const typename Space<D>::Spin& w, bool nearest = false)
{
  const AxisView& axis = sig.height.spin_ratio;
  const Scalar s = spin_ratio<D>(v, w, sig.length, axis.values[axis.size - 1]);
  return nearest ? sig.height.nearest_at(s) : sig.height.mean_at(s);
}

/// The canonical frame of a contact (paper Figure 4): `basis` maps canonical coordinates to
/// world ones. Its last column is the collision normal; its first is the tangential direction of
/// the velocity, so that V- has a non-negative first coordinate. When the velocity has no
/// tangential part the first axis follows the spin's tangential part (3D), else a fixed
/// perpendicular of the normal. In 2D the two possible tangents are mirror images, and
/// `mirror` (+1 or -1) is the sign by which the spin changes between the frames.
template <int D>
struct ContactFrame {
  Eigen::Matrix<Scalar, D, D> basis;
  Scalar mirror = 1;
};

namespace detail {
/// A unit vector perpendicular to the unit vector n, from the world axis least aligned with it.
inline Vector3 any_perpendicular(const Vector3& n)
{
  const Scalar ax = std::fabs(n.x()), ay = std::fabs(n.y()), az = std::fabs(n.z());
  const int k = ax <= ay && ax <= az ? 0 : (ay <= az ? 1 : 2);
  const Vector3 e = Vector3::Unit(k);
  return (e - n * n.dot(e)).normalized();
}
}  // namespace detail

inline ContactFrame<3> contact_frame(const Vector3& n, const Vector3& v, const Vector3& w)
{
  const Vector3 t = v - n * v.dot(n);
  const Scalar tn = t.norm();
  Vector3 x;
  if (tn > Scalar(1e-6) * v.norm()) {
    x = t / tn;
  } else {
    const Vector3 wt = w - n * w.dot(n);
    const Scalar wn = wt.norm();
    x = wn > Scalar(1e-12) ? Vector3(wt / wn) : detail::any_perpendicular(n);
  }
  ContactFrame<3> f;
  f.basis.col(0) = x;
  f.basis.col(1) = n.cross(x);
  f.basis.col(2) = n;
  return f;
}

inline ContactFrame<2> contact_frame(const Vector2& n, const Vector2& v, Scalar /*w*/)
{
  const Vector2 perp(n.y(), -n.x());  // (perp, n) is a proper rotation
  ContactFrame<2> f;
  f.mirror = v.dot(perp) >= 0 ? Scalar(1) : Scalar(-1);
  f.basis.col(0) = perp * f.mirror;
  f.basis.col(1) = n;
  return f;
}

/// Kinetic energy per unit mass of a body of the signature's shape, J/kg.
template <int D>
Scalar kinetic_energy_per_mass(const SignatureView<D>& sig, const typename Space<D>::Rot& orientation,
                               const typename Space<D>::Vec& v, const typename Space<D>::Spin& w)
{
  if constexpr (D == 3) {
    const Vector3 wb = orientation.conjugate() * w;
    return Scalar(0.5) * (v.squaredNorm() + sig.unit_inertia[0] * wb.x() * wb.x() +
                          sig.unit_inertia[1] * wb.y() * wb.y() + sig.unit_inertia[2] * wb.z() * wb.z());
  } else {
    (void)orientation;
    return Scalar(0.5) * (v.squaredNorm() + sig.unit_inertia[0] * w * w);
  }
}

/// What `statistical_response` did.
struct ResponseOutcome {
  bool applied = false;         ///< the body was approaching; v and w were replaced
  bool energy_clamped = false;  ///< the sample had more kinetic energy than the contact, and was scaled
  bool stayed = false;          ///< the landing data kept the body on the plane (no normal velocity)
  bool redrawn = false;         ///< the landing data had a response that would have stayed drawn again
};

/// The landing probability of a body striking the ground (`LandingView`: above 0, the extra
/// probability that it stays; below 0, minus the probability that a response that would stay is
/// drawn again), at cos theta `cos_theta`, spin ratio `spin_ratio` and Froude number `froude`:
/// multilinear in the table's cells, clamped at its edges. 0 without landing data.
inline Scalar landing_probability(const LandingView& landing, Scalar cos_theta, Scalar spin_ratio, Scalar froude)
{
  if (!landing.present()) return 0;
  ResponseTableView table;
  for (std::uint32_t a = 0; a < landing_axes; ++a) table.axes[a] = landing.axes[a];
  table.axis_count = landing_axes;
  table.components = 1;
  table.mean = ValuesView(landing.probability);
  const Scalar x[landing_axes] = {cos_theta, spin_ratio, froude};
  Scalar p;
  table.lookup(x, &p);
  return p;
}

/// Table coordinates of a contact (paper 3.3.2 step 4), in the order of the table's axes.
/// `v` is the velocity relative to the collision plane; it must approach it (v.n < 0).
template <int D>
std::uint32_t response_coordinates(const SignatureView<D>& sig, const ContactFrame<D>& frame,
                                   const typename Space<D>::Rot& orientation,
                                   const typename Space<D>::Vec& n, const typename Space<D>::Vec& v,
                                   const typename Space<D>::Spin& w, Scalar* x)
{
  const Scalar speed = v.norm();
  const Scalar cos_theta = -v.dot(n) / speed;
  std::uint32_t k = 0;
  x[k++] = cos_theta;
  if constexpr (D == 3) {
    (void)frame;
    const Scalar wn = w.norm();
    x[k++] = wn > 0 ? v.dot(w) / (speed * wn) : Scalar(0);
    if (sig.layout == ResponseLayout::with_speed) x[k++] = speed;
    Scalar spin = wn;
    if (sig.spin == ResponseSpin::energy) {
      // |K W-| / k: |K W-|^2 = W^T (I / m) W is twice the rotational energy per unit mass, and
      // k^2 = tr(I / m) / 3 its mean over spin axes drawn uniformly, as the trials draw them.
      const Scalar kw2 = 2 * kinetic_energy_per_mass<3>(sig, orientation, Vector3::Zero(), w);
      const Scalar k2 = (sig.unit_inertia[0] + sig.unit_inertia[1] + sig.unit_inertia[2]) / 3;
      spin = std::sqrt(kw2 / k2);
    }
    x[k++] = spin * sig.length / speed;
  } else {
    (void)orientation;
    x[k++] = frame.mirror * w * sig.length / speed;
    if (sig.layout == ResponseLayout::with_speed) x[k++] = speed;
  }
  return k;
}

/// One draw of a response table's model at table coordinates `x` (one per axis): writes
/// `table.components` normalised response components to `out`. The table must have passed
/// `add_shape`'s checks (its spread size is its model's).
inline void sample_response(const ResponseTableView& table, const Scalar* x, Pcg32& rng, Scalar* out)
{
  constexpr std::uint32_t C = max_response_components;
  const std::uint32_t n = table.components;
  STATSIM_ASSERT(n <= C);
  Scalar mean[C];
  switch (table.model) {
    case ResponseModel::independent_gaussian: {
      Scalar stddev[C];
      STATSIM_ASSERT(table.spread_per_cell == n);
      table.lookup(x, mean, stddev);
      for (std::uint32_t c = 0; c < n; c += 2) {
        float g0, g1;
        rng.gaussian_pair(g0, g1);
        out[c] = mean[c] + stddev[c] * g0;
        if (c + 1 < n) out[c + 1] = mean[c + 1] + stddev[c + 1] * g1;
      }
      return;
    }
    case ResponseModel::correlated_gaussian: {
      // out = mean + L z, L lower triangular stored row by row: row i starts at i (i + 1) / 2.
      Scalar factor[C * (C + 1) / 2], z[C];
      STATSIM_ASSERT(table.spread_per_cell == n * (n + 1) / 2);
      table.lookup(x, mean, factor);
      for (std::uint32_t c = 0; c < n; c += 2) {
        float g0, g1;
        rng.gaussian_pair(g0, g1);
        z[c] = g0;
        if (c + 1 < n) z[c + 1] = g1;
      }
      for (std::uint32_t i = 0; i < n; ++i) {
        const Scalar* row = factor + i * (i + 1) / 2;
        Scalar sum = mean[i];
        for (std::uint32_t j = 0; j <= i; ++j) sum += row[j] * z[j];
        out[i] = sum;
      }
      return;
    }
    case ResponseModel::empirical: {
      // A mixture of the corner cells, each with its interpolation weight (their means
      // interpolate as in the Gaussian models): one stored outcome of one corner, about the
      // interpolated mean. Picking rather than blending outcomes keeps a cell's separate modes.
      CellWeight cw[1u << max_response_axes];
      const std::uint32_t corners = table.corners(x, cw);
      table.interpolate(cw, corners, mean);
      const Scalar u = rng.uniform();
      std::uint32_t pick = corners - 1;
      Scalar below = 0;
      for (std::uint32_t k = 0; k + 1 < corners; ++k) {
        below += cw[k].weight;
        if (u < below) {
          pick = k;
          break;
        }
      }
      const std::uint32_t outcomes = table.spread_per_cell / n;
      // Multiply-shift maps 32 random bits onto [0, outcomes) without a division.
      const std::uint32_t k = std::uint32_t((std::uint64_t(rng.next_u32()) * outcomes) >> 32);
      const std::uint32_t base = cw[pick].cell * table.spread_per_cell + k * n;
      for (std::uint32_t c = 0; c < n; ++c) out[c] = mean[c] + table.spread[base + c];
      return;
    }
  }
  for (std::uint32_t c = 0; c < n; ++c) out[c] = 0;  // unreachable for a checked table
}

/// The statistical response of paper 3.3.2, steps 2 to 8, for one body against a collision
/// plane with unit normal `n` (pointing towards the body). `v` is the body's velocity relative to
/// the plane (to the other body, for body-body contacts), `w` its spin; both are replaced.
/// `orientation` (body to world) is needed for the energy guard, which scales the sampled
/// response down when it would leave more kinetic energy than the body brought to the contact,
/// and for a table whose spin is measured by `ResponseSpin::gyration` or `energy`.
/// The normal part of the new velocity is kept non-negative: a sphere that still approached the
/// plane would collide again at once.
/// `gravity` (m/s^2) is the part of gravity that presses the body onto the plane, for a contact
/// with a plane; 0 (the default, and for body-body contacts) or less leaves the landing data out.
/// With landing data and gravity, a draw made before the response decides whether the body stays
/// on the plane (`LandingView`): it then keeps the response's tangential velocity and leaves
/// with no normal velocity and no spin; or, where the table's probability is negative, whether a
/// response that would stay is drawn again. Without landing data no such draw is made, so older
/// tables give the same bits as before.
template <int D>
ResponseOutcome statistical_response(const SignatureView<D>& sig, const typename Space<D>::Rot& orientation,
                                     const typename Space<D>::Vec& n, typename Space<D>::Vec& v,
                                     typename Space<D>::Spin& w, Pcg32& rng, Scalar gravity = 0)
{
  using Vec = typename Space<D>::Vec;
  using Spin = typename Space<D>::Spin;
  ResponseOutcome out;
  const Scalar vn = v.dot(n);
  if (!(vn < 0)) return out;
  const Scalar speed = v.norm();
  const ContactFrame<D> frame = contact_frame(n, v, w);

  Scalar x[max_response_axes];
  response_coordinates<D>(sig, frame, orientation, n, v, w, x);
  // Landing data: one draw u before the response; p = the table's probability here. u < p keeps
  // the body on the plane; u < -p draws again a response that would stay (rise below hop L).
  const bool landing = sig.landing.present() && gravity > 0;
  Scalar p = 0, u = 1;
  if (landing) {
    // x holds cos theta first and the spin ratio last (3D) or second (2D), whatever the layout.
    const Scalar spin = D == 3 ? x[sig.layout == ResponseLayout::with_speed ? 3 : 2] : std::fabs(x[1]);
    const Scalar froude = speed * speed / (gravity * sig.length);
    p = landing_probability(sig.landing, x[0], spin, froude);
    u = rng.uniform();
  }
  const bool stay = u < p;
  constexpr int C = D == 3 ? 6 : 3;  // spin components, then velocity-offset components
  STATSIM_ASSERT(sig.response.components == std::uint32_t(C));
  const Vec v_particle = point_particle_velocity<D>(v, n, sig.material, sig.restitution_threshold);
  Spin w_new;
  Vec v_new;
  // One draw of the tables, back to the world frame and to physical units: W+ = w_c |V-| / L,
  // offset = dv_c |V-|.
  const auto draw = [&]() {
    Scalar sample[C];
    sample_response(sig.response, x, rng, sample);
    Vec offset;
    if constexpr (D == 3) {
      const Vector3 drawn = frame.basis * Vector3(sample[0], sample[1], sample[2]);
      if (sig.spin != ResponseSpin::length) {
        // W+ = R diag(sqrt(m / I_k)) R^T (draw) |V-|: the draw's rotational energy, 1/2 |draw|^2
        // |V-|^2 per unit mass, whichever way the body is turned.
        Vector3 body = orientation.conjugate() * drawn;
        for (int k = 0; k < 3; ++k) body[k] /= std::sqrt(sig.unit_inertia[std::size_t(k)]);
        w_new = orientation * body * speed;
      } else {
        w_new = drawn * (speed / sig.length);
      }
      offset = frame.basis * Vector3(sample[3], sample[4], sample[5]) * speed;
    } else {
      w_new = frame.mirror * sample[0] * (speed / sig.length);
      offset = frame.basis * Vector2(sample[1], sample[2]) * speed;
    }
    v_new = v_particle + offset;
    const Scalar vn_new = v_new.dot(n);
    if (vn_new < 0 || stay) v_new -= n * vn_new;
    // The drawn spin belongs to the gravity-free flight the stay replaces; a body held down
    // turns onto the ground instead, which the rest poses then steer.
    if (stay) w_new = Spin(w_new * Scalar(0));
  };
  draw();
  if (u < -p) {
    // v_n^2 < 2 g hop L: the centre would rise less than hop L.
    const Scalar vn_new = v_new.dot(n);
    if (vn_new * vn_new < 2 * gravity * sig.landing.hop * sig.length) {
      draw();
      out.redrawn = true;
    }
  }
  out.stayed = stay;

  // Energy guard: kinetic energy per unit mass, 1/2 |v|^2 + 1/2 w^T (I/m) w.
  const Scalar before = kinetic_energy_per_mass<D>(sig, orientation, v, w);
  const Scalar after = kinetic_energy_per_mass<D>(sig, orientation, v_new, w_new);
  if (after > before) {
    const Scalar f = std::sqrt(before / after);
    v_new *= f;
    w_new = w_new * f;
    out.energy_clamped = true;
  }
  v = v_new;
  w = w_new;
  out.applied = true;
  return out;
}

/// Most rest poses a statistical shape may have (the gatherers keep no more).
constexpr std::uint32_t max_rest_poses = 32;

/// The rest pose needing the smallest rotation (paper 3.4): the one whose body-frame normal,
/// turned into the world, is closest to `up`, each cosine raised by `bias[i]` when given (see
/// `rest_basin_biases`). Returns `sig.rest.count` when there are none.
template <int D>
std::uint32_t nearest_rest_pose(const SignatureView<D>& sig, const typename Space<D>::Rot& orientation,
                                const typename Space<D>::Vec& up, const Scalar* bias = nullptr)
{
  std::uint32_t best = sig.rest.count;
  Scalar best_score = -std::numeric_limits<Scalar>::infinity();
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    const Scalar d = (orientation * sig.rest.normal(i)).dot(up) + (bias ? bias[i] : Scalar(0));
    if (d > best_score) {
      best_score = d;
      best = i;
    }
  }
  return best;
}

namespace detail {
/// Directions spread evenly over the unit sphere (a Fibonacci lattice of `count` points: equal
/// steps in z, the azimuth turned by the golden angle) or, in 2D, the unit circle (equal steps in
/// angle, half a step from 0). Only + - * / and sqrt, in double, so every platform gets the same
/// points.
template <int D>
struct EvenDirections;
template <>
struct EvenDirections<3> {
  static constexpr std::uint32_t count = 2048;
  std::uint32_t k = 0;
  double c = 1, s = 0;  // cos and sin of the azimuth k * golden angle
  void next(Scalar* x)
  {
    const double z = 1 - (2 * double(k) + 1) / count;
    const double r = std::sqrt(1 - z * z);
    x[0] = Scalar(r * c);
    x[1] = Scalar(r * s);
    x[2] = Scalar(z);
    // Turn by the golden angle 2 pi (1 - 1/phi) = 2.39996 rad.
    const double gc = -0.7373688780783201, gs = 0.6754902942615235;
    const double c2 = c * gc - s * gs;
    s = s * gc + c * gs;
    c = c2;
    ++k;
  }
};
template <>
struct EvenDirections<2> {
  static constexpr std::uint32_t count = 2048;
  double c = 0.99999882345170190, s = 0.0015339801862847655;  // angle pi / count
  void next(Scalar* x)
  {
    x[0] = Scalar(c);
    x[1] = Scalar(s);
    const double gc = 0.99999529380957619, gs = 0.0030679567629659761;  // step 2 pi / count
    const double c2 = c * gc - s * gs;
    s = s * gc + c * gs;
    c = c2;
  }
};
}  // namespace detail

/// Biases that make the basins of the rest poses as large as the reference measured them
/// (paper 3.4 made to keep the signature's frequencies). Pose i's basin is the set of body-frame
/// up vectors u for which n_i . u + bias[i] is largest; with no biases these are the cells of
/// plain nearest-pose choice, whose sizes follow only the geometry of the normals, so a pose the
/// reference rarely ends in can own a large share of directions. The biases are chosen so
/// that, for up vectors spread uniformly over the sphere (circle in 2D), each basin holds the
/// pose's share of the table's frequencies. Of all partitions with those shares this one needs
/// the smallest mean rotation (1 - cos of the angle): it is the optimal transport of uniform
/// directions onto the poses, so the choice is still the nearest pose, measured with the
/// signature's statistics. The pose a body takes is still decided by its orientation when it
/// settles, i.e. by its motion. Writes `sig.rest.count` values; all 0 without frequencies.
///
/// Found by fixed-step ascent on the basin sizes over 2048 evenly spread directions (about 30
/// iterations reach the lattice's resolution); the cost grows with the rest poses times the
/// directions, once per shape (`add_shape`), never in a step.
template <int D>
void rest_basin_biases(const SignatureView<D>& sig, Scalar* bias)
{
  const std::uint32_t n = sig.rest.count < max_rest_poses ? sig.rest.count : max_rest_poses;
  for (std::uint32_t i = 0; i < n; ++i) bias[i] = 0;
  if (n < 2 || !sig.rest.frequencies) return;
  Scalar target[max_rest_poses], step[max_rest_poses], last[max_rest_poses], normals[max_rest_poses * D];
  // Frequencies that are not in (0, 1] (negative, NaN, huge) count as 0.
  const auto frequency = [&sig](std::uint32_t i) {
    const Scalar f = sig.rest.frequencies[i];
    return f > 0 && f <= 1 ? f : Scalar(0);
  };
  Scalar total = 0;
  for (std::uint32_t i = 0; i < n; ++i) total += frequency(i);
  if (!(total > 0)) return;
  for (std::uint32_t i = 0; i < n; ++i) {
    target[i] = frequency(i) / total;
    // A basin's size changes by about (its border's length) / (area of the sphere) per unit of
    // bias, 0.2 to 0.5 for typical poses: a step of 2 is close to Newton's; it halves whenever
    // the error changes sign, so the ascent cannot oscillate.
    step[i] = 2;
    last[i] = 0;
    for (int k = 0; k < D; ++k) normals[i * D + k] = sig.rest.normals[i * D + k];
  }
  constexpr std::uint32_t samples = detail::EvenDirections<D>::count;
  for (int iteration = 0; iteration < 40; ++iteration) {
    std::uint32_t hits[max_rest_poses] = {};
    detail::EvenDirections<D> directions;
    for (std::uint32_t m = 0; m < samples; ++m) {
      Scalar u[D];
      directions.next(u);
      std::uint32_t best = 0;
      Scalar best_score = -std::numeric_limits<Scalar>::infinity();
      for (std::uint32_t i = 0; i < n; ++i) {
        Scalar score = bias[i];
        for (int k = 0; k < D; ++k) score += normals[i * D + k] * u[k];
        if (score > best_score) {
          best_score = score;
          best = i;
        }
      }
      ++hits[best];
    }
    Scalar error[max_rest_poses];
    bool done = true;
    for (std::uint32_t i = 0; i < n; ++i) {
      error[i] = target[i] - Scalar(hits[i]) / Scalar(samples);
      done = done && error[i] * error[i] * Scalar(samples) * Scalar(samples) <= 1;  // within one lattice point
    }
    if (done) break;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (error[i] * last[i] < 0) step[i] *= Scalar(0.5);
      last[i] = error[i];
      bias[i] += step[i] * error[i];
    }
  }
}

/// Angular velocity that turns `rest_normal` (body frame) toward `up` (world) in about
/// `turn_time` seconds: (u x up) / turn_time with u the rest normal in the world, i.e. the
/// rotation axis scaled by the sine of the remaining angle (paper 3.4's rotational impulse).
inline Vector3 rest_turn(const Quaternion& orientation, const Vector3& rest_normal, const Vector3& up, Scalar turn_time)
{
  return (orientation * rest_normal).cross(up) / turn_time;
}
inline Scalar rest_turn(const Rot2& orientation, const Vector2& rest_normal, const Vector2& up, Scalar turn_time)
{
  return detail::moment(Vector2(orientation * rest_normal), up) / turn_time;
}

/// A body's rocking about its rest pose while its settling time runs (`SettleView`): its spin,
/// given `offset`, the rest turn with a turn time of 1 s (the axis that turns the pose into place,
/// scaled by the sine of the angle left), the ground's normal `up`, the settling time left
/// `left` (s), the rocking's angular frequency `omega` (rad/s) and its amplitude `amplitude`
/// (rad), and the rest turn's `turn_time` (s).
///
/// The rest turn, offset / turn_time, keeps the body centred on its pose; on top of it the body
/// rocks about a level axis with a spin of amplitude * omega that follows a triangle wave of
/// period 2 pi / omega in the time left: a rock of about `amplitude` each way, whose spin is
/// slow only for moments. With the amplitude at which the farthest point swings at the sleep
/// speed the body rises no more than a few millimetres, and it is not still before its time is
/// over, as the reference's bodies rock in their pose. A triangle wave, not a sine: floor and
/// products only, so the same bits on every platform.
template <class Spin, class Up>
Spin settle_rock(const Spin& offset, const Up& up, Scalar left, Scalar omega, Scalar amplitude, Scalar turn_time)
{
  constexpr Scalar two_pi = Scalar(6.283185307179586);
  const Scalar cycles = left * (omega / two_pi);
  const Scalar f = cycles - std::floor(cycles);
  const Scalar wave = 4 * std::fabs(f - Scalar(0.5)) - 1;  // -1 .. 1
  const Scalar swing = amplitude * omega * wave;
  if constexpr (std::is_same<Spin, Scalar>::value) {
    return offset / turn_time + swing;
  } else {
    return offset / turn_time + detail::any_perpendicular(up) * swing;
  }
}

/// The orientation turned by the smallest rotation that makes `rest_normal` point exactly `up`.
inline Quaternion snap_to_rest(const Quaternion& orientation, const Vector3& rest_normal, const Vector3& up)
{
  const Vector3 u = orientation * rest_normal;
  const Scalar c = u.dot(up);
  Quaternion turn;
  if (c > Scalar(-0.9999)) {
    // Half-angle quaternion without trigonometry: (1 + cos a, sin a * axis), normalised.
    const Vector3 axis = u.cross(up);
    turn = detail::normalized(Quaternion(1 + c, axis.x(), axis.y(), axis.z()));
  } else {
    const Vector3 axis = detail::any_perpendicular(up);
    turn = Quaternion(0, axis.x(), axis.y(), axis.z());
  }
  return detail::normalized(detail::product(turn, orientation));
}
inline Rot2 snap_to_rest(const Rot2& orientation, const Vector2& rest_normal, const Vector2& up)
{
  const Vector2 u = orientation * rest_normal;
  return detail::normalized(Rot2{u.dot(up), detail::moment(u, up)} * orientation);
}

}  // namespace statsim
