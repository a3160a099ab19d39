// See gather_settle.hpp.
#include "ref3d/gather_settle.hpp"

#include "statsim/signature.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace statsim::tools::ref3d {

std::vector<double> settle_quantiles(std::vector<double> times, int quantiles)
{
  std::vector<double> q;
  if (times.empty() || quantiles < 1) return q;
  std::sort(times.begin(), times.end());
  const double n = static_cast<double>(times.size());
  const double last = n - 1;
  for (int k = 0; k < quantiles; ++k) {
    const double p = (k + 0.5) / quantiles;
    const double h = std::min(std::max(p * n - 0.5, 0.0), last);
    const std::size_t lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, times.size() - 1);
    q.push_back(times[lo] + (h - static_cast<double>(lo)) * (times[hi] - times[lo]));
  }
  return q;
}

SettleFit fit_settle(const std::vector<DropTrial>& drops, const std::vector<RestPose>& rest, const GatherOptions& o)
{
  const auto t0 = std::chrono::steady_clock::now();
  SettleFit f;
  if (rest.empty() || drops.empty()) return f;
  f.quantiles = o.settle_quantiles;
  f.settle_speed = o.settle_speed;
  f.quiet_speed = o.quiet_speed;
  std::vector<std::vector<double>> per_pose(rest.size());
  std::vector<double> all;
  for (const DropTrial& d : drops) {
    // The runtime's nearest pose: the largest cosine, the first of equals.
    std::size_t best = 0;
    for (std::size_t i = 1; i < rest.size(); ++i)
      if (rest[i].normal.dot(d.up) > rest[best].normal.dot(d.up)) best = i;
    per_pose[best].push_back(d.settle_time);
    all.push_back(d.settle_time);
    if (!d.settled) ++f.time_limited;
  }
  const double limit = static_cast<double>(max_settle_time);
  for (const std::vector<double>& times : per_pose) {
    const std::vector<double>& used = times.empty() ? all : times;
    for (double x : settle_quantiles(used, f.quantiles)) f.time.push_back(std::min(std::max(x, 0.0), limit));
    f.drops.push_back(static_cast<int>(times.size()));
    double sum = 0.0;
    for (double x : used) sum += x;
    f.mean.push_back(sum / static_cast<double>(used.size()));
  }
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return f;
}

}  // namespace statsim::tools::ref3d
