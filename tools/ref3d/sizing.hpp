// `statsim gather --size-for-scene`: the smallest table a scene needs.
//
// A scene sees a limited range of impacts: speeds from some v_min to v_max (v_max = sqrt(2 g H)
// for a drop from height H) and spins up to w_max. With the bounding radius L, the largest spin
// ratio it meets is s_max = w_max L / v_min. The sizing:
// 1. gathers a dense table over that range: the given axes (default: the default axes), the spin
//    ratio axes of the response and h_coll tables cut at s_max (s_max itself becomes the last
//    sample), and for the paper's layout the speed axis cut to [v_min, v_max];
// 2. considers candidate tables made of subsets of the dense samples: per axis, m samples spread
//    evenly in index over the dense axis, the two ends always kept (so every dense sample lies
//    inside the candidate's range), each f32 or i16;
// 3. measures each candidate's error against the dense table at every dense cell: the runtime's
//    own lookup (ResponseTableView::lookup on the candidate's float or dequantised 16-bit values)
//    gives mean mu_c and spread sigma_c; the dense cell has mu_d, sigma_d. The miss is the
//    2-Wasserstein distance between the normal distributions N(mu_c, sigma_c) and
//    N(mu_d, sigma_d), sqrt((mu_c - mu_d)^2 + (sigma_c - sigma_d)^2), in units of the dense
//    cell's spread max(sigma_d, floor) (floor: `sigma_floor` times the component's median spread
//    over the table, so near-deterministic cells do not dominate). The response error is the
//    arithmetic mean of that over all dense cells and the 6 components; the h_coll error is the
//    mean over the dense spin ratios of |h_c - h_d| / max(std_d, floor) with the runtime's
//    HeightTableView::mean_at (the runtime reads only the mean height);
//    sampling noise removed: the dense means and spreads come from T trials a cell, so even a
//    response the candidate could interpolate exactly misses by noise. With multilinear weights
//    w_k over the candidate's corner cells (each from the same gathering, independent), the
//    noise of mu_c - mu_d has variance sigma^2 / T (1 + sum w_k^2), and of sigma_c - sigma_d about
//    sigma^2 / (2 (T - 1)) (1 + sum w_k^2), where sum w_k^2 = prod over axes ((1 - t)^2 + t^2)
//    (0 noise at a cell the candidate keeps: it is the same number). The miss counted is
//    sqrt(max(0, miss^2 - that variance)), an estimate of the systematic (interpolation) part,
//    so that the budget speaks of the table's shape, not of the gathering's noise; the
//    uncorrected mean is reported beside it (`raw_error`);
// 4. picks the response candidate with the fewest bytes whose error is within the budget (ties:
//    the smaller error), and independently the h_coll axis with the fewest samples within it;
//    the table's error is the larger of the two.
// The dense table fits itself exactly (error 0 up to float rounding), so a positive budget is
// always met. Uncorrected, a cell midway between kept samples would miss by about
// sqrt(2/pi) sqrt(1.5 / T) ~ 0.18 sigma in its mean alone for T = 30 impacts a cell, whatever
// the response's shape; the correction removes that on average (noise still scatters the
// corrected error, by roughly the same order divided by the square root of the cells).
#pragma once

#include "ref3d/gather.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace statsim::tools::ref3d {

/// The range of impacts a scene will see.
struct SceneRange {
  double max_speed = 0.0;  ///< m/s, e.g. sqrt(2 g H) for a drop from H
  double min_speed = 0.0;  ///< m/s, > 0; the default in the command: restitution x max_speed
  double max_spin = 0.0;   ///< rad/s, >= 0
};

/// s_max = max_spin L / min_speed, the largest spin ratio of the scene (L in m).
double scene_max_spin_ratio(const SceneRange& scene, double length);

/// `axis` cut at `hi`: the samples below hi, then hi itself (when hi is inside the axis);
/// unchanged when hi is at or beyond its last sample.
std::vector<double> cut_axis(const std::vector<double>& axis, double hi);

