// Box2D helpers shared by the 2D reference experiments (fig3, gather2d, compare2d): bodies made
// of convex polygon pieces, and the exact first contact of a core shape with the line y = 0.
// Internal to statsim_ref2d (includes Box2D).
#pragma once

#include "ref2d/first_contact.hpp"
#include "ref2d/polygon2d.hpp"
#include "statsim/random.hpp"  // mix64, the runtime's SplitMix64 finaliser

#include <box2d/box2d.h>

#include <cstdint>
#include <optional>
#include <random>
#include <vector>

namespace statsim::tools {

// ---- random numbers: a per-trial std::mt19937_64 seeded by hashing a few integers -------------

/// A generator seeded from (seed, a, b, c) only: mix64(mix64(mix64(mix64(seed) ^ a) ^ b) ^ c).
std::mt19937_64 trial_rng(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c);
/// Uniform in [0, 1) from 53 random bits (std::uniform_real_distribution is not specified bit for
/// bit across standard libraries).
double uniform01(std::mt19937_64& rng);

// ---- bodies -----------------------------------------------------------------------------------

/// Box2D polygons of the shape's convex pieces (body frame: the centroid is the origin).
std::vector<b2PolygonShape> box2d_pieces(const Shape2& shape);

/// Surface of a body's fixtures.
struct Surface {
  float friction = 0.5f;
  float restitution = 0.3f;
  float restitution_threshold = 1.0f;  ///< m/s (b2FixtureDef's default)
  float density = 1.0f;
};

/// Creates a body from `def` with one fixture per piece.
b2Body* create_body(b2World& world, const b2BodyDef& def, const std::vector<b2PolygonShape>& pieces,
                    const Surface& surface);

/// Creates the static ground: the two-sided edge y = 0 from x = -half_length to +half_length.
b2Body* create_ground(b2World& world, const Surface& surface, float half_length = 100.0f);

/// True when any contact of `body` is touching.
bool touching_anything(b2Body* body);

/// The core vertices of all fixtures of `body`, relative to its centre of mass, in the body
/// frame (Box2D's own m_vertices: no skin).
std::vector<Point2> core_vertices(const b2Body* body);

// ---- exact first contact of a core shape with the line y = 0 ----------------------------------

/// A rigid motion: centre of mass, angle, velocities.
struct FreeState {
  double cx = 0.0;
  double cy = 0.0;
  double angle = 0.0;
  double vx = 0.0;
  double vy = 0.0;
  double w = 0.0;
};

FreeState read_state(const b2Body* body);

/// Height above y = 0 of the lowest of `verts` (body frame, about the centre of mass) at time t
/// of free flight (no forces) from s, minus `offset`.
double core_gap(const FreeState& s, const std::vector<Point2>& verts, double t, double offset = 0.0);

/// Earliest t in [0, t_max] with core_gap(s, verts, t, offset) <= 0, if any. Conservative
/// advancement (the gap is Lipschitz in t with |vy| + |w| max|p|, so no crossing happens before
/// t + gap / L), then bisection to machine precision: a brief dip of a fast-turning corner below
/// the line is not skipped.
std::optional<double> first_contact_time(const FreeState& s, const std::vector<Point2>& verts, double t_max,
                                         double offset = 0.0);

/// Drops a body of the given pieces with its centre at (0, height), turned by `angle`, moving
/// straight down at `speed` and spinning at `spin` (rad/s), without gravity, onto the edge y = 0,
/// steps Box2D at `dt` until it reports touching, and returns the exact centre height at the first
/// contact of the core shape (`FirstContact`, first_contact.hpp; the method: fig3.cpp's header
/// comment). Throws std::runtime_error if Box2D does not move the body as
/// expected.
FirstContact measure_first_contact(const std::vector<b2PolygonShape>& pieces, double height, double angle,
                                   double speed, double spin, double dt);

}  // namespace statsim::tools
