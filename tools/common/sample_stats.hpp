// The mean and sample standard deviation (n - 1) of the trial outcomes, two-pass, shared by the
// statistics of `statsim gather` (3D) and `statsim gather2d` (2D): one summation order, so that
// every table's means and spreads come from the same arithmetic.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

namespace statsim::tools {

struct MeanStd {
  double mean = 0.0, std = 0.0;  ///< 0 and 0 for no value; std 0 for one
};

/// Of get(0) .. get(n - 1).
template <class Get>
MeanStd mean_std(std::size_t n, Get&& get)
{
  MeanStd s;
  if (n == 0) return s;
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) sum += get(i);
  s.mean = sum / static_cast<double>(n);
  if (n < 2) return s;
  double sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = get(i) - s.mean;
    sq += d * d;
  }
  s.std = std::sqrt(sq / static_cast<double>(n - 1));
  return s;
}

inline MeanStd mean_std(const std::vector<double>& xs)
{
  return mean_std(xs.size(), [&](std::size_t i) { return xs[i]; });
}

}  // namespace statsim::tools
