// `statsim gather --cell-report FILE`: how far the paper's response model (an independent
// Gaussian per component and cell) is from the trials it is fitted to, measured on the
// gathering's own trial outcomes, cell by cell:
//  - shape: the Kolmogorov-Smirnov distance of each component's outcomes from the Gaussian of
//    their mean and standard deviation, against Lilliefors' 5% critical value 0.886 / sqrt(n)
//    (the KS test with estimated parameters): a cell above it is not Gaussian in that component;
//  - correlation: Pearson's r of each pair of components; |r| > 0.5 is a correlation the paper's
//    model drops;
//  - modes: the bimodality coefficient (g^2 + 1) / (k + 3 (n - 1)^2 / ((n - 2)(n - 3))), g the
//    sample skewness and k the excess kurtosis; above 5/9 (its value for a uniform distribution)
//    the component is likely bimodal.
// Components without spread in a cell (a constant outcome) are left out of its shape and modes.
#pragma once

#include "ref3d/gather.hpp"

#include <string>

namespace statsim::tools::ref3d {

/// Per-component and per-pair summary over the cells of `r` (which needs `r.cell_outcomes`).
struct CellReport {
  int cells = 0;
  int components = 6;
  /// Per component: cells with spread, cells above Lilliefors' 5% value, median KS distance,
  /// cells whose bimodality coefficient exceeds 5/9.
  int with_spread[6] = {};
  int not_gaussian[6] = {};
  double median_ks[6] = {};
  int bimodal[6] = {};
  /// Per pair (i < j): mean r over the cells where both have spread, and cells with |r| > 0.5.
  double mean_r[6][6] = {};
  int strong[6][6] = {};
  int cells_with_strong = 0;   ///< cells with at least one pair |r| > 0.5
  int cells_multimodal = 0;    ///< cells with at least one bimodal component
  int cells_not_gaussian = 0;  ///< cells with at least one component above Lilliefors' value
};

CellReport cell_report(const GatherResult& r);

/// The report as markdown (what `--cell-report` writes), with the definitions above.
std::string cell_report_text(const GatherResult& r, const CellReport& c);

/// The same as JSON (for charts).
std::string cell_report_json(const CellReport& c);

}  // namespace statsim::tools::ref3d
