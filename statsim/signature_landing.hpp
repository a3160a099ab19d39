#pragma once
/// @file
/// The landing data of a signature (table format 2.2, optional): how often a body that strikes
/// the ground under gravity stays on it instead of flying off, as a correction of how often the
/// response table's own draws do. The view the runtime reads (`LandingView`) and the storage generated
/// tables hold (`LandingData`). Included by signature.hpp.
///
/// Why a table of its own. The response tables are gathered without gravity (paper 3.2.2): an
/// impact lasts until the body leaves the ground for good, over as many strikes of its corners as
/// that takes. Under gravity a body that turns slowly from one corner onto the next loses its
/// small upward speed before it leaves, and stays: a rod or a wedge landing at a slant pivots
/// down onto its side. The gravity-free outcome of such an impact still carries that upward
/// speed, so the responses alone let far fewer bodies stay than the reference does.
///
/// What is stored. `statsim gather` runs impacts with gravity from the same first contacts as
/// the response trials and counts as staying those after which the centre never rises by
/// `hop` L (L the signature's length) before the body is at rest or a second has passed. On a
/// grid of (cos theta, spin ratio, Froude number F = |V-|^2 / (g L)), each cell holds one
/// probability p in [-1, 1], from s, the trials' share of stays, and q, the probability that a
/// response drawn from the tables for the trial's contact rises less than `hop` L (measured with
/// the runtime's own draws, averaged over the cell's trials):
///  - s >= q: the responses stay too rarely. p = (s - q) / (1 - q) is the probability of an extra
///    stay: a body that stays keeps the drawn tangential velocity and leaves with no normal
///    velocity and no spin (the drawn spin is that of the gravity-free flight the stay replaces;
///    tools/fidelity/README.md measures both); with the draws that stay by themselves, s stay.
///  - s < q (the Gaussian draws of a cell whose trials either rebound or stay put mass between
///    the two): -p = (q - s) / (q (1 - q)), at most 1, is the probability that a response that
///    would stay is drawn again, once: q (1 - (-p) (1 - q)) = s stay.
/// At F = 0 every impact stays, in the trials as in the draws (s = q = 1), so the gathering's
/// first Froude sample is 0 with p = 0, without trials: slow impacts keep their draws' outcome
/// rather than the p of the first measured speed. The Froude number makes the table hold for a
/// shape of another size and for another gravity.

#include "statsim/signature_contact.hpp"

#include <array>
#include <cstdint>

namespace statsim {

/// Axes of a landing table, in order.
constexpr std::uint32_t landing_axes = 3;

/// The landing data a world reads (see the file comment); absent (`present()` false) in tables
/// without it, which then behave exactly as before.
struct LandingView {
  /// cos theta (1 = head-on), spin ratio |w| L / |v|, Froude number |v|^2 / (g L): each strictly
  /// increasing.
  std::array<AxisView, landing_axes> axes{};
  /// Landing probability per cell, in [-1, 1] (see the file comment), cells in row-major order of
  /// the axes (the first axis varies slowest): the product of the axes' sizes.
  Span<const Scalar> probability;
  /// Rise (over L) below which an impact counted as a stay when the table was gathered.
  Scalar hop = 0;
  bool present() const { return probability.size > 0; }
  /// Cells the axes describe.
  std::uint32_t cells() const
  {
    std::uint32_t n = 1;
    for (const AxisView& a : axes) n *= a.size;
    return n;
  }
};

/// Landing data of a generated signature; sizes are template arguments.
///   NT: cos theta samples, NS: spin ratio samples, NF: Froude number samples.
template <std::uint32_t NT, std::uint32_t NS, std::uint32_t NF>
struct LandingData {
  static_assert(NT >= 1 && NS >= 1 && NF >= 1, "every axis needs a sample");
  Scalar hop;
  std::array<Scalar, NT> cos_theta;
  std::array<Scalar, NS> spin_ratio;
  std::array<Scalar, NF> froude;
  std::array<Scalar, NT * NS * NF> probability;
};

/// The `landing` of a table without landing data (formats 2.0 and 2.1).
struct NoLandingData {};

}  // namespace statsim
