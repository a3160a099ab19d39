// The distances of `statsim fidelity` between a method's outcomes and the reference's, single
// drops and drop piles, with their bootstrap intervals (see fidelity.cpp's header for what each
// distance is).
#include "fidelity/fidelity.hpp"
#include "fidelity/metrics.hpp"

#include <algorithm>
#include <cmath>

namespace statsim::tools::fidelity {

namespace {

std::vector<double> config_histogram(const std::vector<int>& configs, int k)
{
  std::vector<double> h(static_cast<std::size_t>(k), 0.0);
  for (int c : configs)
    if (c >= 0 && c < k) h[static_cast<std::size_t>(c)] += 1;
  return h;
}

template <class F>
std::vector<double> column(const std::vector<DropRun>& runs, F f)
{
  std::vector<double> v;
  v.reserve(runs.size());
  for (const DropRun& r : runs) v.push_back(f(r));
  return v;
}

double guard(double m)
{
  return m > 0 ? m : 1.0;
}

// Stands for "no flight" in the samples of leaving speeds and spins (both are >= 0).
constexpr double kNoFlight = -1.0;

// W1 of the times to rest of the drops that rest in each sample, over the reference's mean: a
// body that is still rocking at the time limit has no time to rest to compare (a rigid bunny on
// its curved back loses energy only at impacts and can rock on far past any limit), so those
// are left out on both sides, and their shares are reported beside. When only one sample has
// drops that rest, as far apart as can be said: 1.
double rest_time_distance(const std::vector<DropRun>& m, const std::vector<DropRun>& ref)
{
  std::vector<double> a, b;
  for (const DropRun& r : m)
    if (!r.time_limited) a.push_back(r.rest_time);
  for (const DropRun& r : ref)
    if (!r.time_limited) b.push_back(r.rest_time);
  if (a.empty() || b.empty()) return a.empty() && b.empty() ? 0.0 : 1.0;
  return w1(a, b) / guard(mean(b));
}

struct DropStats {
  double tvd, height, travel, bounce, rest_time, ks_v, ks_w;
  double ks() const { return std::max(ks_v, ks_w); }
  double summary() const { return summary_error(tvd, height, travel, bounce, ks()); }
};

DropStats drop_stats(const std::vector<DropRun>& m, const std::vector<DropRun>& ref, int configs)
{
  DropStats s{};
  std::vector<int> cm, cr;
  for (const DropRun& r : m) cm.push_back(r.config);
  for (const DropRun& r : ref) cr.push_back(r.config);
  s.tvd = tvd(config_histogram(cm, configs), config_histogram(cr, configs));

  // zref(c): the reference's mean rest height per configuration.
  std::vector<double> zsum(static_cast<std::size_t>(configs), 0.0), zn(static_cast<std::size_t>(configs), 0.0);
  double all = 0;
  for (const DropRun& r : ref) {
    zsum[static_cast<std::size_t>(r.config)] += r.rest_height;
    zn[static_cast<std::size_t>(r.config)] += 1;
    all += r.rest_height;
  }
  const double overall = ref.empty() ? 0.0 : all / static_cast<double>(ref.size());
  double err = 0;
  for (const DropRun& r : m) {
    const std::size_t c = static_cast<std::size_t>(r.config);
    const double zref = zn[c] > 0 ? zsum[c] / zn[c] : overall;
    err += std::fabs(r.rest_height - zref);
  }
  // Rest heights are stored in units of R (run_single), so this is the error as a fraction of R.
  s.height = m.empty() ? 0.0 : err / static_cast<double>(m.size());

  auto travel = [](const DropRun& r) { return r.travel; };
  auto bounces = [](const DropRun& r) { return r.bounces; };
  s.travel = w1(column(m, travel), column(ref, travel)) / guard(mean(column(ref, travel)));
  s.bounce = w1(column(m, bounces), column(ref, bounces)) / guard(mean(column(ref, bounces)));
  s.rest_time = rest_time_distance(m, ref);
  // A drop without a flight after its first contact is an atom below every speed: the KS
  // statistic then also sees a difference in how often the body flies again, which leaving
  // those drops out would hide.
  auto speed = [](const DropRun& r) { return r.flight ? r.flight_speed : kNoFlight; };
  auto spin = [](const DropRun& r) { return r.flight ? r.flight_spin : kNoFlight; };
  s.ks_v = ks(column(m, speed), column(ref, speed));
  s.ks_w = ks(column(m, spin), column(ref, spin));
  return s;
}

struct PileStats {
  double radial, height, tvd;
};

PileStats pile_stats(const std::vector<PileRun>& m, const std::vector<PileRun>& ref, int configs)
{
  std::vector<double> mr, rr, mh, rh;
  std::vector<int> mc, rc;
  for (const PileRun& p : m) {
    mr.insert(mr.end(), p.radius.begin(), p.radius.end());
    mh.insert(mh.end(), p.height.begin(), p.height.end());
    mc.insert(mc.end(), p.config.begin(), p.config.end());
  }
  for (const PileRun& p : ref) {
    rr.insert(rr.end(), p.radius.begin(), p.radius.end());
    rh.insert(rh.end(), p.height.begin(), p.height.end());
    rc.insert(rc.end(), p.config.begin(), p.config.end());
  }
  return {w1(mr, rr) / guard(mean(rr)), w1(mh, rh) / guard(mean(rh)),
          tvd(config_histogram(mc, configs), config_histogram(rc, configs))};
}

}  // namespace

Distances compare(const std::vector<DropRun>& method, const std::vector<DropRun>& reference,
                  const std::vector<PileRun>& method_piles, const std::vector<PileRun>& reference_piles, int configs,
                  int resamples)
{
  Distances d;
  const DropStats full = drop_stats(method, reference, configs);
  // One resampling per statistic with the same seed: every statistic sees the same resamples.
  const auto drops = [&](const std::vector<DropRun>& a, const std::vector<DropRun>& b) {
    return drop_stats(a, b, configs);
  };
  auto ci = [&](auto get) { return resampled(method, reference, drops, get, resamples); };
  d.rest_tvd = {full.tvd, ci([](const DropStats& s) { return s.tvd; })};
  d.rest_height_err = {full.height, ci([](const DropStats& s) { return s.height; })};
  d.travel_w1 = {full.travel, ci([](const DropStats& s) { return s.travel; })};
  d.bounce_w1 = {full.bounce, ci([](const DropStats& s) { return s.bounce; })};
  d.rest_time_w1 = {full.rest_time, ci([](const DropStats& s) { return s.rest_time; })};
  d.first_impact_ks_v = {full.ks_v, ci([](const DropStats& s) { return s.ks_v; })};
  d.first_impact_ks_w = {full.ks_w, ci([](const DropStats& s) { return s.ks_w; })};
  d.first_impact_ks = {full.ks(), ci([](const DropStats& s) { return s.ks(); })};
  d.summary_error = {full.summary(), ci([](const DropStats& s) { return s.summary(); })};
  if (!method_piles.empty() && !reference_piles.empty()) {
    d.piles = true;
    const PileStats p = pile_stats(method_piles, reference_piles, configs);
    const auto piles = [&](const std::vector<PileRun>& a, const std::vector<PileRun>& b) {
      return pile_stats(a, b, configs);
    };
    auto pci = [&](auto get) { return resampled(method_piles, reference_piles, piles, get, resamples); };
    d.pile_radial_w1 = {p.radial, pci([](const PileStats& s) { return s.radial; })};
    d.pile_height_w1 = {p.height, pci([](const PileStats& s) { return s.height; })};
    d.pile_rest_tvd = {p.tvd, pci([](const PileStats& s) { return s.tvd; })};
  }
  return d;
}

}  // namespace statsim::tools::fidelity
