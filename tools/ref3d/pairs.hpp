// `statsim gather-pairs`: body-body statistics of a shape measured with the 3D reference, for
// the runtime's body-body contacts (which today touch at 2 h_coll, paper 3.3.1).
//
// What is measured (body frame of the principal axes, as the signature tables):
// 1. Pair distance: two bodies of the shape, each at a uniform random orientation with a spin
//    of uniform random axis and |w| = s |v| / L, thrown head-on at each other (relative speed
//    |v| along the line of their centres, no gravity, exact torque-free flight); the centre
//    distance at their first contact, mean and sample standard deviation per spin ratio s.
//    Contact of the convex hulls by conservative advancement on their distance (Bullet's GJK);
//    a concave shape then continues on its true geometry (Bullet's box compound or GImpact mesh,
//    margin of the reference) in steps of at most 0.005 L of relative motion, the contact
//    refined by bisection. Starting at 2 L apart makes the phase of the approach uniform.
// 2. Support map: the cube map of the hull's support function (common/support_map.hpp) at
//    several sizes S: its bound and its error against the exact support.
// 3. Packing in reference piles: drop_scene3 piles of the shape (or a bin, PairOptions::bin) in
//    Bullet with statsim bench's settings (the pile reference of `statsim fidelity`), run until
//    every body sleeps; for every
//    pair of bodies in contact (manifold points within `touch_distance`), the centre distance
//    against 2 h_coll (s = 0), the pair distance at s = 0, and the hull support along the line
//    of centres e, s_a(R_a^T e) + s_b(-R_b^T e), exact and by the cube map; and the centre
//    separation along the contact normal n against the support along n. Ratios binned by the
//    angle of e to the vertical.
// 4. Responses: pair impacts in Bullet (two bodies head-on as in 1 from their states at first
//    contact, spin ratios uniform in 0..2, the true geometry, the reference's settings) against
//    the runtime's body-body response (World3 with the shape's committed table, the default
//    PairResponse::momentum, no gravity) from the same states; Kolmogorov-Smirnov distance of the
//    relative speed after the impact |v_b+ - v_a+| / u and of one body's spin |w_b+| L / u, and
//    its noise floor: the KS distance of a second, independent Bullet sample.
#pragma once

#include "ref3d/gather.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace statsim::tools::ref3d {

struct PairOptions {
  GatherOptions shape;  ///< shape, mesh_file or box_size, name, seed, threads, progress, reference
  std::vector<double> spin_ratios = {0, 0.5, 1, 2, 4, 8};
  int trials = 400;                  ///< pair flights per spin ratio
  int height_trials = 2000;          ///< plane flights for h_coll at s = 0
  std::vector<int> support_sizes = {3, 5, 9, 17, 33};
  int support_size = 17;             ///< S of the stored cube map
  int support_directions = 100000;   ///< directions of the error measurement
  /// Hull faces (largest first) tried as contact normals by the stored table's estimate (the
  /// face's own body by its offset, the other body by the cube map).
  int candidate_faces = 16;
  int piles = 4;                     ///< reference piles (scene seeds 1..piles)
  int pile_count = 50;               ///< bodies per pile
  double pile_dt = 1.0 / 240.0;      ///< s
  double pile_time = 20.0;           ///< s: a pile still awake then is used as it is
  double touch_distance = 0.002;     ///< m: a manifold point this close counts as a contact
  /// > 0: instead of drop_scene3, a bin: four walls at +-bin L around the vertical axis, the
  /// bodies at rest on a square lattice of cells 2.1 L wide filling it layer by layer from 1.05 L
  /// up, each at a uniform random orientation (so they stack).
  double bin = 0.0;
  int response_trials = 0;           ///< pair impacts for 4. (0: none)
  double speed = 2.0;                ///< m/s, relative approach speed of 1. and 4.
};

/// Statistics of a sample.
struct Summary {
  int n = 0;
  double mean = 0.0, std = 0.0, p10 = 0.0, p50 = 0.0, p90 = 0.0, min = 0.0, max = 0.0;
};
Summary summarise(std::vector<double> v);

struct SupportRow {
  int size = 0;
  int bytes = 0;        ///< 6 S^2 floats
  double bound = 0.0;   ///< m, SupportMap3::error_bound
  double mean = 0.0, max = 0.0, min = 0.0;  ///< m, over the directions
};

/// One touching pair of a reference pile.
struct PilePair {
  double distance = 0.0;   ///< |c_b - c_a|, m
  double angle_deg = 0.0;  ///< of the line of centres to the vertical, 0..90
  double along_normal = 0.0;   ///< (c_b - c_a) . n, m
  double support_e = 0.0;      ///< exact hull support sum along e, m
  double support_e_map = 0.0;  ///< the same by the stored cube map, m
  double support_n = 0.0;      ///< exact hull support sum along n, m
  /// Upper bounds of the hulls' contact distance along e from candidate normals (see
  /// radial_estimate): the hull's 6 and 16 largest faces and all its faces, exact support; and
  /// the `candidate_faces` largest by the stored cube map, m.
  double radial6 = 0.0, radial16 = 0.0, radial_all = 0.0, radial_map = 0.0;
  double penetration = 0.0;    ///< deepest manifold point, m (>= 0)
};

