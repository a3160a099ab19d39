// See flight_top.hpp.
#include "common/flight_top.hpp"

#include <cmath>

namespace statsim::tools {

FlightTop::FlightTop(double dt, double min_rise, double gravity) : dt_(dt), min_rise_(min_rise), gravity_(gravity) {}

void FlightTop::add(const Eigen::Vector3d& velocity, const Eigen::Vector3d& spin)
{
  ++steps_;
  const Eigen::Vector3d prev = prev_v_, prev_w = prev_w_;
  prev_v_ = velocity;
  prev_w_ = spin;
  if (steps_ == 0 || found_) return;
  const double g_dt = gravity_ * dt_;
  // Over a free step v_k = v_(k-1) - g dt e_z; what is left is the impulse of the contacts over
  // the step, per unit mass.
  const Eigen::Vector3d kick = velocity - prev + Eigen::Vector3d(0, 0, g_dt);
  if (contact_step_ < 0) {
    if (velocity.z() - prev.z() <= 2 * g_dt) return;
    contact_step_ = steps_;
    impact_speed_ = prev.norm();
    impact_spin_ = prev_w.norm();
  }
  if (kick.norm() > kFreeTolerance * g_dt) {
    // Whatever the step, the velocity after the last step with a contact is the one the body
    // leaves with: engines apply gravity before they solve the contacts.
    leave_v_ = velocity;
    leave_w_ = spin;
    leave_step_ = steps_;
    return;
  }
  // The top of a free flight: from there the body left with leave_v_, and its centre rose
  // v_z^2 / (2 g) since, whatever the step.
  const double rise = leave_v_.z() > 0 ? leave_v_.z() * leave_v_.z() / (2 * gravity_) : 0.0;
  if (prev.z() > 0 && velocity.z() <= 0 && rise >= min_rise_) {
    found_ = true;
    speed_ = leave_v_.norm();
    spin_ = leave_w_.norm();
    rise_ = rise;
  }
}

}  // namespace statsim::tools
