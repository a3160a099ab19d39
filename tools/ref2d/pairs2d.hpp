// `statsim gather-pairs2d`: body-body statistics of a 2D shape with Box2D, the 2D counterpart
// of `statsim gather-pairs` (tools/ref3d/pairs.hpp).
//
// 1. Pair distance: two bodies at uniform random angles, spinning at s |v| / L with a random
//    sign each, thrown head-on at each other; the centre distance at their first contact, exact:
//    conservative advancement on the distance of the true outlines (the least vertex-to-edge
//    distance either way, in double precision; a concave outline is exact too), and of the hulls.
// 2. Support map: the square map of the hull's support (common/support_map.hpp) at several S.
// 3. Packing: the piles of `statsim compare2d` (compare2d_initial_states, the committed table's
//    material, Box2D at 1/60 s with 8 velocity and 3 position iterations for `steps` steps); for
//    every pair of bodies with a touching contact, the centre distance against 2 h_coll (the
//    committed table's, s = 0), the pair distance at s = 0, the hull support along the line of
//    centres e and the upper bound from candidate normals (e and every hull edge normal of either
//    body), and the separation along Box2D's contact normal against the support along it.
#pragma once

#include "ref2d/polygon2d.hpp"
#include "statsim/signature.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace statsim::tools {

struct Pairs2dOptions {
  std::string shape = "square";  ///< square or lshape (a committed table gives h_coll and the material)
  std::vector<double> spin_ratios = {0, 0.5, 1, 2, 4, 8};
  int trials = 2000;
  std::vector<int> support_sizes = {3, 5, 9, 17, 33};
  int support_size = 9;
  int drops = 10;       ///< piles (seeds seed..seed+drops-1)
  int n = 100;          ///< bodies per pile
  int steps = 900;      ///< steps of 1/60 s
  double speed = 2.0;   ///< m/s
  std::uint64_t seed = 1;
  unsigned threads = 0;
};

struct Pairs2dPile {
  double distance = 0.0, angle_deg = 0.0, along_normal = 0.0;
  double support_e = 0.0, support_e_map = 0.0, support_n = 0.0, radial = 0.0, radial_map = 0.0;
};

struct Pairs2dResult {
  Pairs2dOptions options;
  double bounding_radius = 0.0;
  double h_coll = 0.0;  ///< the committed table's mean at s = 0, m
  std::vector<double> pair_mean, pair_std, hull_mean;
  double pair_seconds = 0.0;
  struct Support {
    int size = 0;
    double bound = 0.0, mean = 0.0, max = 0.0;
  };
  std::vector<Support> support;
  std::vector<double> support_map;
  double support_bound = 0.0;
  std::vector<Pairs2dPile> pile_pairs;
  int asleep = 0, bodies = 0;
  double pile_seconds = 0.0;
};

/// Pair distance at first contact (1.) per spin ratio: mean, sample standard deviation and the
/// hulls' mean, m; `trials` flights per ratio at relative speed `speed` (m/s). Deterministic for a
/// seed, any thread count.
struct PairDistances2d {
  std::vector<double> mean, std, hull_mean;
  long long flights = 0;
};
PairDistances2d pair_distances2d(const Shape2& shape, const std::vector<double>& spin_ratios, int trials, double speed,
                                 std::uint64_t seed, unsigned threads);

/// A touching pair of a Box2D pile (3.): centres (m), angles (rad) and the mean contact normal
/// from a to b (a before b by body index).
struct Pile2dContact {
  Eigen::Vector2d ca = Eigen::Vector2d::Zero(), cb = Eigen::Vector2d::Zero();
  double angle_a = 0.0, angle_b = 0.0;
  Eigen::Vector2d normal = Eigen::Vector2d::UnitY();
};
/// One pile of `statsim compare2d` (`n` bodies of `shape` with the material and restitution
/// threshold of `sig`, `steps` steps of 1/60 s, initial states from `seed`): its touching pairs;
/// `asleep` tells whether every body slept at the end.
std::vector<Pile2dContact> box2d_pile_contacts(const Shape2& shape, const statsim::SignatureView<2>& sig, int n,
                                               int steps, std::uint64_t seed, bool& asleep);

/// Centre distance at the first contact of one pair flight (exposed for the tests): of the true
/// outlines, or of the hulls (`hull_only`).
double pair_trial2d(const std::string& shape, double spin_ratio, std::uint64_t seed, std::uint64_t index,
                    bool hull_only);

Pairs2dResult gather_pairs2d(const Pairs2dOptions& options);
/// As ref3d::pairs_json: the command first, no timings, the proposed fields under "table".
std::string pairs2d_json(const Pairs2dResult& r, const std::string& command);
std::string pairs2d_markdown(const Pairs2dResult& r, const std::string& command);

/// Adds `gather-pairs2d` to `app`.
void register_pairs2d_command(CLI::App& app);

}  // namespace statsim::tools