struct PairResult {
  PairOptions options;
  ShapeModel model;
  double h_coll = 0.0, h_coll_std = 0.0;  ///< s = 0, m
  std::vector<double> pair_mean, pair_std;  ///< per spin ratio, m
  std::vector<double> pair_hull_mean;       ///< per spin ratio: the hulls' first contact, m
  long long pair_flights = 0;
  double pair_seconds = 0.0;
  std::vector<SupportRow> support;
  std::vector<double> support_map;  ///< the stored cube map (options.support_size)
  double support_bound = 0.0;       ///< its error bound, m
  std::vector<PilePair> pile_pairs;
  int pile_bodies = 0, piles_asleep = 0;
  double pile_seconds = 0.0;
  // responses
  int response_trials = 0;
  double ks_speed = 0.0, ks_spin = 0.0;  ///< KS distance runtime vs Bullet
  double ks_speed_floor = 0.0, ks_spin_floor = 0.0;  ///< KS of two independent Bullet samples
  Summary bullet_speed, bullet_spin, runtime_speed, runtime_spin;
  double response_seconds = 0.0;
};

/// The outward normals of the hull's faces, largest area first (body frame).
std::vector<Eigen::Vector3d> faces_by_area(const ShapeModel& model);

/// The distance along the unit line of centres e (from a to b) at which the hulls of two bodies
/// at orientations ra, rb touch, estimated from above: for every unit n with n.e > 0 the hulls
/// are apart while (c_b - c_a).n exceeds s_a(ra^T n) + s_b(-rb^T n), so the contact distance is
/// at most min over n of [s_a(ra^T n) + s_b(-rb^T n)] / (n.e). Candidates: e, and the first
/// `count` of `faces` (outward face normals, body frame) of a (n = ra f) and of b (n = -rb f).
/// `support` maps a body-frame unit direction to the body's support (exact or a table); with
/// `offsets` (the faces' distances from the centre) a body's support along its own face is
/// that offset, and only the other body's is looked up. Exact when the contact normal is a
/// candidate and the support exact.
template <class Support>
double radial_estimate(const Support& support, const Eigen::Matrix3d& ra, const Eigen::Matrix3d& rb,
                       const Eigen::Vector3d& e, const std::vector<Eigen::Vector3d>& faces, std::size_t count,
                       const std::vector<double>* offsets = nullptr)
{
  const auto along = [&](const Eigen::Vector3d& n, double sa, double sb) {
    const double c = n.dot(e);
    if (!(c > 1e-6)) return std::numeric_limits<double>::infinity();
    const double a = std::isnan(sa) ? support(ra.transpose() * n) : sa;
    const double b = std::isnan(sb) ? support(-(rb.transpose() * n)) : sb;
    return (a + b) / c;
  };
  const double lookup = std::numeric_limits<double>::quiet_NaN();
  double best = along(e, lookup, lookup);
  for (std::size_t k = 0; k < std::min(count, faces.size()); ++k) {
    const double own = offsets ? (*offsets)[k] : lookup;
    best = std::min(best, along(ra * faces[k], own, lookup));
    best = std::min(best, along(-(rb * faces[k]), lookup, own));
  }
  return best;
}

/// The offsets (distance from the centre of mass, m) of the faces of faces_by_area, in order.
std::vector<double> face_offsets(const ShapeModel& model, const std::vector<Eigen::Vector3d>& faces);

/// One pair flight (exposed for the tests): centre distance at the first contact, m, of the
/// hulls (hull_only) or of the true geometry (Bullet's, with `margin`); the hulls' distance and
/// the two states at contact when asked for.
double pair_trial(const ShapeModel& model, double spin_ratio, std::uint64_t seed, std::uint64_t index,
                  bool hull_only, double margin, double* hull_distance = nullptr,
                  std::pair<RigidState, RigidState>* at_contact = nullptr);

/// Pair distance at first contact (1.) per spin ratio: mean, sample standard deviation and the
/// hulls' mean, m; `trials` flights per ratio at relative speed `speed` (m/s), the true geometry
/// with `margin` (m). Deterministic for a seed, any thread count.
struct PairDistances {
  std::vector<double> mean, std, hull_mean;
  long long flights = 0;
};
PairDistances pair_distances(const ShapeModel& model, const std::vector<double>& spin_ratios, int trials, double speed,
                             double margin, std::uint64_t seed, unsigned threads, bool progress);

/// A touching pair of a reference pile: both bodies' poses (position and orientation are set),
/// the mean contact normal from a to b and the deepest manifold point's penetration (m, >= 0).
struct PileContact {
  RigidState a, b;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double penetration = 0.0;
};
/// One reference pile of 3. (a drop pile, or a bin when `options.bin` > 0) run until every body
/// sleeps or `pile_time` passes: its touching pairs (a before b, by body index), body count,
/// whether all slept and the Bullet steps taken.
struct ReferencePile {
  std::vector<PileContact> contacts;
  int bodies = 0;
  bool asleep = false;
  long steps = 0;
};
ReferencePile reference_pile(const ShapeModel& model, const PairOptions& options, std::uint64_t seed);

/// Runs everything the options ask for (deterministic for a seed, any thread count).
PairResult gather_pairs(const PairOptions& options);

/// The JSON: "generated_by" (the regenerating command) first, then every statistic and, under
/// "table", the fields proposed for the signature. No timings (they are in the markdown), so a
/// run with the same options writes the same bytes whatever the thread count.
std::string pairs_json(const PairResult& r, const std::string& command);
/// The markdown report, with the gathering's times.
std::string pairs_markdown(const PairResult& r, const std::string& command);

}  // namespace statsim::tools::ref3d
