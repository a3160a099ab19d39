// The landing stage of `statsim gather` (statsim/signature_landing.hpp has the model): impacts
// with gravity from the response trials' first contacts, on a grid of (cos theta, spin ratio,
// Froude number), each followed until the body flies off (rises at least `hop` L, as
// common/flight_top.hpp finds it), comes to rest or a second has passed; against them, the
// runtime's own draws from the gathered response tables at each trial's contact. Per cell: the
// trials' share of stays s, the draws' mean share q, and the table's landing probability: the
// extra stays (s - q) / (1 - q) where s >= q, else minus the share of stays drawn again,
// (q - s) / (q (1 - q)), at most 1.
#pragma once

#include "ref3d/gather_options.hpp"
#include "ref3d/reference_pool.hpp"
#include "statsim/signature.hpp"

#include <vector>

namespace statsim::tools::ref3d {

/// What the landing stage measured (a part of GatherResult).
struct LandingFit {
  double hop = 0;  ///< rise over L below which an impact counts as a stay
  std::vector<double> cos_theta, spin_ratio, froude;  ///< the axes
  std::vector<double> probability;  ///< landing probability per cell, row-major in the axes
  std::vector<double> stays;        ///< the trials' share of stays per cell
  std::vector<double> draw_stays;   ///< the runtime draws' mean share of stays per cell
  long long trials = 0;
  double seconds = 0;
  bool present() const { return !probability.empty(); }
};

/// Runs the stage for the shape of `pool` with the options `o`; `tables` is the signature the
/// runtime would read (its response tables are drawn from, at the stored precision).
LandingFit gather_landing(const GatherOptions& o, ReferencePool& pool, const SignatureView<3>& tables);

}  // namespace statsim::tools::ref3d
