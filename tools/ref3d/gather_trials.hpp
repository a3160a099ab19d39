// The reference trials of `statsim gather` in Bullet, one at a time: an h_coll flight (exact,
// no stepping), a response impact, a rest drop. Each is seeded from (seed, stream, index) only,
// so a trial's outcome does not depend on which thread runs it or in which order.
#pragma once

#include "ref3d/gather_options.hpp"
#include "ref3d/model.hpp"
#include "ref3d/reference.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace statsim::tools::ref3d {

/// One impact's normalised outcome: W+ L/|V-| (3), (V+ - V_particle+)/|V-| (3); or, with the
/// spin measured by gyration (statsim::ResponseSpin), K W+ / |V-| for the first three.
using Response = std::array<double, 6>;

/// One response trial: W+ and V+ of one impact, and how Bullet got there.
struct ResponseTrial {
  Response value{};     ///< spin by length (statsim::ResponseSpin::length)
  Response gyration{};  ///< the same outcome with the spin by gyration (statsim::ResponseSpin::gyration)
  RigidState contact;   ///< the body as it met the ground: where the runtime's draws start (gather_spin.hpp)
  RigidState departure; ///< the body as it left the ground (W+ and V+; its orientation is K's in `gyration`)
  bool time_limited = false;
  /// GatherOptions::response_flight: no flight rising landing_hop L within landing_time (the
  /// outcome is then the gravity-free impact's)
  bool no_flight = false;
  double max_penetration = 0.0;
  int steps = 0;
};
/// How a body left the ground under gravity (`first_flight`).
struct FirstFlight {
  bool found = false;                              ///< it flew: its centre rose hop at least
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< m/s, as it left for that flight
  Eigen::Vector3d spin = Eigen::Vector3d::Zero();      ///< rad/s, as it left for that flight
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< as it left for that flight
};
/// Runs `start` in Bullet with gravity until its first flight whose centre rises `hop` (m;
/// common/flight_top.hpp, as `statsim fidelity` finds a drop's), until it is at rest (centre and
/// farthest point by spin below `o.still_speed`) or for `o.landing_time`.
FirstFlight first_flight(const Reference& ref, const GatherOptions& o, const RigidState& start, double hop);

/// The spin a trial meets the ground with at spin ratio `spin_ratio` and speed |V-| `speed`
/// (m/s), about the world-frame unit axis `axis`, for a body at orientation `orientation`:
/// |W-| = spin_ratio |V-| / L, or with `by_energy` (statsim::ResponseSpin::energy) the |W-| that
/// gives |K W-| / k = spin_ratio |V-| / L, k^2 = tr(I / m) / 3, as the runtime looks it up.
Eigen::Vector3d trial_spin(const ShapeModel& model, const Eigen::Quaterniond& orientation, const Eigen::Vector3d& axis,
                           double spin_ratio, double speed, bool by_energy);

/// The impact of cell (cos theta, cos phi, speed, spin ratio), trial `index` of `stream`; with
/// `by_energy` at a spin ratio by energy (`trial_spin`).
ResponseTrial response_trial(const Reference& ref, const GatherOptions& o, double cos_theta, double cos_phi,
                             double speed, double spin_ratio, std::uint64_t stream, std::uint64_t index,
                             bool by_energy);

/// One h_coll flight: the centre height at first contact.
double height_trial(const ShapeModel& model, double spin_ratio, std::uint64_t seed, std::uint64_t index);

/// One rest drop: where the body's up vector ended (body frame), at what height, after how long,
/// and how long it took to settle once slow (DropResult::settle_time, s).
struct DropTrial {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double height = 0.0;
  double time = 0.0;
  bool settled = false;
  double settle_time = 0.0;
};
/// Drop `index`: a random pose and velocity with gravity until the body is still.
DropTrial drop_trial(const Reference& ref, const GatherOptions& o, std::uint64_t index);

}  // namespace statsim::tools::ref3d
