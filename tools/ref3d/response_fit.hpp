// The response stage of `statsim gather` after the trials: each cell's mean and standard
// deviation of the normalised outcomes (the trials of every cos phi pooled at spin ratio 0), and
// the spread each response model stores (paper: the deviations; correlated: a Cholesky factor;
// empirical: kept outcomes). Needs no reference engine: the trials are given.
#pragma once

#include "ref3d/gather_trials.hpp"

#include <cstddef>
#include <vector>

namespace statsim::tools::ref3d {

struct GatherResult;

/// The statistics of every response cell (a part of GatherResult).
struct ResponseFit {
  std::vector<double> response_mean, response_std;  ///< cells x 6, row-major in the axes
  /// Per cell, the trial outcomes its statistics were taken over (at spin ratio 0, the trials of
  /// every cos phi of its cos theta and speed, pooled).
  std::vector<std::vector<Response>> cell_outcomes;
  long long response_trials = 0;
  long long time_limited = 0;
  long long no_flight = 0;  ///< GatherOptions::response_flight: trials not flown off (ResponseTrial::no_flight)
  double max_penetration = 0.0;
};

/// `all` holds `trials` trials a cell, the cells row-major in (cos theta: nt, cos phi: np,
/// speed: nv, spin ratio: spin_ratios); a cell at spin ratio 0 takes the trials of every cos phi.
ResponseFit fit_responses(const std::vector<ResponseTrial>& all, std::size_t trials, std::size_t nt, std::size_t np,
                          std::size_t nv, const std::vector<double>& spin_ratios);

/// The spread values of every cell (cells x statsim::response_spread_size), by the model of
/// `r.options`, from `r.cell_outcomes` (the paper's model: `r.response_std`):
///  - correlated: the lower triangle, row by row, of the Cholesky factor of the cell's sample
///    covariance (n - 1); a direction without variance gets a zero column.
///  - empirical: `empirical_outcomes` of the cell's outcomes, picked at evenly spaced ranks of
///    the normal velocity offset (so the kept outcomes span its distribution, the other
///    components coming with them), each minus the mean of the kept ones (a draw's mean is then
///    the table's mean).
/// Throws std::runtime_error when a model needs outcomes that `r` lacks.
std::vector<double> response_spread(const GatherResult& r);

/// Lower triangle, row by row, of a Cholesky factor of the symmetric positive semi-definite
/// n x n matrix `a` (row-major); a pivot not above 1e-12 times the largest diagonal is taken
/// as 0 with its column.
std::vector<double> cholesky_lower(const std::vector<double>& a, int n);

}  // namespace statsim::tools::ref3d
