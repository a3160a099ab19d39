// The spin measure of `statsim gather`'s response table (statsim::ResponseSpin): the response
// trials reduced with the spin by length (W+ L / |V-|, the paper's) and by gyration (K W+ / |V-|,
// K the body's radii of gyration at its orientation), and, by default, the one chosen whose
// runtime draws reproduce the trials' spins.
//
// Why: a table by length draws a spin without knowing how the body is turned, so on a thin shape
// a spin that the reference made about the long axis, cheap there, may be drawn about a short
// one with up to I_max / I_min times the energy, which the energy guard then scales away along
// with the rebound. By gyration the drawn rotational energy is the reference's whatever the
// orientation, but the spin's axis is still drawn in the contact frame; on a shape whose
// impacts mostly spin it about one body axis, energy kept on the wrong axis becomes a faster
// spin. Neither is right for every shape, so the trials decide.
//
// Where gyration wins, auto takes `energy` (format 2.5): gyration, with the trials made again at
// spin ratios by energy, |K W-| L / (k |V-|), which the runtime then looks the table up at. The
// trials by length put, in one cell, spins about every body axis with the same |W-|, so on such
// a shape their energies differ by up to I_max / I_min: a rod rolling fast about its long axis
// was looked up among trials that spun about short axes with many times its energy, and
// bounced as they did. The test itself compares length and gyration on the trials by length,
// so a shape that keeps length keeps its table to the byte.
//
// K is taken at the orientation the body leaves the ground with, the one W+ belongs to (after a
// long contact the body has turned since it met the ground): half the squared length of K W+ /
// |V-| is then exactly the rotational share of the energy it leaves with.
//
// The test: at every response trial's contact (the state the body met the ground with), one
// draw of statsim::statistical_response from each candidate table, as the runtime reads it (the
// JSON at the stored precision, energy guard included), and the larger of the two-sample
// Kolmogorov-Smirnov distances between the draws' |V+| / |V-| and |W+| L / |V-| and the
// trials' (as `statsim fidelity`'s first_impact_ks takes the larger of its two). Gyration is
// taken only when its distance is below length's by more than the 5% critical value of the
// test, 1.358 sqrt(2 / n) for n trials: the paper's measure stays unless the other is
// measurably better.
#pragma once

#include "ref3d/gather_trials.hpp"

#include <cstddef>
#include <vector>

namespace statsim::tools::ref3d {

struct GatherResult;

/// What the test measured (a part of GatherResult); `run` false with --response-spin length or
/// energy, or without the landing data. With --response-spin gyration it is run and reported, not
/// obeyed.
struct SpinTest {
  bool run = false;
  long long trials = 0;      ///< draws of each candidate, one per response trial
  double ks_length = 0.0;    ///< larger KS distance of |V+| / |V-| and |W+| L / |V-|, draws by length vs trials
  double ks_gyration = 0.0;  ///< the same with the table by gyration
  double critical = 0.0;     ///< the margin gyration must win by
  double clamp_length = 0.0, clamp_gyration = 0.0;  ///< share of the draws the energy guard scaled
  double seconds = 0.0;
};

/// Sets `r.spin` to length or gyration by `r.options.response_spin` (length for `energy`, which
/// the caller takes, gather.cpp), and `r.spin_test` unless that is length or energy; when
/// gyration is taken, `r`'s response statistics become the fit of the trials' gyration values.
/// `all` holds the response trials as `fit_responses` takes them; `r` must hold everything a
/// table holds before its landing data (the draws read the table from its JSON).
void choose_spin(GatherResult& r, const std::vector<ResponseTrial>& all);

/// The trials with their gyration values (K W+ / |V-|) in place of their values by length.
std::vector<ResponseTrial> gyration_values(std::vector<ResponseTrial> all);

}  // namespace statsim::tools::ref3d
