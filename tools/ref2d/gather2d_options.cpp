// See gather2d_options.hpp.
#include "ref2d/gather2d_options.hpp"

#include "common/format.hpp"
#include "statsim/signature.hpp"

#include <cmath>
#include <stdexcept>

namespace statsim::tools {

std::vector<double> default_height_ratios()
{
  // Below s ~ 1 the body turns by less than ~0.3 rad while crossing its height band (bounding
  // radius to inradius), so the heights barely change; beyond, the mean climbs slowly toward L.
  return {0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 13.0, 17.0, 23.0, 32.0};
}
std::vector<double> default_cos_thetas()
{
  return {0.15, 0.3, 0.5, 0.7, 0.85, 0.95, 1.0};
}
std::vector<double> default_signed_spins()
{
  return {-6.0, -3.0, -1.5, -0.5, 0.0, 0.5, 1.5, 3.0, 6.0};
}
std::vector<double> default_speeds()
{
  return {0.5, 1.5, 3.0, 5.0, 9.0};
}

Shape2 gather2d_shape(const Gather2dOptions& o)
{
  if (o.shape == "square") {
    return square_shape();
  }
  if (o.shape == "lshape") {
    return lshape_shape();
  }
  if (o.shape == "polygon") {
    const std::vector<Point2> v = parse_polygon(o.polygon);
    return make_shape(v, "polygon", "polygon " + format_polygon(v) + " (as given; centred on its centroid)");
  }
  throw std::invalid_argument("unknown shape '" + o.shape + "' (square, lshape or polygon)");
}

void validate_gather2d_options(const Gather2dOptions& o)
{
  const auto bad = [](const std::string& m) { throw std::invalid_argument(m); };
  if (!cpp_identifier(o.name)) {
    bad("the table name '" + o.name + "' is not a C++ identifier (use --name)");
  }
  if (!(o.restitution >= 0.0 && o.restitution <= 1.0)) {
    bad("--restitution must be in [0, 1]");
  }
  if (!(o.friction >= 0.0 && std::isfinite(o.friction))) {
    bad("--friction must be >= 0");
  }
  if (o.height_trials < 2 || o.trials < 2) {
    bad("need at least 2 trials per table entry (for a standard deviation)");
  }
  if (o.rest_drops < 20) {
    bad("--rest-drops must be at least 20");
  }
  if (!(o.min_frequency >= 0.0 && o.min_frequency < 1.0)) {
    bad("--rest-min-frequency must be in [0, 1)");
  }
  if (!(o.max_dropped >= 0.0 && o.max_dropped <= 1.0)) {
    bad("--rest-max-dropped must be in [0, 1]");
  }
  if (o.body_contacts) {
    if (o.support_size < 2 || o.support_size > static_cast<int>(statsim::max_support_size)) {
      bad("--support-size must be in [2, " + std::to_string(statsim::max_support_size) + "]");
    }
    if (o.contact_faces < 0 || o.contact_faces > static_cast<int>(statsim::max_contact_faces)) {
      bad("--contact-faces must be in [0, " + std::to_string(statsim::max_contact_faces) + "]");
    }
    if (o.pair_trials < 2) {
      bad("--pair-trials must be at least 2");
    }
    if (o.packing_piles < 0 || o.packing_count < 2 || o.packing_steps < 1) {
      bad("--packing-piles must be >= 0, --packing-count >= 2 and --packing-steps >= 1");
    }
  }
  const auto increasing = [&](const std::vector<double>& a, const char* what, double lo, double hi) {
    if (a.empty()) {
      bad(std::string(what) + ": need at least one value");
    }
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (!std::isfinite(a[i]) || a[i] < lo || a[i] > hi || (i > 0 && !(a[i] > a[i - 1]))) {
        bad(std::string(what) + ": values must be strictly increasing within [" + num(lo) + ", " + num(hi) + "]");
      }
    }
  };
  increasing(o.height_ratios, "height spin ratios", 0.0, 1e3);
  increasing(o.cos_thetas, "cos(theta) axis", 0.05, 1.0);
  increasing(o.signed_spins, "signed spin axis", -1e3, 1e3);
  increasing(o.speeds, "speed axis", 0.05, 100.0);
  if (!(o.height_speed > 0.0) || !(o.response_dt > 0.0) || !(o.rest_dt > 0.0) || !(o.response_time_limit > 0.0) ||
      !(o.rest_time_limit > 0.0)) {
    bad("speeds, time steps and time limits must be positive");
  }
  if (o.speeds.back() * o.response_dt >= 1.0) {
    bad("the largest speed moves too far per Box2D step (b2_maxTranslation is 2 m)");
  }
  (void)gather2d_shape(o);  // a bad polygon throws here
}

}  // namespace statsim::tools
