#include "ref3d/cell_report.hpp"

#include "common/format.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace statsim::tools::ref3d {

namespace {

const char* const kComponents[6] = {"w_x", "w_y", "w_z", "dv_x", "dv_y", "dv_z"};

// Standard normal CDF.
double phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// One-sample KS distance of `x` from N(mean, sd).
double ks_gaussian(std::vector<double> x, double mean, double sd)
{
  std::sort(x.begin(), x.end());
  const double n = static_cast<double>(x.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double f = phi((x[i] - mean) / sd);
    d = std::max({d, f - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - f});
  }
  return d;
}

}  // namespace

CellReport cell_report(const GatherResult& r)
{
  if (r.cell_outcomes.empty()) throw std::runtime_error("the cell report needs the gathering's trial outcomes");
  CellReport c;
  c.cells = static_cast<int>(r.cell_outcomes.size());
  std::vector<double> ks[6];
  int pair_cells[6][6] = {};
  for (const std::vector<Response>& t : r.cell_outcomes) {
    const std::size_t n = t.size();
    if (n < 4) continue;
    double mean[6] = {}, sd[6] = {};
    for (const Response& x : t)
      for (int k = 0; k < 6; ++k) mean[k] += x[k] / static_cast<double>(n);
    for (const Response& x : t)
      for (int k = 0; k < 6; ++k) sd[k] += (x[k] - mean[k]) * (x[k] - mean[k]);
    bool spread[6];
    for (int k = 0; k < 6; ++k) {
      sd[k] = std::sqrt(sd[k] / static_cast<double>(n - 1));
      // Constant up to rounding: no shape to test.
      spread[k] = sd[k] > 1e-9 * (1.0 + std::fabs(mean[k]));
    }
    bool any_bimodal = false, any_strong = false, any_not_gaussian = false;
    for (int k = 0; k < 6; ++k) {
      if (!spread[k]) continue;
      ++c.with_spread[k];
      std::vector<double> v;
      double m3 = 0, m4 = 0;
      for (const Response& x : t) {
        v.push_back(x[k]);
        const double z = (x[k] - mean[k]) / sd[k];
        m3 += z * z * z / static_cast<double>(n);
        m4 += z * z * z * z / static_cast<double>(n);
      }
      const double d = ks_gaussian(v, mean[k], sd[k]);
      ks[k].push_back(d);
      if (d > 0.886 / std::sqrt(static_cast<double>(n))) {
        ++c.not_gaussian[k];
        any_not_gaussian = true;
      }
      const double nn = static_cast<double>(n);
      const double bc = (m3 * m3 + 1.0) / ((m4 - 3.0) + 3.0 * (nn - 1) * (nn - 1) / ((nn - 2) * (nn - 3)));
      if (bc > 5.0 / 9.0) {
        ++c.bimodal[k];
        any_bimodal = true;
      }
    }
    for (int i = 0; i < 6; ++i)
      for (int j = i + 1; j < 6; ++j) {
        if (!spread[i] || !spread[j]) continue;
        double cov = 0;
        for (const Response& x : t) cov += (x[i] - mean[i]) * (x[j] - mean[j]);
        const double rr = cov / static_cast<double>(n - 1) / (sd[i] * sd[j]);
        c.mean_r[i][j] += rr;
        ++pair_cells[i][j];
        if (std::fabs(rr) > 0.5) {
          ++c.strong[i][j];
          any_strong = true;
        }
      }
    c.cells_multimodal += any_bimodal;
    c.cells_with_strong += any_strong;
    c.cells_not_gaussian += any_not_gaussian;
  }
  for (int k = 0; k < 6; ++k) {
    std::vector<double>& v = ks[k];
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    c.median_ks[k] = v[v.size() / 2];
  }
  for (int i = 0; i < 6; ++i)
    for (int j = i + 1; j < 6; ++j)
      if (pair_cells[i][j] > 0) c.mean_r[i][j] /= pair_cells[i][j];
  return c;
}

std::string cell_report_text(const GatherResult& r, const CellReport& c)
{
  std::ostringstream s;
  const int trials = r.cell_outcomes.empty() ? 0 : static_cast<int>(r.cell_outcomes.back().size());
  s << "# Cell report: " << r.options.name << "\n\n"
    << c.cells << " cells, " << trials << " trial outcomes in a cell with spin (more where phi is pooled).\n\n"
    << "- cells with a component that is not Gaussian (KS above Lilliefors' 5% value 0.886 / sqrt(n)): "
    << c.cells_not_gaussian << "\n"
    << "- cells with a pair of components correlated beyond |r| = 0.5: " << c.cells_with_strong << "\n"
    << "- cells with a likely bimodal component (bimodality coefficient above 5/9): " << c.cells_multimodal
    << "\n\n"
    << "| component | cells with spread | not Gaussian | median KS | bimodal |\n|---|---|---|---|---|\n";
  for (int k = 0; k < 6; ++k)
    s << "| " << kComponents[k] << " | " << c.with_spread[k] << " | " << c.not_gaussian[k] << " | "
      << fmt("%.3f", c.median_ks[k]) << " | " << c.bimodal[k] << " |\n";
  s << "\nPairs with |r| > 0.5 in more than a tenth of the cells (mean r over the cells):\n\n"
    << "| pair | cells with abs(r) > 0.5 | mean r |\n|---|---|---|\n";
  for (int i = 0; i < 6; ++i)
    for (int j = i + 1; j < 6; ++j)
      if (c.strong[i][j] * 10 > c.cells)
        s << "| " << kComponents[i] << ", " << kComponents[j] << " | " << c.strong[i][j] << " | "
          << fmt("%.2f", c.mean_r[i][j]) << " |\n";
  return s.str();
}

std::string cell_report_json(const CellReport& c)
{
  nlohmann::ordered_json j;
  j["cells"] = c.cells;
  j["cells_not_gaussian"] = c.cells_not_gaussian;
  j["cells_with_strong_correlation"] = c.cells_with_strong;
  j["cells_multimodal"] = c.cells_multimodal;
  nlohmann::ordered_json comps = nlohmann::ordered_json::array();
  for (int k = 0; k < 6; ++k)
    comps.push_back({{"name", kComponents[k]},
                     {"with_spread", c.with_spread[k]},
                     {"not_gaussian", c.not_gaussian[k]},
                     {"median_ks", c.median_ks[k]},
                     {"bimodal", c.bimodal[k]}});
  j["components"] = comps;
  nlohmann::ordered_json pairs = nlohmann::ordered_json::array();
  for (int i = 0; i < 6; ++i)
    for (int jj = i + 1; jj < 6; ++jj)
      pairs.push_back({{"pair", {kComponents[i], kComponents[jj]}},
                       {"strong_cells", c.strong[i][jj]},
                       {"mean_r", c.mean_r[i][jj]}});
  j["pairs"] = pairs;
  return j.dump(2) + "\n";
}

}  // namespace statsim::tools::ref3d
