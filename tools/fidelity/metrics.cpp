#include "fidelity/metrics.hpp"

#include <algorithm>
#include <cmath>

namespace statsim::tools::fidelity {
namespace {

std::uint64_t splitmix64(std::uint64_t& state)
{
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Unbiased index in [0, n) by rejection.
std::size_t below(std::uint64_t& state, std::size_t n)
{
  const std::uint64_t m = static_cast<std::uint64_t>(n);
  const std::uint64_t limit = ~std::uint64_t{0} - (~std::uint64_t{0} % m);
  std::uint64_t x;
  do {
    x = splitmix64(state);
  } while (x >= limit);
  return static_cast<std::size_t>(x % m);
}

double percentile(std::vector<double> v, double p)
{
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(pos));
  if (i + 1 >= v.size()) return v.back();
  const double t = pos - static_cast<double>(i);
  return v[i] + (v[i + 1] - v[i]) * t;
}

}  // namespace

double tvd(const std::vector<double>& a, const std::vector<double>& b)
{
  double sa = 0, sb = 0;
  for (double x : a) sa += x;
  for (double x : b) sb += x;
  if (sa <= 0 && sb <= 0) return 0.0;
  if (sa <= 0 || sb <= 0) return 1.0;
  const std::size_t n = std::max(a.size(), b.size());
  double d = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double p = k < a.size() ? a[k] / sa : 0.0;
    const double q = k < b.size() ? b[k] / sb : 0.0;
    d += std::fabs(p - q);
  }
  return 0.5 * d;
}

namespace {

/// Calls step(x, fa, fb) at each jump point x of the empirical CDFs of `a` and `b` (sorted, not
/// empty), in increasing order, with fa and fb the two CDFs just after x.
template <class Step>
void walk_cdfs(const std::vector<double>& a, const std::vector<double>& b, Step step)
{
  const double na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    const double x = j >= b.size() || (i < a.size() && a[i] <= b[j]) ? a[i] : b[j];
    while (i < a.size() && a[i] == x) ++i;
    while (j < b.size() && b[j] == x) ++j;
    step(x, static_cast<double>(i) / na, static_cast<double>(j) / nb);
  }
}

}  // namespace

double w1(std::vector<double> a, std::vector<double> b)
{
  if (a.empty() || b.empty()) return 0.0;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  // Between consecutive jump points both CDFs are constant.
  double x0 = std::min(a[0], b[0]), fa0 = 0, fb0 = 0;
  double d = 0;
  walk_cdfs(a, b, [&](double x, double fa, double fb) {
    d += std::fabs(fa0 - fb0) * (x - x0);
    x0 = x;
    fa0 = fa;
    fb0 = fb;
  });
  return d;
}

double ks(std::vector<double> a, std::vector<double> b)
{
  if (a.empty() || b.empty()) return 0.0;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  double d = 0;
  walk_cdfs(a, b, [&](double, double fa, double fb) { d = std::max(d, std::fabs(fa - fb)); });
  return d;
}

double mean(const std::vector<double>& a)
{
  if (a.empty()) return 0.0;
  double s = 0;
  for (double x : a) s += x;
  return s / static_cast<double>(a.size());
}

std::vector<std::size_t> iota(std::size_t n)
{
  std::vector<std::size_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = i;
  return v;
}

Interval bootstrap(std::size_t n_a, std::size_t n_b,
                   const std::function<double(const std::vector<std::size_t>&, const std::vector<std::size_t>&)>& statistic,
                   int resamples, double level, std::uint64_t seed)
{
  if (n_a == 0 || n_b == 0 || resamples < 1) {
    const double s = statistic(iota(n_a), iota(n_b));
    return {s, s};
  }
  std::uint64_t state = seed;
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(resamples));
  std::vector<std::size_t> ia(n_a), ib(n_b);
  for (int r = 0; r < resamples; ++r) {
    for (auto& i : ia) i = below(state, n_a);
    for (auto& i : ib) i = below(state, n_b);
    values.push_back(statistic(ia, ib));
  }
  return {percentile(values, 0.5 * (1 - level)), percentile(values, 0.5 * (1 + level))};
}

}  // namespace statsim::tools::fidelity
