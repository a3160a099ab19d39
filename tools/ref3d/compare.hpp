// `statsim compare-tables`: how far a 3D signature is from another one scaled by a size factor s
// (tools/ref3d/README.md, "One table at any size"). Each quantity of the reference table A is
// multiplied by s^k, k its power of length (h_coll 1, mass 3, unit inertia 2, normalised
// responses 0...), and compared with the same quantity of table B. Distances are in units of the
// quantity's own spread where the table stores one, relative differences otherwise; comparing a
// table with itself at s = 1 gives 0 for every quantity.
#pragma once

#include "statsim/signature.hpp"

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace statsim::tools {

/// The distance of one quantity of B from the same quantity of A scaled by s^exponent, over its
/// `count` samples (cells, poses, nodes...).
struct QuantityDistance {
  std::string name;     ///< e.g. "h_coll", "response dv_z"
  int exponent = 0;     ///< the quantity scales as s^exponent
  std::string measure;  ///< what `mean` and `max` are, e.g. "W2/spread"
  int count = 0;
  double mean = 0;  ///< mean of the per-sample distances
  double max = 0;   ///< largest per-sample distance
};

struct TableComparison {
  double scale = 1;
  std::vector<QuantityDistance> quantities;
  /// The quantity named `name`, or null.
  const QuantityDistance* find(const std::string& name) const;
};

/// Compares B with A scaled by `scale` (> 0). The two tables must share their response layout,
/// model and axes and their h_coll axis (they come from gatherings with the same options); throws
/// std::invalid_argument otherwise. Body-body quantities are compared when both tables have them
/// (support maps of the same size).
TableComparison compare_tables(const SignatureView<3>& a, const SignatureView<3>& b, double scale);

/// The comparison as a text table (one line per quantity).
std::string comparison_text(const TableComparison& c);

/// The comparison as JSON: {"scale", "quantities": [{name, exponent, measure, count, mean, max}]}.
std::string comparison_json(const TableComparison& c, const std::string& command);

/// Registers `statsim compare-tables`.
void add_compare_command(CLI::App& app);

}  // namespace statsim::tools