/// The dense gathering's options for a scene: `o` with the spin ratio axes cut at the scene's
/// s_max (L = `length`), and with the paper's layout the speed axis cut to [min, max speed].
/// Throws std::runtime_error on a bad range.
GatherOptions scene_dense_options(const GatherOptions& o, const SceneRange& scene, double length);

/// A dense table to cut candidates from (synthetic in tests, else from a gathering).
struct DenseTable {
  std::vector<std::vector<double>> axes;  ///< 1 to 4 response axes, in table order
  std::size_t components = 6;
  std::vector<double> mean, stddev;       ///< cells x components, row-major in the axes
  std::vector<double> height_axis, height_mean, height_stddev;
  std::size_t rest_poses = 0;             ///< counted in the bytes only
  /// Trials behind each response cell's statistics (empty: exact values, no noise correction).
  std::vector<double> cell_trials;
  double height_trials = 0;               ///< flights per h_coll sample (0: exact)
};
DenseTable dense_table(const GatherResult& r);

struct SizingOptions {
  double budget = 0.05;       ///< largest error accepted, in units of the dense spread
  double sigma_floor = 0.05;  ///< floor of a cell's spread, times its component's median spread
  bool allow_i16 = true;
  unsigned threads = 1;
};

struct Candidate {
  std::vector<std::vector<std::size_t>> keep;  ///< per response axis: kept dense indices
  bool i16 = false;
  double error = 0.0;      ///< mean normalised miss over the dense cells and components, noise removed
  double raw_error = 0.0;  ///< the same without removing the sampling noise
  double max_error = 0.0;  ///< largest normalised miss (noise removed) of one cell and component
  std::size_t bytes = 0;   ///< the whole signature's bytes with the chosen h_coll axis
};

struct HeightCandidate {
  std::vector<std::size_t> keep;
  double error = 0.0, raw_error = 0.0, max_error = 0.0;
};

struct SizingResult {
  std::vector<Candidate> candidates;         ///< every response candidate considered
  std::size_t chosen = 0;                    ///< index into candidates
  std::vector<HeightCandidate> height_candidates;
  std::size_t height_chosen = 0;
  double error = 0.0;                        ///< max(response error, h_coll error) of the choice
  double budget = 0.0;
};

/// `m` indices spread evenly over [0, n): round(j (n - 1) / (m - 1)), j = 0 .. m-1 (m >= 2; m = 1
/// or n = 1 gives {0}).
std::vector<std::size_t> spread_indices(std::size_t n, std::size_t m);

/// The sample counts tried on an axis of n dense samples: every count from 2 to n up to 12,
/// then about 15% apart, always n itself (an axis of one sample: 1).
std::vector<std::size_t> candidate_counts(std::size_t n);

/// Errors of one response candidate / one h_coll axis against the dense table.
Candidate response_error(const DenseTable& d, const std::vector<std::vector<std::size_t>>& keep, bool i16,
                         double sigma_floor);
HeightCandidate height_error(const DenseTable& d, const std::vector<std::size_t>& keep, double sigma_floor);

/// Bytes of a 3D signature as stored (the count of signature_json.hpp's signature_bytes()): ten
/// scalars and two words, the h_coll table (3 x nh), the four axes (an unused axis has one
/// sample), the response mean and std at 4 or 2 bytes a value (i16: plus two scales and two
/// offsets) and 5 scalars per rest pose.
std::size_t signature_bytes(std::size_t height_samples, const std::vector<std::size_t>& axis_sizes,
                            std::size_t components, std::size_t rest_poses, bool i16);

/// Considers every candidate and picks the smallest within the budget (see the file comment).
SizingResult size_table(const DenseTable& d, const SizingOptions& o);

/// The chosen table cut from the dense gathering, with `notes` for its header.
GatherResult sized_result(const GatherResult& dense, const SizingResult& s, const std::vector<std::string>& notes);

/// The candidates as text: the chosen one, and the error against bytes of the best candidate
/// at each size that beats every smaller one (all candidates with `all`).
std::string sizing_report(const DenseTable& d, const SizingResult& s, bool all);

}  // namespace statsim::tools::ref3d
