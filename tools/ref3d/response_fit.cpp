// See response_fit.hpp.
#include "ref3d/response_fit.hpp"

#include "common/sample_stats.hpp"
#include "ref3d/gather.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace statsim::tools::ref3d {

ResponseFit fit_responses(const std::vector<ResponseTrial>& all, std::size_t trials, std::size_t nt, std::size_t np,
                          std::size_t nv, const std::vector<double>& spin_ratios)
{
  ResponseFit f;
  const std::size_t ns = spin_ratios.size(), cells = nt * np * nv * ns;
  f.response_mean.assign(cells * 6, 0.0);
  f.response_std.assign(cells * 6, 0.0);
  for (std::size_t cell = 0; cell < cells; ++cell) {
    const std::size_t is = cell % ns, iv = (cell / ns) % nv, it = cell / (ns * nv * np);
    // At zero spin phi means nothing: pool the trials of every phi.
    std::vector<const ResponseTrial*> pooled;
    if (spin_ratios[is] == 0.0) {
      for (std::size_t jp = 0; jp < np; ++jp) {
        const std::size_t c2 = ((it * np + jp) * nv + iv) * ns + is;
        for (std::size_t t = 0; t < trials; ++t) pooled.push_back(&all[c2 * trials + t]);
      }
    } else {
      for (std::size_t t = 0; t < trials; ++t) pooled.push_back(&all[cell * trials + t]);
    }
    std::vector<Response>& outcomes = f.cell_outcomes.emplace_back();
    for (const ResponseTrial* t : pooled) outcomes.push_back(t->value);
    for (int c = 0; c < 6; ++c) {
      const MeanStd s = mean_std(pooled.size(), [&](std::size_t k) { return pooled[k]->value[c]; });
      f.response_mean[cell * 6 + c] = s.mean;
      f.response_std[cell * 6 + c] = s.std;
    }
  }
  for (const ResponseTrial& t : all) {
    f.time_limited += t.time_limited ? 1 : 0;
    f.no_flight += t.no_flight ? 1 : 0;
    f.max_penetration = std::max(f.max_penetration, t.max_penetration);
  }
  f.response_trials = static_cast<long long>(all.size());
  return f;
}

std::vector<double> cholesky_lower(const std::vector<double>& a, int n)
{
  std::vector<double> l(static_cast<std::size_t>(n * n), 0.0);
  double largest = 0.0;
  for (int i = 0; i < n; ++i) largest = std::max(largest, a[static_cast<std::size_t>(i * n + i)]);
  const double tiny = 1e-12 * largest;
  // Column by column: l_jj = sqrt(a_jj - sum_k l_jk^2), l_ij = (a_ij - sum_k l_ik l_jk) / l_jj.
  for (int j = 0; j < n; ++j) {
    double d = a[static_cast<std::size_t>(j * n + j)];
    for (int k = 0; k < j; ++k) d -= l[static_cast<std::size_t>(j * n + k)] * l[static_cast<std::size_t>(j * n + k)];
    if (!(d > tiny)) continue;  // no variance left in this direction: a zero column
    const double ljj = std::sqrt(d);
    l[static_cast<std::size_t>(j * n + j)] = ljj;
    for (int i = j + 1; i < n; ++i) {
      double x = a[static_cast<std::size_t>(i * n + j)];
      for (int k = 0; k < j; ++k) x -= l[static_cast<std::size_t>(i * n + k)] * l[static_cast<std::size_t>(j * n + k)];
      l[static_cast<std::size_t>(i * n + j)] = x / ljj;
    }
  }
  std::vector<double> packed;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j) packed.push_back(l[static_cast<std::size_t>(i * n + j)]);
  return packed;
}

std::vector<double> response_spread(const GatherResult& r)
{
  const GatherOptions& o = r.options;
  if (o.response_model == ResponseModel::independent_gaussian) return r.response_std;
  const std::size_t cells = r.response_mean.size() / 6;
  if (r.cell_outcomes.size() != cells)
    throw std::runtime_error(std::string("the ") + response_model_name(o.response_model) +
                             " response model needs every cell's trial outcomes");
  std::vector<double> out;
  for (std::size_t cell = 0; cell < cells; ++cell) {
    const std::vector<Response>& t = r.cell_outcomes[cell];
    if (o.response_model == ResponseModel::correlated_gaussian) {
      std::vector<double> cov(36, 0.0);
      const double* mean = &r.response_mean[cell * 6];
      for (const Response& x : t)
        for (int i = 0; i < 6; ++i)
          for (int j = 0; j < 6; ++j) cov[static_cast<std::size_t>(i * 6 + j)] += (x[i] - mean[i]) * (x[j] - mean[j]);
      const double n1 = t.size() > 1 ? static_cast<double>(t.size() - 1) : 1.0;
      for (double& c : cov) c /= n1;
      const std::vector<double> l = cholesky_lower(cov, 6);
      out.insert(out.end(), l.begin(), l.end());
    } else {
      const std::size_t k = static_cast<std::size_t>(o.empirical_outcomes);
      if (t.size() < k) throw std::runtime_error("a cell has fewer outcomes than --empirical-outcomes");
      // Ranks by the normal velocity offset (component 5), ties by trial order: a stable sort.
      std::vector<std::size_t> order(t.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::stable_sort(order.begin(), order.end(), [&t](std::size_t a, std::size_t b) { return t[a][5] < t[b][5]; });
      std::vector<Response> kept;
      for (std::size_t i = 0; i < k; ++i) kept.push_back(t[order[(2 * i + 1) * t.size() / (2 * k)]]);
      Response centre{};
      for (const Response& x : kept)
        for (int c = 0; c < 6; ++c) centre[c] += x[c] / static_cast<double>(k);
      for (const Response& x : kept)
        for (int c = 0; c < 6; ++c) out.push_back(x[c] - centre[c]);
    }
  }
  return out;
}

}  // namespace statsim::tools::ref3d
