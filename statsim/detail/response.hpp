#pragma once
/// @file
/// Particle (solid sphere) collision response with restitution and Coulomb friction, for body
/// against plane and body against body. The statistical response of the paper builds its
/// V_particle+ on the same rule.
///
/// With the contact point at r from the centre, the contact velocity is u = v + w x r. The normal
/// impulse is j_n = -(1 + e) u.n / (sum of inverse masses); the tangential impulse opposes the
/// slip u_t and is the smaller of mu j_n (sliding) and the impulse that stops the slip (sticking):
/// for a solid sphere (I = k m R^2) a tangential impulse j changes the slip by
/// j (1/m)(1 + 1/k), so sticking needs |u_t| / ((1/m)(1 + 1/k)) per body. Neither impulse can add
/// kinetic energy: restitution e <= 1, and friction never exceeds the impulse that stops the slip.

#include "statsim/math.hpp"

namespace statsim {

/// Surface properties of a contact.
struct Material {
  /// Coefficient of restitution, 0 (no bounce) to 1 (elastic). Typical: 0.3.
  Scalar restitution = Scalar(0.3);
  /// Coulomb friction coefficient, >= 0. Typical: 0.5.
  Scalar friction = Scalar(0.5);
  /// Rolling resistance coefficient, >= 0: each contact takes up to this times the normal
  /// impulse off the rolling speed, and the spin in proportion, so that a rolling body stops
  /// (on the ground, a deceleration of about this times g). Typical: 0.01 to 0.1.
  Scalar rolling_resistance = Scalar(0.05);
};

/// Combined material of two touching bodies: the larger restitution (a bouncy body bounces on
/// anything), the geometric mean of the frictions (a frictionless body slides on anything) and
/// the larger rolling resistance.
inline Material mix(const Material& a, const Material& b)
{
  return {a.restitution > b.restitution ? a.restitution : b.restitution, std::sqrt(a.friction * b.friction),
          a.rolling_resistance > b.rolling_resistance ? a.rolling_resistance : b.rolling_resistance};
}

/// One side of a contact: the velocities are updated in place.
template <int D>
struct ContactSide {
  typename Space<D>::Vec& velocity;     ///< m/s
  typename Space<D>::Spin& spin;        ///< rad/s
  Scalar inv_mass;                      ///< 1/kg; 0 for a static or sleeping body
  /// m, centre to contact point. 0 makes the side a point particle: its spin takes no part in
  /// the contact (only rolling resistance slows it).
  Scalar radius;
};

namespace detail {

/// Normal and friction impulse of a contact whose relative contact velocity `u` approaches
/// along the unit normal `n` at `vn` < 0 (writes the normal impulse to `jn`): restitution above
/// `restitution_threshold`, and the tangential impulse the lesser of mu j_n and the impulse
/// `slip / compliance` that stops the slip.
template <int D>
typename Space<D>::Vec contact_impulse(const typename Space<D>::Vec& u, const typename Space<D>::Vec& n, Scalar vn,
                                       Scalar inv_mass_sum, Scalar compliance, const Material& m,
                                       Scalar restitution_threshold, Scalar& jn)
{
  using Vec = typename Space<D>::Vec;
  const Scalar e = -vn > restitution_threshold ? m.restitution : Scalar(0);
  jn = -(1 + e) * vn / inv_mass_sum;
  Vec impulse = n * jn;
  const Vec ut = u - n * vn;
  const Scalar slip = ut.norm();
  if (slip > Scalar(0)) {
    const Scalar jt_stick = slip / compliance;
    const Scalar jt_slide = m.friction * jn;
    const Scalar jt = jt_stick < jt_slide ? jt_stick : jt_slide;
    impulse -= ut * (jt / slip);
  }
  return impulse;
}

/// Rolling resistance after a normal impulse `jn`: each body's tangential velocity relative to
/// the other and its spin shrink by the same factor, which takes at most
/// rolling_resistance * j_n * inv_mass off the rolling speed and never adds energy (a factor in
/// [0, 1] on each term).
template <int D>
void rolling_resistance(ContactSide<D>& a, ContactSide<D>& b, const typename Space<D>::Vec& n, Scalar jn,
                        Scalar inv_mass_sum, const Material& m)
{
  using Vec = typename Space<D>::Vec;
  if (!(m.rolling_resistance > 0)) return;
  const Vec rel = b.velocity - a.velocity;
  const Vec rel_t = rel - n * rel.dot(n);
  const Scalar speed = rel_t.norm();
  const Scalar cut = m.rolling_resistance * jn * inv_mass_sum;
  const Scalar f = speed > cut ? 1 - cut / speed : Scalar(0);
  // Both tangential velocities move toward their mass-weighted mean, which conserves momentum
  // and leaves a static side (inverse mass 0) where it is.
  const Vec mean = (a.velocity * b.inv_mass + b.velocity * a.inv_mass) / inv_mass_sum;
  const Vec mean_t = mean - n * mean.dot(n);
  a.velocity += (a.velocity - n * a.velocity.dot(n) - mean_t) * (f - 1);
  b.velocity += (b.velocity - n * b.velocity.dot(n) - mean_t) * (f - 1);
  if (a.inv_mass > 0) a.spin = a.spin * f;
  if (b.inv_mass > 0) b.spin = b.spin * f;
}

}  // namespace detail

/// Resolves the contact of `a` and `b` along the unit normal `n` (pointing from a to b).
/// Returns true when the bodies were approaching and an impulse was applied. Below
/// `restitution_threshold` (m/s of approach) the contact is treated as inelastic, so that resting
/// contacts do not jitter.
template <int D>
bool particle_response(ContactSide<D> a, ContactSide<D> b, const typename Space<D>::Vec& n,
                       const Material& m, Scalar restitution_threshold)
{
  using Vec = typename Space<D>::Vec;
  const Scalar inv_k = Scalar(1) / Space<D>::inertia_factor;
  const Vec ra = n * a.radius;
  const Vec rb = n * -b.radius;
  const Vec u = (b.velocity + detail::cross(b.spin, rb)) - (a.velocity + detail::cross(a.spin, ra));
  const Scalar vn = u.dot(n);
  const Scalar inv_mass_sum = a.inv_mass + b.inv_mass;
  if (vn >= 0 || inv_mass_sum <= 0) return false;
  // Tangential compliance: an impulse j changes the slip by j (1/m)(1 + 1/k) on a rolling sphere
  // and by j / m on a point particle.
  const Scalar compliance = a.inv_mass * (a.radius > 0 ? 1 + inv_k : Scalar(1)) +
                            b.inv_mass * (b.radius > 0 ? 1 + inv_k : Scalar(1));
  Scalar jn;
  const Vec impulse = detail::contact_impulse<D>(u, n, vn, inv_mass_sum, compliance, m, restitution_threshold, jn);
  // Impulse `impulse` acts on b at rb and its opposite on a at ra; I^-1 = inv_mass / (k R^2).
  b.velocity += impulse * b.inv_mass;
  a.velocity -= impulse * a.inv_mass;
  if (b.radius > 0) b.spin += detail::moment(rb, impulse) * (b.inv_mass * inv_k / (b.radius * b.radius));
  if (a.radius > 0) a.spin -= detail::moment(ra, impulse) * (a.inv_mass * inv_k / (a.radius * a.radius));
  detail::rolling_resistance(a, b, n, jn, inv_mass_sum, m);
  return true;
}

/// The same rule as `particle_response` for two point-like sides (radius 0: statistical bodies,
/// whose spheres are not their shapes): the impulses do not turn them, and only rolling
/// resistance slows their spins. The terms of the radii vanish exactly (w x 0 = 0, x + 0 = x,
/// compliance = sum of inverse masses), so the result is bit for bit that of `particle_response`
/// with both radii 0 (tests/test_contacts.cpp checks it); written out because it runs for every
/// touching pair of statistical bodies in every contact pass.
template <int D>
bool particle_point_response(ContactSide<D> a, ContactSide<D> b, const typename Space<D>::Vec& n, const Material& m,
                             Scalar restitution_threshold)
{
  using Vec = typename Space<D>::Vec;
  const Vec u = b.velocity - a.velocity;
  const Scalar vn = u.dot(n);
  const Scalar inv_mass_sum = a.inv_mass + b.inv_mass;
  if (vn >= 0 || inv_mass_sum <= 0) return false;
  Scalar jn;
  const Vec impulse = detail::contact_impulse<D>(u, n, vn, inv_mass_sum, inv_mass_sum, m, restitution_threshold, jn);
  b.velocity += impulse * b.inv_mass;
  a.velocity -= impulse * a.inv_mass;
  detail::rolling_resistance(a, b, n, jn, inv_mass_sum, m);
  return true;
}

/// Body against a static plane with unit normal `n` (pointing out of the plane, towards the
/// body). Mass cancels out, so none is needed. The same rule as `particle_response` with a static,
/// spinless first side and a unit-mass body, written out because resting bodies meet the ground
/// in every contact pass: the terms of the static side vanish.
template <int D>
bool particle_plane_response(typename Space<D>::Vec& velocity, typename Space<D>::Spin& spin, Scalar radius,
                             const typename Space<D>::Vec& n, const Material& m, Scalar restitution_threshold)
{
  using Vec = typename Space<D>::Vec;
  const Scalar inv_k = Scalar(1) / Space<D>::inertia_factor;
  const Vec r = n * -radius;
  const Vec u = velocity + detail::cross(spin, r);
  const Scalar vn = u.dot(n);
  if (vn >= 0) return false;
  const Scalar compliance = radius > 0 ? 1 + inv_k : Scalar(1);
  // A unit inverse mass: j_n / 1 is j_n exactly.
  Scalar jn;
  const Vec impulse = detail::contact_impulse<D>(u, n, vn, Scalar(1), compliance, m, restitution_threshold, jn);
  velocity += impulse;
  if (radius > 0) spin += detail::moment(r, impulse) * (inv_k / (radius * radius));
  if (m.rolling_resistance > 0) {
    const Vec vt = velocity - n * velocity.dot(n);
    const Scalar speed = vt.norm();
    const Scalar cut = m.rolling_resistance * jn;
    const Scalar f = speed > cut ? 1 - cut / speed : Scalar(0);
    velocity += vt * (f - 1);
    spin = spin * f;
  }
  return true;
}

/// V_particle+ of the statistical response (paper 3.3.2 step 7): the velocity a point particle
/// would leave a static plane with (unit normal `n`, towards the particle) with. Normal part:
/// -e v_n (e = 0 below `restitution_threshold` of approach speed). Tangential part: Coulomb
/// friction over the normal impulse, v_t' = v_t max(0, 1 - mu (1 + e) |v_n| / |v_t|). The
/// gathering tools compute the same V_particle+ for their offsets V_rigid+ - V_particle+.
template <int D>
typename Space<D>::Vec point_particle_velocity(const typename Space<D>::Vec& v, const typename Space<D>::Vec& n,
                                               const Material& m, Scalar restitution_threshold)
{
  using Vec = typename Space<D>::Vec;
  const Scalar vn = v.dot(n);
  if (vn >= 0) return v;
  const Scalar e = -vn > restitution_threshold ? m.restitution : Scalar(0);
  const Vec vt = v - n * vn;
  const Scalar slip = vt.norm();
  const Scalar cut = m.friction * (1 + e) * -vn;
  const Scalar keep = slip > cut ? 1 - cut / slip : Scalar(0);
  return vt * keep - n * (e * vn);
}

/// Kinetic energy of a solid sphere (or disc in 2D) of mass `mass` and radius `radius`, J.
template <int D>
Scalar kinetic_energy(const typename Space<D>::Vec& v, const typename Space<D>::Spin& w, Scalar mass, Scalar radius)
{
  const Scalar inertia = Space<D>::inertia_factor * mass * radius * radius;
  return Scalar(0.5) * (mass * v.squaredNorm() + inertia * detail::squared_norm(w));
}

}  // namespace statsim
