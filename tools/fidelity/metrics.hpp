// Distances between samples for `statsim fidelity`: total variation distance of histograms,
// 1-Wasserstein distance and Kolmogorov-Smirnov statistic of empirical distributions, and
// percentile bootstrap intervals. Plain functions of their arguments, deterministic.
#pragma once

#include "common/pick.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

namespace statsim::tools::fidelity {

/// Total variation distance 0.5 * sum_k |p_k - q_k| of two histograms given as counts (or any
/// non-negative weights), each normalised to sum 1. Bins missing from the shorter one count as 0.
/// 0 when both are empty; 1 when exactly one is empty.
double tvd(const std::vector<double>& a, const std::vector<double>& b);

/// 1-Wasserstein distance of the empirical distributions of two samples: the integral over x of
/// |F_a(x) - F_b(x)| (for equal sizes, the mean |a_(i) - b_(i)| of the sorted samples). In the
/// samples' unit. 0 when either sample is empty (nothing to compare).
double w1(std::vector<double> a, std::vector<double> b);

/// Kolmogorov-Smirnov statistic: sup over x of |F_a(x) - F_b(x)|, in [0, 1]. 0 when either
/// sample is empty.
double ks(std::vector<double> a, std::vector<double> b);

/// Arithmetic mean; 0 for an empty sample.
double mean(const std::vector<double>& a);

/// Percentile bootstrap interval of a two-sample statistic.
struct Interval {
  double lo = 0;
  double hi = 0;
};

/// Resamples both samples with replacement (`resamples` times; indices drawn from a splitmix64
/// stream seeded with `seed`), evaluates `statistic(indices_a, indices_b)` on each pair of
/// resampled index lists, and returns the (1 - level)/2 and (1 + level)/2 percentiles (linear
/// interpolation between order statistics). With an empty sample, or resamples < 1, returns
/// the statistic on the full samples at both ends.
Interval bootstrap(std::size_t n_a, std::size_t n_b,
                   const std::function<double(const std::vector<std::size_t>&, const std::vector<std::size_t>&)>& statistic,
                   int resamples = 200, double level = 0.90, std::uint64_t seed = 0x626f6f74ull);

/// 0, 1, ..., n - 1.
std::vector<std::size_t> iota(std::size_t n);

/// The bootstrap interval of get(stats(method, reference)) over resamples of both samples.
template <class Run, class Stats, class Get>
Interval resampled(const std::vector<Run>& method, const std::vector<Run>& reference, const Stats& stats,
                   const Get& get, int resamples)
{
  return bootstrap(
      method.size(), reference.size(),
      [&](const std::vector<std::size_t>& ia, const std::vector<std::size_t>& ib) {
        return get(stats(pick(method, ia), pick(reference, ib)));
      },
      resamples);
}

}  // namespace statsim::tools::fidelity
