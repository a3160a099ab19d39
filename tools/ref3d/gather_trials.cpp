// See gather_trials.hpp.
#include "ref3d/gather_trials.hpp"

#include "common/flight_top.hpp"
#include "common/pi.hpp"
#include "ref3d/sampling.hpp"
#include "statsim/detail/response.hpp"
#include "statsim/statistical.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace statsim::tools::ref3d {

double height_trial(const ShapeModel& m, double spin_ratio, std::uint64_t seed, std::uint64_t index)
{
  TrialRng rng(seed, kHeightStream, index);
  const double L = m.bounding_radius, u = 1.0;
  RigidState s;
  s.orientation = rng.rotation();
  s.spin = rng.direction() * (spin_ratio * u / L);
  s.velocity = Eigen::Vector3d(0, 0, -u);
  s.position = Eigen::Vector3d(0, 0, L * (1 + 1e-9));
  const FreeFlight flight(m.unit_inertia);
  const FirstContact fc = first_contact(m.hull, L, flight, s, 0.0, std::numeric_limits<double>::infinity(),
                                        1e-12 * L, 100000000);
  return fc.state.position.z() - lowest_point(m.hull, fc.state);
}

FirstFlight first_flight(const Reference& ref, const GatherOptions& o, const RigidState& start, double hop)
{
  const double L = ref.model().bounding_radius;
  const std::unique_ptr<Reference::Run> run = ref.run(start);
  const double dt = ref.settings().dt;
  FlightTop top(dt, hop, o.reference.gravity);
  top.add(start.velocity, start.spin);
  FirstFlight f;
  f.orientation = start.orientation;
  const long steps = static_cast<long>(std::ceil(o.landing_time / dt));
  for (long k = 0; k < steps && !top.found(); ++k) {
    run->step();
    const RigidState s = run->state();
    top.add(s.velocity, s.spin);
    if (top.leave_step() == k + 1) f.orientation = s.orientation;  // the state it leaves with, so far
    if (k > 0 && s.velocity.norm() < o.still_speed && s.spin.norm() * L < o.still_speed) break;  // at rest
  }
  f.found = top.found();
  f.velocity = top.leave_velocity();
  f.spin = top.leave_spin();
  return f;
}

Eigen::Vector3d trial_spin(const ShapeModel& m, const Eigen::Quaterniond& orientation, const Eigen::Vector3d& axis,
                           double spin_ratio, double speed, bool by_energy)
{
  const Eigen::Vector3d w = axis * (spin_ratio * speed / m.bounding_radius);
  if (!by_energy) return w;
  const Eigen::Vector3d b = orientation.conjugate() * axis;
  const double kw2 = m.unit_inertia.dot(b.cwiseProduct(b)), k2 = m.unit_inertia.sum() / 3.0;
  return w * std::sqrt(k2 / kw2);
}

ResponseTrial response_trial(const Reference& ref, const GatherOptions& o, double cos_theta, double cos_phi,
                             double speed, double spin_ratio, std::uint64_t stream, std::uint64_t index,
                             bool by_energy)
{
  const ShapeModel& m = ref.model();
  TrialRng rng(o.seed, stream, index);
  const double L = m.bounding_radius;
  const double ct = cos_theta, st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
  const Eigen::Vector3d vhat(st, 0.0, -ct), e1(ct, 0.0, st), e2(0.0, 1.0, 0.0);
  const double azimuth = 2.0 * kPi * rng.uniform();
  const double alpha = ct >= 1.0 ? 0.0 : azimuth;
  const double sp = std::sqrt(std::max(0.0, 1.0 - cos_phi * cos_phi));
  const Eigen::Vector3d wdir = cos_phi * vhat + sp * (std::cos(alpha) * e1 + std::sin(alpha) * e2);

  RigidState s0;
  s0.orientation = rng.rotation();
  s0.velocity = speed * vhat;
  s0.spin = trial_spin(m, s0.orientation, wdir, spin_ratio, speed, by_energy);
  s0.position = Eigen::Vector3d(0, 0, L * (1 + 1e-9));
  const FreeFlight flight(m.unit_inertia);
  const FirstContact fc = first_contact(m.hull, L, flight, s0, 0.0, std::numeric_limits<double>::infinity(),
                                        1e-12 * L, 100000000);
  RigidState start = fc.state;
  start.position.z() -= 1e-6 * L;  // a hair into the ground, so that Bullet's first step has the contact
  ImpactResult ir = ref.impact(start, o.max_impact_time);
  bool no_flight = false;
  if (o.response_flight) {
    // The same start under gravity, to the first flight that rises landing_hop L: where a corner's
    // hop lands again before the body flies, the drop's first flight ends the whole chain, and the
    // runtime's sphere, which cannot hop on corners, takes it as one response.
    const FirstFlight f = first_flight(ref, o, start, o.landing_hop * L);
    if (f.found) {
      ir.after.velocity = f.velocity;
      ir.after.spin = f.spin;
      ir.after.orientation = f.orientation;  // as it left: K's, as for the gravity-free trials
    } else {
      no_flight = true;
    }
  }

  const Material mat{static_cast<Scalar>(o.reference.restitution), static_cast<Scalar>(o.reference.friction),
                     static_cast<Scalar>(o.rolling_resistance)};
  const Vector3 vminus = s0.velocity.cast<Scalar>();
  const Vector3 vp = point_particle_velocity<3>(vminus, Vector3(0, 0, 1), mat,
                                                static_cast<Scalar>(o.reference.restitution_threshold));
  ResponseTrial out;
  const Eigen::Vector3d w = ir.after.spin * (L / speed);
  const Eigen::Vector3d dv = (ir.after.velocity - vp.cast<double>()) / speed;
  out.value = {w.x(), w.y(), w.z(), dv.x(), dv.y(), dv.z()};
  // K W+ / |V-| with K = R diag(sqrt(I_k / m)) R^T at the orientation the body leaves with, which
  // belongs to W+: half its squared length is then the rotational energy the body leaves with. (At
  // the orientation it met the ground with, after a long contact, it is not.)
  const Eigen::Matrix3d R = ir.after.orientation.toRotationMatrix();
  const Eigen::Vector3d k = R * (m.unit_inertia.cwiseSqrt().asDiagonal() * (R.transpose() * ir.after.spin)) / speed;
  out.gyration = {k.x(), k.y(), k.z(), dv.x(), dv.y(), dv.z()};
  out.contact = start;
  out.departure = ir.after;
  out.time_limited = ir.time_limited;
  out.no_flight = no_flight;
  out.max_penetration = ir.max_penetration;
  out.steps = ir.steps;
  return out;
}

DropTrial drop_trial(const Reference& ref, const GatherOptions& o, std::uint64_t index)
{
  const ShapeModel& m = ref.model();
  TrialRng rng(o.seed, kRestStream, index);
  const double L = m.bounding_radius;
  RigidState s;
  s.orientation = rng.rotation();
  s.velocity = Eigen::Vector3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
  s.spin = rng.direction() * rng.uniform(0, 4 * kPi);
  const double lift = L * rng.uniform(0.25, 3.0);
  s.position = Eigen::Vector3d(0, 0, -lowest_point(m.hull, s) + lift);
  const DropResult r = ref.drop(s, o.still_speed, o.still_time, o.max_drop_time, {o.settle_speed, o.quiet_speed});
  DropTrial d;
  d.up = r.rest.orientation.conjugate() * Eigen::Vector3d::UnitZ();
  d.height = r.height;
  d.time = r.time;
  d.settled = r.settled;
  d.settle_time = r.settle_time;
  return d;
}

}  // namespace statsim::tools::ref3d
