// The two-sample Kolmogorov-Smirnov distance, shared by the host tools that compare a runtime's
// draws with a reference's outcomes (`statsim gather`'s spin measure, `gather-pairs`).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace statsim::tools {

/// The largest gap between the empirical distribution functions of `a` and `b`; 0 when either
/// is empty.
inline double ks_distance(std::vector<double> a, std::vector<double> b)
{
  if (a.empty() || b.empty()) return 0.0;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  std::size_t i = 0, j = 0;
  double d = 0.0;
  while (i < a.size() && j < b.size()) {
    const double x = std::min(a[i], b[j]);
    while (i < a.size() && a[i] <= x) ++i;
    while (j < b.size() && b[j] <= x) ++j;
    d = std::max(d, std::fabs(static_cast<double>(i) / static_cast<double>(a.size()) -
                              static_cast<double>(j) / static_cast<double>(b.size())));
  }
  return d;
}

/// The distance two samples of sizes n and m exceed with probability 5% when drawn from one
/// distribution (asymptotic: 1.358 sqrt((n + m) / (n m))).
inline double ks_critical_5(std::size_t n, std::size_t m)
{
  return 1.358 * std::sqrt(static_cast<double>(n + m) / (static_cast<double>(n) * static_cast<double>(m)));
}

}  // namespace statsim::tools
