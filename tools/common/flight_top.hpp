// The end of a body's first collision with the ground, found step by step in its trajectory:
// what `statsim fidelity` compares (first_impact_ks, the no-flight share) and what `statsim
// gather`'s landing stage counts as a stay. Needs no engine: the velocities are given.
#pragma once

#include <Eigen/Core>

namespace statsim::tools {

/// Finds, in a trajectory sampled after every step of any size, the event a signature table
/// describes: the state in which the body leaves the ground once its first collision is over.
/// A collision, as the tables are gathered, lasts from the first contact until the body has left
/// the ground for good, over as many contact episodes as that takes (a box landing on a corner
/// strikes with a second corner, and more). Under gravity a body always comes back, so the
/// collision counts as over at the first real flight: the body leaves the ground fast enough to
/// rise at least `min_rise`, and flies without any contact up to the top of that flight.
///  - First contact: the first step whose vertical velocity rises by more than 2 g dt (a free
///    step changes it by exactly -g dt, resting support by about +g dt).
///  - Free step: the velocity changed by gravity alone: |v_k - v_(k-1) + g dt e_z| at most
///    kFreeTolerance g dt (any contact impulse, normal or friction, changes it more).
///  - Leaving state: the velocity and spin after the last step that was not free. Engines apply
///    gravity before they solve contacts, so at any step this is the velocity the body leaves
///    with, and the flight that follows is ballistic.
///  - Top: after the first contact, the first free step across which v_z goes from > 0 to <= 0,
///    when the leaving state's v_z^2 / (2 g), the rise of the flight, is at least `min_rise`.
///    Lower hops (between the corners of one landing, or a body jittering on the ground) are
///    part of the collision.
/// speed() and spin() are |v| and |w| of the leaving state of that flight. A body that never
/// flies again after its first contact (it slides, rolls or rocks to rest) has no such flight:
/// found() stays false.
class FlightTop {
public:
  /// Largest velocity change of a free step other than gravity's, as a share of g dt.
  static constexpr double kFreeTolerance = 0.01;

  /// `dt`: s, the trajectory's step; `min_rise`: m, the least rise of a flight that ends the
  /// collision; `gravity`: m/s^2, along -z.
  FlightTop(double dt, double min_rise, double gravity = 9.81);
  /// The centre's velocity (m/s) and the spin (rad/s) before the first step (the drop's initial
  /// state), then after each step.
  void add(const Eigen::Vector3d& velocity, const Eigen::Vector3d& spin);
  bool contact() const { return contact_step_ >= 0; }  ///< the first contact has been seen
  bool found() const { return found_; }                ///< the first real flight was found
  double speed() const { return speed_; }              ///< m/s, |v| as the body left for that flight
  double spin() const { return spin_; }                ///< rad/s, |w| as the body left for that flight
  double rise() const { return rise_; }                ///< m, the rise of that flight, v_z^2 / (2 g)
  /// m/s and rad/s, the velocity and spin the body left for that flight with (valid when found())
  const Eigen::Vector3d& leave_velocity() const { return leave_v_; }
  const Eigen::Vector3d& leave_spin() const { return leave_w_; }
  /// The add() call (0 = the initial state) whose state is the one the body leaves with so far
  long leave_step() const { return leave_step_; }
  /// m/s, |v| before the step of the first contact (the approach speed |V-|); 0 before a contact
  double impact_speed() const { return impact_speed_; }
  /// rad/s, |w| before the step of the first contact; 0 before a contact
  double impact_spin() const { return impact_spin_; }

private:
  double dt_, min_rise_, gravity_;
  long steps_ = -1;
  long contact_step_ = -1;
  long leave_step_ = -1;
  bool found_ = false;
  double speed_ = 0, spin_ = 0, rise_ = 0, impact_speed_ = 0, impact_spin_ = 0;
  Eigen::Vector3d prev_v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d prev_w_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d leave_v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d leave_w_ = Eigen::Vector3d::Zero();
};

}  // namespace statsim::tools
