#include "ref3d/sizing.hpp"

#include "common/format.hpp"
#include "common/parallel.hpp"
#include "common/pick.hpp"
#include "statsim/signature.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace statsim::tools::ref3d {

namespace {

std::vector<float> as_float(const std::vector<double>& v)
{
  std::vector<float> f;
  f.reserve(v.size());
  for (double x : v) f.push_back(static_cast<float>(x));
  return f;
}


std::size_t product(const std::vector<std::size_t>& sizes)
{
  std::size_t p = 1;
  for (std::size_t s : sizes) p *= s;
  return p;
}

std::vector<std::size_t> axis_sizes(const std::vector<std::vector<double>>& axes)
{
  std::vector<std::size_t> s;
  for (const auto& a : axes) s.push_back(a.size());
  return s;
}

// The dense cells of a candidate (its kept samples' combinations), in the candidate's row-major order.
std::vector<std::size_t> kept_cells(const std::vector<std::size_t>& dense_sizes,
                                    const std::vector<std::vector<std::size_t>>& keep)
{
  std::vector<std::size_t> cells{0};
  for (std::size_t a = 0; a < keep.size(); ++a) {
    std::vector<std::size_t> next;
    next.reserve(cells.size() * keep[a].size());
    for (std::size_t c : cells)
      for (std::size_t k : keep[a]) next.push_back(c * dense_sizes[a] + k);
    cells = std::move(next);
  }
  return cells;
}

// Per component: sigma_floor times the median spread over the dense cells (at least 1e-6, so
// that a table of exact zeros is not divided by zero).
std::vector<double> spread_floors(const DenseTable& d, double sigma_floor)
{
  const std::size_t nc = d.components, cells = d.mean.size() / nc;
  std::vector<double> floors(nc, 1e-6);
  for (std::size_t c = 0; c < nc; ++c) {
    std::vector<double> s;
    for (std::size_t i = 0; i < cells; ++i) s.push_back(d.stddev[i * nc + c]);
    if (s.empty()) continue;
    std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(s.size() / 2), s.end());
    floors[c] = std::max(1e-6, sigma_floor * s[s.size() / 2]);
  }
  return floors;
}

double height_floor(const DenseTable& d, double sigma_floor)
{
  std::vector<double> s = d.height_stddev;
  if (s.empty()) return 1e-9;
  std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(s.size() / 2), s.end());
  return std::max(1e-9, sigma_floor * s[s.size() / 2]);
}

