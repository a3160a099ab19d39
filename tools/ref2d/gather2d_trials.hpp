// The reference trials of `statsim gather2d` in Box2D 2.4.1, one at a time: a response impact
// and a rest drop, each from its own random stream (box2d_util.hpp's trial_rng), with the shape
// and material as Box2D holds them. The h_coll flights are fig3.hpp's measure_first_contact.
#pragma once

#include "ref2d/box2d_util.hpp"
#include "ref2d/gather2d_options.hpp"
#include "ref2d/polygon2d.hpp"
#include "statsim/signature.hpp"

#include <box2d/box2d.h>

#include <cstdint>
#include <random>
#include <vector>

namespace statsim::tools {

/// Gravity of the rest drops, m/s^2 (the responses have none).
constexpr double kGravity = 9.81;
// Experiments: the first word of each trial's seed.
constexpr std::uint64_t kHeightTable = 1;
constexpr std::uint64_t kResponseTable = 2;
constexpr std::uint64_t kRestPoses = 3;

/// The shape in Box2D and the material of every trial.
struct Gather2dContext {
  Shape2 shape;
  std::vector<b2PolygonShape> pieces;
  std::vector<Point2> verts;  ///< core vertices as Box2D stores them, about the centre of mass
  double length = 0.0;        ///< L = bounding radius
  Surface surface;
  statsim::Material material;
  float threshold = 1.0f;
};

Gather2dContext make_context(const Gather2dOptions& o);

/// The time step for a largest spin: Box2D limits a body's rotation to b2_maxRotation (pi/2) a
/// step, so keep below 0.4 rad.
double step_for_spin(double dt, double max_spin);

struct ResponseTrial2d {
  double out[3] = {0.0, 0.0, 0.0};
  int steps = 0;
  char time_limited = 0;
};

// One response trial (paper 3.2.2) in the canonical frame: ground y = 0 with normal +y, V- =
// |V-| (sin theta, -cos theta) (non-negative x), spin w = s |V-| / L (counter-clockwise positive,
// as in the runtime's 2D frame). No gravity. Box2D steps until the collision is over:
//  - separated: no touching contact, moving up, and the exact free flight (box2d_util's
//    first_contact_time) does not bring the core within the skin of the ground again before the
//    centre is clear of it (looked at up to 1 s ahead); or
//  - sliding: velocities unchanged for 16 steps and not approaching (slow grazing contacts end
//    like this without gravity: no normal force, so no friction);
//  - else the time limit after the first contact (counted; a body rocking on a corner without
//    gravity can take long), whose final velocities are used.
// Output: W+ L / |V-|, (V_rigid+ - V_particle+) / |V-| with V_particle+ from the runtime's
// statsim::point_particle_velocity<2> on Box2D's float V- (same material and threshold).
ResponseTrial2d simulate_response(const Gather2dContext& ctx, double cos_theta, double spin_ratio, double speed, double dt,
                                  double time_limit, std::mt19937_64& rng);

struct RestTrial2d {
  Point2 up;
  char settled = 0;
};

/// One rest drop: a random pose and velocity with gravity until Box2D puts the body to sleep.
RestTrial2d simulate_rest(const Gather2dContext& ctx, const Gather2dOptions& o, std::mt19937_64& rng);

/// Box2D 2.4.1 fills its contact-function table lazily on first use (b2Contact::Create): this
/// does so on one thread, before any worker starts.
void warm_up_box2d(const Gather2dContext& ctx);

}  // namespace statsim::tools
