#include "common/rest_families.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace statsim::tools {

namespace {

bool equivalent(const std::vector<double>& a, const std::vector<double>& b, double tolerance)
{
  if (a.empty() || a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (!(std::fabs(a[k] - b[k]) <= tolerance)) return false;
  return true;
}

}  // namespace

std::vector<int> rest_families(const std::vector<RestCandidate>& candidates, double tolerance)
{
  const std::size_t n = candidates.size();
  // Raw families in order of their first member, then renumbered by summed frequency.
  std::vector<int> raw(n, -1);
  std::vector<std::size_t> first;  // first member of each raw family
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t f = 0; f < first.size() && raw[i] < 0; ++f)
      if (equivalent(candidates[first[f]].descriptor, candidates[i].descriptor, tolerance)) raw[i] = static_cast<int>(f);
    if (raw[i] < 0) {
      raw[i] = static_cast<int>(first.size());
      first.push_back(i);
    }
  }
  std::vector<double> sum(first.size(), 0.0);
  for (std::size_t i = 0; i < n; ++i) sum[static_cast<std::size_t>(raw[i])] += candidates[i].frequency;
  std::vector<int> order(first.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return sum[a] > sum[b]; });
  std::vector<int> rank(first.size());
  for (std::size_t k = 0; k < order.size(); ++k) rank[static_cast<std::size_t>(order[k])] = static_cast<int>(k);
  std::vector<int> family(n);
  for (std::size_t i = 0; i < n; ++i) family[i] = rank[static_cast<std::size_t>(raw[i])];
  return family;
}

RestSelection select_rest_poses(const std::vector<RestCandidate>& candidates, const RestSelectionOptions& o)
{
  RestSelection s;
  const std::size_t n = candidates.size();
  s.family = rest_families(candidates, o.tolerance);
  int families = 0;
  for (int f : s.family) families = std::max(families, f + 1);
  s.family_frequency.assign(static_cast<std::size_t>(families), 0.0);
  std::vector<int> count(static_cast<std::size_t>(families), 0), size(static_cast<std::size_t>(families), 0);
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto f = static_cast<std::size_t>(s.family[i]);
    s.family_frequency[f] += candidates[i].frequency;
    count[f] += candidates[i].count;
    ++size[f];
    total += candidates[i].frequency;
  }
  std::vector<char> family_kept(static_cast<std::size_t>(families), 0);
  std::size_t poses = 0;
  double kept = 0.0;
  const auto keep = [&](std::size_t f) {
    if (poses + static_cast<std::size_t>(size[f]) > o.max_poses) return;
    family_kept[f] = 1;
    poses += static_cast<std::size_t>(size[f]);
    kept += s.family_frequency[f];
  };
  // Families are numbered most frequent first.
  for (std::size_t f = 0; f < s.family_frequency.size(); ++f)
    if (s.family_frequency[f] > o.min_frequency) keep(f);
  const auto dropped = [&] { return total > 0 ? (total - kept) / total : 0.0; };
  for (std::size_t f = 0; f < s.family_frequency.size() && dropped() > o.max_dropped; ++f)
    if (!family_kept[f] && count[f] >= o.min_count) keep(f);
  s.kept.assign(n, 0);
  double lost = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    s.kept[i] = family_kept[static_cast<std::size_t>(s.family[i])];
    if (!s.kept[i]) lost += candidates[i].frequency;
  }
  // Summed from the dropped poses themselves (not 1 - kept), so that nothing dropped reads as a
  // rounding residue.
  s.dropped = total > 0 ? lost / total : 0.0;
  return s;
}

}  // namespace statsim::tools