Candidate response_error_with(const DenseTable& d, const std::vector<std::vector<std::size_t>>& keep, bool i16,
                              const std::vector<double>& floors)
{
  const std::size_t na = d.axes.size(), nc = d.components;
  STATSIM_ASSERT(na >= 1 && na <= max_response_axes && keep.size() == na && nc <= 8);
  const std::vector<std::size_t> dense_sizes = axis_sizes(d.axes);
  std::vector<std::vector<float>> cand_axes;
  for (std::size_t a = 0; a < na; ++a) cand_axes.push_back(as_float(pick(d.axes[a], keep[a])));
  const std::vector<std::size_t> cells = kept_cells(dense_sizes, keep);
  std::vector<double> mean, stddev;
  mean.reserve(cells.size() * nc);
  stddev.reserve(cells.size() * nc);
  for (std::size_t cell : cells)
    for (std::size_t c = 0; c < nc; ++c) {
      mean.push_back(d.mean[cell * nc + c]);
      stddev.push_back(d.stddev[cell * nc + c]);
    }
  const std::vector<float> mean_f = as_float(mean), std_f = as_float(stddev);
  Quantized qm, qs;
  ResponseTableView view;
  view.axis_count = static_cast<std::uint32_t>(na);
  view.components = static_cast<std::uint32_t>(nc);
  view.spread_per_cell = view.components;  // the paper's model: one standard deviation a component
  for (std::size_t a = 0; a < na; ++a)
    view.axes[a] = AxisView{cand_axes[a].data(), static_cast<std::uint32_t>(cand_axes[a].size())};
  if (i16) {
    qm = quantize(mean_f);
    qs = quantize(std_f);
    view.mean = ValuesView{Span<const std::int16_t>(qm.q), qm.scale, qm.offset};
    view.spread = ValuesView{Span<const std::int16_t>(qs.q), qs.scale, qs.offset};
  } else {
    view.mean = ValuesView(mean_f);
    view.spread = ValuesView(std_f);
  }

  Candidate out;
  out.keep = keep;
  out.i16 = i16;
  const std::size_t dense_cells = product(dense_sizes);
  std::vector<float> dense_axes_f[max_response_axes];
  for (std::size_t a = 0; a < na; ++a) dense_axes_f[a] = as_float(d.axes[a]);
  // Per axis and dense index: the sum of the squared interpolation weights of the two candidate
  // samples around it, (1 - t)^2 + t^2 (1 at a kept sample); `kept`: whether it is one.
  std::vector<double> weight2[max_response_axes];
  std::vector<char> kept[max_response_axes];
  for (std::size_t a = 0; a < na; ++a) {
    const AxisView axis{cand_axes[a].data(), static_cast<std::uint32_t>(cand_axes[a].size())};
    kept[a].assign(d.axes[a].size(), 0);
    for (std::size_t k : keep[a]) kept[a][k] = 1;
    for (std::size_t i = 0; i < d.axes[a].size(); ++i) {
      const double t = axis.size == 1 ? 0.0 : static_cast<double>(locate(axis, dense_axes_f[a][i]).t);
      weight2[a].push_back((1 - t) * (1 - t) + t * t);
    }
  }
  const bool noisy = d.cell_trials.size() == dense_cells;
  double sum = 0.0, raw_sum = 0.0;
  std::size_t index[max_response_axes] = {};
  for (std::size_t cell = 0; cell < dense_cells; ++cell) {
    std::size_t rest = cell;
    for (std::size_t a = na; a-- > 0;) {
      index[a] = rest % dense_sizes[a];
      rest /= dense_sizes[a];
    }
    Scalar x[max_response_axes] = {};
    for (std::size_t a = 0; a < na; ++a) x[a] = dense_axes_f[a][index[a]];
    Scalar m[8], s[8];
    view.lookup(x, m, s);
    bool is_kept = true;
    double w2 = 1.0;
    for (std::size_t a = 0; a < na; ++a) {
      is_kept = is_kept && kept[a][index[a]];
      w2 *= weight2[a][index[a]];
    }
    // Noise variance of (interpolated - dense) per unit sigma^2: mean 1/T, spread 1/(2 (T - 1)).
    double noise = 0.0;
    if (noisy && !is_kept) {
      const double T = d.cell_trials[cell];
      noise = (1.0 + w2) * (1.0 / T + (T > 1 ? 1.0 / (2.0 * (T - 1)) : 0.0));
    }
    for (std::size_t c = 0; c < nc; ++c) {
      const double sd = d.stddev[cell * nc + c];
      const double dm = static_cast<double>(m[c]) - d.mean[cell * nc + c];
      const double ds = static_cast<double>(s[c]) - sd;
      const double scale = std::max(sd, floors[c]);
      const double miss2 = dm * dm + ds * ds;
      const double raw = std::sqrt(miss2) / scale;
      const double e = std::sqrt(std::max(0.0, miss2 - noise * sd * sd)) / scale;
      raw_sum += raw;
      sum += e;
      out.max_error = std::max(out.max_error, e);
    }
  }
  out.error = sum / static_cast<double>(dense_cells * nc);
  out.raw_error = raw_sum / static_cast<double>(dense_cells * nc);
  return out;
}

}  // namespace

double scene_max_spin_ratio(const SceneRange& scene, double length)
{
  return scene.max_spin * length / scene.min_speed;
}

std::vector<double> cut_axis(const std::vector<double>& axis, double hi)
{
  if (axis.empty() || !(hi < axis.back())) return axis;
  std::vector<double> out;
  for (double x : axis)
    if (x < hi) out.push_back(x);
  out.push_back(hi);
  return out;
}

