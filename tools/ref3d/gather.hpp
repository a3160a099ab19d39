// `statsim gather`: a shape's statistical signature (paper 3.2) measured with the 3D reference,
// and its C++ table (tables/NAME.hpp) and JSON dump.
//
// What is measured (all in the canonical frame of paper Figure 4a: normal +z, V- in the xz plane
// with a non-negative x component; statsim/signature.hpp and statsim/statistical.hpp read it):
// 1. h_coll: the centre-of-mass height above the plane at the first contact of the true geometry,
//    from the exact torque-free flight (no stepping): straight down at |v|, uniform random
//    orientation, uniform random spin axis, |w| = s |v| / L, L the bounding radius; the flight
//    starts with the centre at L above the plane (uniform orientation there makes the contact
//    phase uniform). Mean and sample standard deviation per spin-ratio sample s.
// 2. Responses: per cell (cos theta, cos phi, [|V-|,] s), `trials` impacts in Bullet without
//    gravity, each from a uniform random orientation at the exact first contact of its free
//    flight (V- = |V-| (sin theta, 0, -cos theta); W- at angle phi to V-, at a uniform random
//    azimuth about V-, except at cos theta = 1 where the azimuth is the one the runtime's frame
//    takes (W-'s tangential part along +x)), until the body leaves the ground for good.
//    Per cell: mean and std of W+ L / |V-| and (V_rigid+ - V_particle+) / |V-|, V_particle+ from
//    statsim::point_particle_velocity. At s = 0 phi does not matter, and the cells of all phi
//    share the statistics of all their trials.
// 3. Rest poses: `rest_drops` drops with gravity from random poses and velocities until the body
//    is still; body-frame up vectors clustered within `rest_tolerance_deg`. A body at rest stands
//    on a face of its convex hull, so a cluster's mean normal within 3 degrees of a hull face's
//    is replaced by the face's, and its height by the face's distance from the centre of mass:
//    the exact rest height of the true geometry standing on that face, which the runtime's
//    snapped orientation needs (the measured mean, in the JSON, is of bodies tilted by up to
//    the clustering angle). Clusters snapped to the same face are one pose. Which poses are kept
//    (common/rest_families.hpp): poses are grouped into families equivalent under the shape's
//    symmetry (hull faces with the same rest height, face area, face shape, centre projection,
//    moment of inertia about the up axis and hull vertex heights, within 1e-3 of the bounding
//    radius); every member of a family seen in more than `rest_min_frequency` of the settled
//    drops together is kept; then, while more than `rest_max_dropped` of the settled drops are
//    in poses not kept, the most frequent remaining family seen in at least 5 drops is kept too.
//    A hexagonal nut's six side faces, each rarer than the cut, are thus one family above it; a
//    shape's few rare poses of different kinds are kept while together they would be a visible
//    part of its rest-pose distribution (tools/ref3d/README.md has the measurements). The header
//    and the JSON give each pose's family and the dropped share.
#pragma once

#include "common/body_contacts.hpp"
#include "ref3d/gather_checks.hpp"
#include "ref3d/gather_emit.hpp"
#include "ref3d/gather_landing.hpp"
#include "ref3d/gather_options.hpp"
#include "ref3d/gather_settle.hpp"
#include "ref3d/gather_spin.hpp"
#include "ref3d/gather_trials.hpp"
#include "ref3d/response_fit.hpp"
#include "ref3d/rest_poses.hpp"

#include <string>
#include <vector>

namespace statsim::tools::ref3d {

/// Everything a gathering measured: the response fit (response_fit.hpp) and the rest poses
/// (rest_poses.hpp) as their stages give them, and the rest here.
struct GatherResult : ResponseFit, RestPoseFit {
  GatherOptions options;
  ShapeModel model;
  std::string ground;  ///< "box" or "plane"
  // h_coll
  std::vector<double> height_mean, height_std;
  long long height_flights = 0;  ///< flights run (0: height samples x height_trials)
  // responses (and ResponseFit's statistics)
  std::vector<std::vector<double>> axes;  ///< 3 (scaled) or 4 (with speed) axes, in table order
  /// Extra header lines ("// Sized: ..."; "sizing" in the JSON), e.g. how --size-for-scene
  /// chose the table. Empty for a plain gathering.
  std::vector<std::string> notes;
  BodyContactData contact;  ///< when options.body_contacts
  LandingFit landing;       ///< when options.landing
  SettleFit settle;         ///< when options.settle (and the landing data it follows)
  ResponseSpin spin = ResponseSpin::length;  ///< what the response statistics' spin measures
  SpinTest spin_test;       ///< how `spin` was chosen (gather_spin.hpp)
  // timings, s
  double height_seconds = 0.0, response_seconds = 0.0, rest_seconds = 0.0;
};

/// Runs the gathering (deterministic for a given options.seed, whatever options.threads).
GatherResult gather(const GatherOptions& options);
}  // namespace statsim::tools::ref3d
