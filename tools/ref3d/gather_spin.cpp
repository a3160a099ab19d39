// See gather_spin.hpp.
#include "ref3d/gather_spin.hpp"

#include "common/ks_distance.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/sampling.hpp"
#include "ref3d/signature_json.hpp"
#include "statsim/statistical.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace statsim::tools::ref3d {

namespace {

struct Draws {
  std::vector<double> speed;  ///< |V+| / |V-| of each draw
  std::vector<double> spin;   ///< |W+| L / |V-| of each draw
  long long clamped = 0;
};

// One draw per trial from the table `r` describes, read back as the runtime reads it.
Draws draw_spins(const GatherResult& r, const std::vector<ResponseTrial>& all)
{
  const LoadedSignature3 tables = parse_signature_json(json_text(r, "spin measure"), "the gathered tables");
  const SignatureView<3> view = tables.view();
  const double L = r.model.bounding_radius;
  Draws d;
  d.speed.resize(all.size());
  d.spin.resize(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const RigidState& c = all[i].contact;
    // The same stream for both candidates: their draws differ by the table alone.
    Pcg32 rng(r.options.seed ^ (std::uint64_t(i) * 0x9e3779b97f4a7c15ull), kSpinDrawStream);
    Vector3 v = c.velocity.cast<Scalar>(), w = c.spin.cast<Scalar>();
    const ResponseOutcome out = statistical_response<3>(view, c.orientation.cast<Scalar>(), Vector3(0, 0, 1), v, w, rng);
    d.clamped += out.energy_clamped ? 1 : 0;
    d.speed[i] = static_cast<double>(v.norm()) / c.velocity.norm();
    d.spin[i] = static_cast<double>(w.norm()) * L / c.velocity.norm();
  }
  return d;
}

}  // namespace

std::vector<ResponseTrial> gyration_values(std::vector<ResponseTrial> all)
{
  for (ResponseTrial& t : all) t.value = t.gyration;
  return all;
}

void choose_spin(GatherResult& r, const std::vector<ResponseTrial>& all)
{
  const GatherOptions& o = r.options;
  r.spin = ResponseSpin::length;
  r.spin_test = SpinTest{};
  // The spin measure follows the landing data in a table: without it, the paper's. Given
  // `energy`, the caller fits the trials it made by energy: no test.
  const bool untested = o.response_spin == SpinOption::length || o.response_spin == SpinOption::energy;
  if (untested || !o.landing || !o.body_contacts) return;
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t nt = o.cos_theta.size(), np = o.cos_phi.size(), nv = o.with_speed ? o.speeds.size() : 1;
  const std::size_t trials = static_cast<std::size_t>(o.trials);
  GatherResult g = r;
  static_cast<ResponseFit&>(g) = fit_responses(gyration_values(all), trials, nt, np, nv, o.spin_ratios);
  g.spin = ResponseSpin::gyration;
  // The trials' |V+| / |V-| and |W+| L / |V-|, from the state each body left the ground with.
  const double L = r.model.bounding_radius;
  std::vector<double> speed(all.size()), spin(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const double u = all[i].contact.velocity.norm();
    speed[i] = all[i].departure.velocity.norm() / u;
    spin[i] = all[i].departure.spin.norm() * L / u;
  }
  const Draws by_length = draw_spins(r, all), by_gyration = draw_spins(g, all);
  SpinTest t;
  t.run = true;
  t.trials = static_cast<long long>(all.size());
  t.ks_length = std::max(ks_distance(by_length.speed, speed), ks_distance(by_length.spin, spin));
  t.ks_gyration = std::max(ks_distance(by_gyration.speed, speed), ks_distance(by_gyration.spin, spin));
  t.critical = ks_critical_5(all.size(), all.size());
  t.clamp_length = static_cast<double>(by_length.clamped) / static_cast<double>(all.size());
  t.clamp_gyration = static_cast<double>(by_gyration.clamped) / static_cast<double>(all.size());
  if (o.response_spin == SpinOption::gyration || t.ks_gyration < t.ks_length - t.critical) {
    static_cast<ResponseFit&>(r) = static_cast<const ResponseFit&>(g);
    r.spin = ResponseSpin::gyration;
  }
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.spin_test = t;
}

}  // namespace statsim::tools::ref3d