GatherOptions scene_dense_options(const GatherOptions& o, const SceneRange& scene, double length)
{
  auto fail = [](const std::string& m) { throw std::runtime_error(m); };
  if (!(scene.max_speed > 0) || !std::isfinite(scene.max_speed)) fail("the scene's largest speed must be positive");
  if (!(scene.min_speed > 0) || !(scene.min_speed <= scene.max_speed))
    fail("the scene's smallest speed must be positive and at most its largest");
  if (!(scene.max_spin >= 0) || !std::isfinite(scene.max_spin)) fail("the scene's largest spin must be >= 0");
  if (!(length > 0)) fail("the shape's length L must be positive");
  GatherOptions d = o;
  const double s_max = scene_max_spin_ratio(scene, length);
  // Clamped lookups beyond s_max never reach samples above it; at s_max = 0 one sample remains.
  d.spin_ratios = cut_axis(o.spin_ratios, s_max);
  d.height_ratios = cut_axis(o.height_ratios, s_max);
  if (o.with_speed) {
    const std::vector<double> speeds = o.speeds.empty() ? default_paper_speeds() : o.speeds;
    std::vector<double> v{scene.min_speed};
    for (double x : speeds)
      if (x > scene.min_speed && x < scene.max_speed) v.push_back(x);
    if (scene.max_speed > scene.min_speed) v.push_back(scene.max_speed);
    d.speeds = v;
  }
  validate_gather_options(d);
  return d;
}

DenseTable dense_table(const GatherResult& r)
{
  DenseTable d;
  d.axes = r.axes;
  d.components = 6;
  d.mean = r.response_mean;
  d.stddev = r.response_std;
  d.height_axis = r.options.height_ratios;
  d.height_mean = r.height_mean;
  d.height_stddev = r.height_std;
  d.rest_poses = r.rest.size();
  // As gather() pools them: at zero spin the trials of every cos phi.
  const std::size_t spin_axis = r.axes.size() - 1, ns = r.axes[spin_axis].size(), np = r.axes[1].size();
  const std::size_t cells = r.response_mean.size() / 6;
  for (std::size_t cell = 0; cell < cells; ++cell) {
    const double t = static_cast<double>(r.options.trials);
    d.cell_trials.push_back(r.axes[spin_axis][cell % ns] == 0.0 ? t * static_cast<double>(np) : t);
  }
  d.height_trials = static_cast<double>(r.options.height_trials);
  return d;
}

std::vector<std::size_t> spread_indices(std::size_t n, std::size_t m)
{
  if (n <= 1 || m <= 1) return {0};
  m = std::min(m, n);
  std::vector<std::size_t> v;
  for (std::size_t j = 0; j < m; ++j) {
    // round(j (n-1) / (m-1)) in integers: distinct and increasing for m <= n.
    v.push_back((2 * j * (n - 1) + (m - 1)) / (2 * (m - 1)));
  }
  return v;
}

std::vector<std::size_t> candidate_counts(std::size_t n)
{
  if (n <= 1) return {1};
  std::vector<std::size_t> v;
  for (std::size_t m = 2; m <= n; ++m) {
    if (m > 12 && m < n && !v.empty() && static_cast<double>(m) < 1.15 * static_cast<double>(v.back())) continue;
    v.push_back(m);
  }
  return v;
}

Candidate response_error(const DenseTable& d, const std::vector<std::vector<std::size_t>>& keep, bool i16,
                         double sigma_floor)
{
  return response_error_with(d, keep, i16, spread_floors(d, sigma_floor));
}

HeightCandidate height_error(const DenseTable& d, const std::vector<std::size_t>& keep, double sigma_floor)
{
  const double floor = height_floor(d, sigma_floor);
  const std::vector<float> axis = as_float(pick(d.height_axis, keep)), mean = as_float(pick(d.height_mean, keep));
  HeightTableView view;
  view.spin_ratio = AxisView{axis.data(), static_cast<std::uint32_t>(axis.size())};
  view.mean = ValuesView(mean);
  HeightCandidate out;
  out.keep = keep;
  std::vector<char> is_kept(d.height_axis.size(), 0);
  for (std::size_t k : keep) is_kept[k] = 1;
  double sum = 0.0, raw_sum = 0.0;
  for (std::size_t i = 0; i < d.height_axis.size(); ++i) {
    const float s = static_cast<float>(d.height_axis[i]);
    const double h = static_cast<double>(view.mean_at(s));
    const double sd = d.height_stddev[i];
    double noise = 0.0;
    if (d.height_trials > 0 && !is_kept[i] && axis.size() > 1) {
      const double t = static_cast<double>(locate(view.spin_ratio, s).t);
      noise = (1.0 + (1 - t) * (1 - t) + t * t) / d.height_trials;
    }
    const double miss2 = (h - d.height_mean[i]) * (h - d.height_mean[i]);
    const double scale = std::max(sd, floor);
    const double e = std::sqrt(std::max(0.0, miss2 - noise * sd * sd)) / scale;
    raw_sum += std::sqrt(miss2) / scale;
    sum += e;
    out.max_error = std::max(out.max_error, e);
  }
  const double n = static_cast<double>(std::max<std::size_t>(1, d.height_axis.size()));
  out.error = sum / n;
  out.raw_error = raw_sum / n;
  return out;
}

