// See gather_options.hpp.
#include "ref3d/gather_options.hpp"

#include "common/format.hpp"

#include <cmath>
#include <stdexcept>

namespace statsim::tools::ref3d {

namespace {

bool strictly_increasing(const std::vector<double>& v)
{
  for (std::size_t i = 1; i < v.size(); ++i)
    if (!(v[i] > v[i - 1])) return false;
  return true;
}

}  // namespace

// ---- axes ------------------------------------------------------------------------------------

std::vector<double> default_height_ratios()
{
  return {0, 0.25, 0.5, 1, 1.5, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64};
}
std::vector<double> default_cos_theta()
{
  return {0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1};
}
std::vector<double> default_cos_phi()
{
  std::vector<double> v;
  for (int i = 0; i < 10; ++i) v.push_back(i == 9 ? 1.0 : -1.0 + 2.0 * i / 9.0);
  return v;
}
std::vector<double> default_spin_ratios()
{
  return {0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.65, 0.8, 1, 1.25, 1.5, 2, 3, 4, 6, 8};
}
std::vector<double> default_paper_speeds()
{
  // 26 speeds, geometric from 0.25 to 12 m/s, rounded to 3 significant digits.
  std::vector<double> v;
  for (int i = 0; i < 26; ++i) {
    const double x = 0.25 * std::pow(12.0 / 0.25, i / 25.0);
    v.push_back(std::strtod(fmt("%.3g", x).c_str(), nullptr));
  }
  return v;
}
std::vector<double> default_coarse_speeds()
{
  return {0.5, 1, 2, 4, 8};
}

std::vector<double> default_landing_froude()
{
  return {0, 1, 4, 16};
}

void validate_gather_options(const GatherOptions& o)
{
  auto fail = [](const std::string& m) { throw std::runtime_error(m); };
  if (!o.name.empty() && !cpp_identifier(o.name)) fail("--name '" + o.name + "' is not a C++ identifier");
  if (o.trials < 2) fail("--trials must be at least 2");
  if (o.height_trials < 2) fail("--height-trials must be at least 2");
  if (o.rest_drops < 1) fail("--rest-drops must be at least 1");
  if (!(o.speed > 0) || !std::isfinite(o.speed)) fail("--speed must be positive");
  if (!(o.density > 0) || !std::isfinite(o.density)) fail("--density must be positive");
  const ReferenceSettings& r = o.reference;
  if (!(r.dt > 0) || r.dt > 0.1) fail("--dt must be in (0, 0.1] s");
  if (!(r.restitution >= 0 && r.restitution <= 1)) fail("--restitution must be in [0, 1]");
  if (!(r.friction >= 0) || !std::isfinite(r.friction)) fail("--friction must be >= 0");
  if (!(r.restitution_threshold >= 0) || !std::isfinite(r.restitution_threshold))
    fail("--restitution-threshold must be >= 0");
  if (!(r.margin > 0) || !std::isfinite(r.margin)) fail("--margin must be positive");
  if (r.solver_iterations < 1) fail("--solver-iterations must be at least 1");
  if (!(o.rolling_resistance >= 0)) fail("--rolling-resistance must be >= 0");
  if (!(o.rest_tolerance_deg > 0 && o.rest_tolerance_deg < 90)) fail("--rest-tolerance must be in (0, 90) degrees");
  if (!(o.rest_min_frequency >= 0 && o.rest_min_frequency < 1)) fail("--rest-min-frequency must be in [0, 1)");
  if (o.response_model == ResponseModel::empirical &&
      (o.empirical_outcomes < 1 || o.empirical_outcomes > o.trials ||
       o.empirical_outcomes > static_cast<int>(max_empirical_outcomes)))
    fail("--empirical-outcomes must be in [1, min(--trials, " + std::to_string(max_empirical_outcomes) + ")]");
  if (!(o.rest_max_dropped >= 0 && o.rest_max_dropped <= 1)) fail("--rest-max-dropped must be in [0, 1]");
  if (!(o.max_impact_time > 0) || !(o.max_drop_time > 0) || !(o.still_time > 0) || !(o.still_speed > 0))
    fail("time limits and the stillness threshold must be positive");
  auto axis = [&](const std::vector<double>& v, const char* what, double lo, double hi) {
    if (v.empty()) fail(std::string(what) + ": needs at least one sample");
    if (!strictly_increasing(v)) fail(std::string(what) + ": samples must be strictly increasing");
    if (!(v.front() >= lo) || !(v.back() <= hi)) fail(std::string(what) + ": samples must lie in [" + num(lo) + ", " + num(hi) + "]");
  };
  if (!o.box_size.empty()) {
    if (o.box_size.size() != 3) fail("--box-size needs three values X,Y,Z");
    for (double x : o.box_size)
      if (!(x > 0) || !std::isfinite(x)) fail("--box-size: sizes must be positive");
  }
  axis(o.height_ratios, "height ratios", 0, 1e6);
  axis(o.cos_theta, "cos theta axis", 1e-3, 1);
  axis(o.cos_phi, "cos phi axis", -1, 1);
  axis(o.spin_ratios, "spin ratio axis", 0, 1e6);
  if (o.with_speed && !o.speeds.empty()) axis(o.speeds, "speed axis", 1e-3, 1e3);
  if (o.response_flight && !(o.landing && o.body_contacts))
    fail("--response-flight needs the landing data, which draws again or keeps the stays its trials leave out "
         "(drop --no-landing and --no-body-contacts)");
  if (o.landing) {
    if (o.landing_trials < 1) fail("--landing-trials must be at least 1");
    axis(o.landing_froude, "--landing-froude axis", 0, 1e6);
    if (!(o.landing_hop >= 0 && o.landing_hop <= 1)) fail("--landing-hop must be in [0, 1]");
    if (!(o.landing_time > 0 && o.landing_time <= 60)) fail("--landing-time must be in (0, 60] s");
  }
  if ((o.response_spin == SpinOption::gyration || o.response_spin == SpinOption::energy) &&
      !(o.landing && o.body_contacts))
    fail(std::string("--response-spin ") + (o.response_spin == SpinOption::energy ? "energy" : "gyration") +
         " needs the landing data, which a table holds before it (drop --no-landing and --no-body-contacts)");
  if (o.settle) {
    if (o.settle_quantiles < 1 || o.settle_quantiles > static_cast<int>(max_settle_quantiles))
      fail("--settle-quantiles must be in [1, " + std::to_string(max_settle_quantiles) + "]");
    if (!(o.settle_speed > 0) || !std::isfinite(o.settle_speed)) fail("--settle-speed must be positive (m/s)");
    if (!(o.quiet_speed > 0 && o.quiet_speed < o.settle_speed))
      fail("--quiet-speed must be positive and below --settle-speed (" + num(o.settle_speed) + " m/s)");
  }
  if (o.body_contacts) {
    if (o.support_size < 2 || o.support_size > static_cast<int>(max_support_size))
      fail("--support-size must be in [2, " + std::to_string(max_support_size) + "]");
    if (o.contact_faces < 0 || o.contact_faces > static_cast<int>(max_contact_faces))
      fail("--contact-faces must be in [0, " + std::to_string(max_contact_faces) + "]");
    if (o.pair_trials < 2) fail("--pair-trials must be at least 2");
    if (o.packing_piles < 0 || o.packing_bins < 0) fail("--packing-piles and --packing-bins must be >= 0");
    if (o.packing_count < 2) fail("--packing-count must be at least 2");
  }
}

ShapeModel build_model(const GatherOptions& o)
{
  if (o.box_size.empty()) return load_shape_model(o.shape, o.mesh_file, o.density, o.mesh_scale, o.mesh_units_given);
  ShapeModel m = make_box_model(Eigen::Vector3d(o.box_size[0], o.box_size[1], o.box_size[2]), o.density);
  m.source = "generated " + num(o.box_size[0]) + " x " + num(o.box_size[1]) + " x " + num(o.box_size[2]) + " m box";
  return m;
}

const char* response_model_name(ResponseModel model)
{
  switch (model) {
    case ResponseModel::independent_gaussian: return "paper";
    case ResponseModel::correlated_gaussian: return "correlated";
    case ResponseModel::empirical: return "empirical";
  }
  return "unknown";
}

ResponseModel parse_response_model(const std::string& name)
{
  for (ResponseModel m :
       {ResponseModel::independent_gaussian, ResponseModel::correlated_gaussian, ResponseModel::empirical})
    if (name == response_model_name(m)) return m;
  throw std::runtime_error("unknown response model '" + name + "' (paper, correlated or empirical)");
}

}  // namespace statsim::tools::ref3d
