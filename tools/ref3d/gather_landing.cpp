// See gather_landing.hpp.
#include "ref3d/gather_landing.hpp"

#include "common/parallel.hpp"
#include "common/pi.hpp"
#include "common/progress.hpp"
#include "ref3d/gather_trials.hpp"
#include "ref3d/sampling.hpp"
#include "statsim/statistical.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace statsim::tools::ref3d {

namespace {

/// Runtime draws per trial: the draws' share is averaged over a cell's trials as well.
constexpr int kDraws = 32;

struct LandingTrial {
  bool stayed = false;
  double draw_stays = 0;  ///< share of the runtime's draws at the same contact that stay
};

LandingTrial landing_trial(const Reference& ref, const GatherOptions& o, const SignatureView<3>& tables,
                           double cos_theta, double spin_ratio, double froude, std::uint64_t index)
{
  const ShapeModel& m = ref.model();
  TrialRng rng(o.seed, kLandingStream, index);
  const double L = m.bounding_radius, g = o.reference.gravity;
  const double speed = std::sqrt(froude * g * L);
  const double ct = cos_theta, st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
  const Eigen::Vector3d vhat(st, 0.0, -ct);
  RigidState s0;
  s0.orientation = rng.rotation();
  s0.velocity = speed * vhat;
  // At the ratio the runtime looks the landing data up at, by the table's spin measure.
  s0.spin = trial_spin(m, s0.orientation, rng.direction(), spin_ratio, speed, tables.spin == ResponseSpin::energy);
  s0.position = Eigen::Vector3d(0, 0, L * (1 + 1e-9));
  const FreeFlight flight(m.unit_inertia);
  const FirstContact fc = first_contact(m.hull, L, flight, s0, 0.0, std::numeric_limits<double>::infinity(),
                                        1e-12 * L, 100000000);
  RigidState start = fc.state;
  start.position.z() -= 1e-6 * L;  // a hair into the ground, as the response trials start

  const double hop = o.landing_hop * L;
  LandingTrial out;
  out.stayed = !first_flight(ref, o, start, hop).found;

  // The runtime's draws at this contact: the sampled response's rise v_z^2 / (2 g) below `hop`.
  const Vector3 n(0, 0, 1);
  const Quaternion q = start.orientation.cast<Scalar>();
  int stays = 0;
  for (int k = 0; k < kDraws; ++k) {
    Pcg32 draw(o.seed ^ (index * 0x9e3779b97f4a7c15ull), kLandingDrawStream * 1000003u + std::uint64_t(k));
    Vector3 v = start.velocity.cast<Scalar>();
    Vector3 w = start.spin.cast<Scalar>();
    statistical_response<3>(tables, q, n, v, w, draw);
    const double vz = static_cast<double>(v.z());
    if (vz * vz / (2 * g) < hop) ++stays;
  }
  out.draw_stays = static_cast<double>(stays) / kDraws;
  return out;
}

}  // namespace

LandingFit gather_landing(const GatherOptions& o, ReferencePool& pool, const SignatureView<3>& tables)
{
  const auto t0 = std::chrono::steady_clock::now();
  LandingFit f;
  f.hop = o.landing_hop;
  f.cos_theta = o.cos_theta;
  f.spin_ratio = o.spin_ratios;
  f.froude = o.landing_froude;
  const std::size_t nt = f.cos_theta.size(), ns = f.spin_ratio.size(), nf = f.froude.size();
  const std::size_t cells = nt * ns * nf, trials = static_cast<std::size_t>(o.landing_trials);
  std::vector<LandingTrial> all(cells * trials);
  // At F = 0 (no speed) every impact stays, in the trials as in the draws (a rise of (e |V-|)^2 /
  // (2 g) against hop L): s = q = 1 and p = 0, without trials. The table's edge at F = 0 then
  // leaves slow impacts as their draws are, where clamping would give them the first sample's p.
  const auto at_rest = [&](std::size_t cell) { return !(f.froude[cell % nf] > 0); };
  Progress progress("landing", cells * trials, o.progress);
  parallel_for(
      cells,
      [&](std::size_t cell) {
        const std::size_t i_f = cell % nf, i_s = (cell / nf) % ns, i_t = cell / (nf * ns);
        if (at_rest(cell)) {
          for (std::size_t t = 0; t < trials; ++t) all[cell * trials + t] = LandingTrial{true, 1.0};
          progress.add(trials);
          return;
        }
        pool.with([&](const Reference& ref) {
          for (std::size_t t = 0; t < trials; ++t)
            all[cell * trials + t] = landing_trial(ref, o, tables, f.cos_theta[i_t], f.spin_ratio[i_s], f.froude[i_f],
                                                   cell * trials + t);
          return 0;
        });
        progress.add(trials);
      },
      o.threads);
  progress.finish();
  for (std::size_t c = 0; c < cells; ++c) {
    double s = 0, q = 0;
    for (std::size_t t = 0; t < trials; ++t) {
      s += all[c * trials + t].stayed ? 1.0 : 0.0;
      q += all[c * trials + t].draw_stays;
    }
    s /= static_cast<double>(trials);
    q /= static_cast<double>(trials);
    f.stays.push_back(s);
    f.draw_stays.push_back(q);
    // statsim/signature_landing.hpp: extra stays, or redraws of stays.
    double p = 0;
    if (s >= q) p = q < 1 ? (s - q) / (1 - q) : 0.0;
    else p = q < 1 ? -std::min(1.0, (q - s) / (q * (1 - q))) : -1.0;
    f.probability.push_back(p);
  }
  for (std::size_t c = 0; c < cells; ++c)
    if (!at_rest(c)) f.trials += static_cast<long long>(trials);
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return f;
}

}  // namespace statsim::tools::ref3d