std::size_t signature_bytes(std::size_t height_samples, const std::vector<std::size_t>& axis_sizes,
                            std::size_t components, std::size_t rest_poses, bool i16)
{
  const std::size_t f = sizeof(Scalar);
  std::size_t bytes = 10 * f + 8 + 3 * height_samples * f;
  std::size_t cells = 1;
  for (std::size_t a = 0; a < max_response_axes; ++a) {
    const std::size_t n = a < axis_sizes.size() ? axis_sizes[a] : 1;
    bytes += n * f;
    cells *= n;
  }
  const std::size_t values = cells * components;
  bytes += i16 ? 2 * values * sizeof(std::int16_t) + 4 * f : 2 * values * f;
  return bytes + rest_poses * 5 * f;
}

SizingResult size_table(const DenseTable& d, const SizingOptions& o)
{
  SizingResult r;
  r.budget = o.budget;
  // h_coll: the fewest samples within the budget (the full axis fits itself).
  const std::size_t nh = d.height_axis.size();
  for (std::size_t m : candidate_counts(nh)) r.height_candidates.push_back(height_error(d, spread_indices(nh, m), o.sigma_floor));
  r.height_chosen = r.height_candidates.size() - 1;
  for (std::size_t i = 0; i < r.height_candidates.size(); ++i)
    if (r.height_candidates[i].error <= o.budget) {
      r.height_chosen = i;
      break;
    }
  const std::size_t nh_chosen = r.height_candidates[r.height_chosen].keep.size();

  // Responses: every combination of per-axis counts, at each precision.
  const std::size_t na = d.axes.size();
  std::vector<std::vector<std::size_t>> counts;
  for (const auto& a : d.axes) counts.push_back(candidate_counts(a.size()));
  std::vector<std::vector<std::vector<std::size_t>>> keeps;
  std::vector<std::size_t> pos(na, 0);
  for (;;) {
    std::vector<std::vector<std::size_t>> keep;
    for (std::size_t a = 0; a < na; ++a) keep.push_back(spread_indices(d.axes[a].size(), counts[a][pos[a]]));
    keeps.push_back(keep);
    std::size_t a = na;
    while (a-- > 0) {
      if (++pos[a] < counts[a].size()) break;
      pos[a] = 0;
    }
    if (a == static_cast<std::size_t>(-1)) break;
  }
  const std::vector<double> floors = spread_floors(d, o.sigma_floor);
  const std::size_t precisions = o.allow_i16 ? 2 : 1;
  r.candidates.resize(keeps.size() * precisions);
  parallel_for(
      r.candidates.size(),
      [&](std::size_t i) {
        const auto& keep = keeps[i / precisions];
        Candidate c = response_error_with(d, keep, i % precisions == 1, floors);
        std::vector<std::size_t> sizes;
        for (const auto& k : keep) sizes.push_back(k.size());
        c.bytes = signature_bytes(nh_chosen, sizes, d.components, d.rest_poses, c.i16);
        r.candidates[i] = std::move(c);
      },
      o.threads);
  // The fewest bytes within the budget, then the smaller error, then the first considered; if
  // none is within it (a budget below float rounding), the smallest error.
  bool found = false;
  for (std::size_t i = 0; i < r.candidates.size(); ++i) {
    const Candidate& c = r.candidates[i];
    if (c.error > o.budget) continue;
    const Candidate& b = r.candidates[r.chosen];
    if (!found || c.bytes < b.bytes || (c.bytes == b.bytes && c.error < b.error)) r.chosen = i;
    found = true;
  }
  if (!found)
    for (std::size_t i = 0; i < r.candidates.size(); ++i)
      if (r.candidates[i].error < r.candidates[r.chosen].error) r.chosen = i;
  r.error = std::max(r.candidates[r.chosen].error, r.height_candidates[r.height_chosen].error);
  return r;
}

GatherResult sized_result(const GatherResult& dense, const SizingResult& s, const std::vector<std::string>& notes)
{
  GatherResult r = dense;
  const Candidate& c = s.candidates[s.chosen];
  const std::vector<std::size_t>& hk = s.height_candidates[s.height_chosen].keep;
  GatherOptions& o = r.options;
  o.i16 = c.i16;
  o.height_ratios = pick(dense.options.height_ratios, hk);
  r.height_mean = pick(dense.height_mean, hk);
  r.height_std = pick(dense.height_std, hk);
  if (dense.contact.pair_mean.size() == dense.options.height_ratios.size()) {
    // The pair distance lies on the h_coll axis: the same samples.
    r.contact.pair_mean = pick(dense.contact.pair_mean, hk);
    r.contact.pair_std = pick(dense.contact.pair_std, hk);
  }
  for (std::size_t a = 0; a < r.axes.size(); ++a) r.axes[a] = pick(dense.axes[a], c.keep[a]);
  o.cos_theta = r.axes[0];
  o.cos_phi = r.axes[1];
  if (o.with_speed) o.speeds = r.axes[2];
  o.spin_ratios = r.axes.back();
  const std::vector<std::size_t> cells = kept_cells(axis_sizes(dense.axes), c.keep);
  r.response_mean.clear();
  r.response_std.clear();
  r.cell_outcomes.clear();
  for (std::size_t cell : cells) {
    if (cell < dense.cell_outcomes.size()) r.cell_outcomes.push_back(dense.cell_outcomes[cell]);
    for (std::size_t k = 0; k < 6; ++k) {
      r.response_mean.push_back(dense.response_mean[cell * 6 + k]);
      r.response_std.push_back(dense.response_std[cell * 6 + k]);
    }
  }
  r.notes = notes;
  return r;
}

std::string sizing_report(const DenseTable& d, const SizingResult& s, bool all)
{
  auto sizes = [](const Candidate& c) {
    std::string t;
    for (const auto& k : c.keep) t += (t.empty() ? "" : " x ") + std::to_string(k.size());
    return t;
  };
  std::ostringstream o;
  std::string dense;
  for (const auto& a : d.axes) dense += (dense.empty() ? "" : " x ") + std::to_string(a.size());
  o << "sizing: dense table " << dense << " cells, h_coll " << d.height_axis.size() << " samples; "
    << s.candidates.size() << " response candidates, " << s.height_candidates.size() << " h_coll candidates; budget "
    << fmt("%.4g", s.budget) << "\n";
  o << "h_coll candidates (samples: mean error, largest, with noise):";
  for (const HeightCandidate& h : s.height_candidates)
    o << " " << h.keep.size() << ": " << fmt("%.4f", h.error) << ", " << fmt("%.3f", h.max_error) << ", "
      << fmt("%.4f", h.raw_error) << ";";
  o << "\n";
  std::vector<std::size_t> order(s.candidates.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (s.candidates[a].bytes != s.candidates[b].bytes) return s.candidates[a].bytes < s.candidates[b].bytes;
    return s.candidates[a].error < s.candidates[b].error;
  });
  o << (all ? "response candidates by bytes:\n" : "response candidates by bytes (each better than every smaller one):\n");
  o << "  bytes      axes              precision  error    largest  (with noise)\n";
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i : order) {
    const Candidate& c = s.candidates[i];
    if (!all && !(c.error < best)) continue;
    best = std::min(best, c.error);
    char line[160];
    std::snprintf(line, sizeof line, "  %-9zu  %-16s  %-9s  %.4f   %-7.3f  %.4f%s\n", c.bytes, sizes(c).c_str(),
                  c.i16 ? "i16" : "f32", c.error, c.max_error, c.raw_error,
                  i == s.chosen ? "   <- chosen" : (c.error <= s.budget ? "" : "   (over budget)"));
    o << line;
  }
  const Candidate& c = s.candidates[s.chosen];
  const HeightCandidate& h = s.height_candidates[s.height_chosen];
  o << "chosen: response " << sizes(c) << " " << (c.i16 ? "i16" : "f32") << " (error " << fmt("%.4f", c.error)
    << "), h_coll " << h.keep.size() << " samples (error " << fmt("%.4f", h.error) << "): " << c.bytes
    << " bytes, error " << fmt("%.4f", s.error) << (s.error <= s.budget ? " within" : " over") << " the budget "
    << num(s.budget) << "\n";
  return o.str();
}

}  // namespace statsim::tools::ref3d
