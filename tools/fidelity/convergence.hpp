// `statsim fidelity --convergence step|iterations`: is the piles' reference converged? A reference
// is a measuring instrument; before a method is measured against it, refining it (the step
// halved, or the solver's iterations doubled) must move no figure by more than its noise floor.
// The pile scenes (heap, bin, column, wall) and the 50-body drop piles are run with the reference
// alone at `refinements` + 1 levels, every seed at every level, and each figure's change from one
// level to the next is set beside its noise floor:
//
//   floor = 1.645 sqrt(s_k^2 / n + s_(k+1)^2 / n)
//
// s_k the standard deviation of the figure over the n seeds at level k: the half-width of the 90%
// interval of the difference of two means of n independent runs, the distance two reference
// samples of n seeds lie apart by chance (what the noise floor of `statsim fidelity`, sample B
// against sample A, measures once). A figure that does not vary between seeds (a stack placed
// the same way for every seed) has no such floor; its floor is then its resolution, a tenth of
// the tolerance its goal allows (convergence_resolution()). The scene's reference setting is the
// coarsest level from which no finer level moves any figure by more than its floor: the halving
// alone, and every further refinement, since steps that each stay within the floor can still
// drift by more than it in sum.
#pragma once

#include "fidelity/fidelity.hpp"

#include <string>
#include <vector>

namespace statsim::tools::fidelity {

/// One level of refinement: the reference's step and iterations and every seed's figures.
struct ConvergenceLevel {
  double dt = 0;                                ///< s
  int iterations = 0;                           ///< solver iterations per step
  std::vector<std::vector<double>> values;      ///< per seed, per figure
  int time_limited = 0;                         ///< runs stopped by the time limit before all rested
  int all_asleep = 0;                           ///< runs with every body asleep at the end
  double cpu_seconds = 0;                       ///< thread CPU time of all its runs
};

/// A figure's change from one level to a finer one and its noise floor.
struct ConvergenceChange {
  double change = 0;  ///< mean at the finer level minus mean at the coarser, in the figure's unit
  double floor = 0;   ///< 1.645 standard errors of that difference, at least the resolution (see the file comment)
};

struct ConvergenceScene {
  std::string kind;                    ///< heap, bin, column, wall or piles (the drop piles)
  std::string description;             ///< the scene's set-up in one line
  std::vector<SceneMetric> metrics;
  std::vector<ConvergenceLevel> levels;
  /// changes[k][m]: figure m from level k to level k + 1.
  std::vector<std::vector<ConvergenceChange>> changes;
  /// to_finest[k][m]: figure m from level k to the finest level.
  std::vector<std::vector<ConvergenceChange>> to_finest;
  /// The coarsest level from which no finer level moves a figure past its floor; -1: none.
  int converged = -1;
};

struct ConvergenceResult {
  FidelityOptions options;
  std::string shape;
  std::vector<ConvergenceScene> scenes;
  std::vector<std::string> settings;   ///< the reference's Bullet settings, one per line
  std::string command;
  double seconds = 0;                  ///< wall time of the whole run
};

/// The mean of figure `m` over a level's seeds.
double level_mean(const ConvergenceLevel& level, std::size_t m);
/// The least change of a figure that counts, in its unit (relative figures: a share of the mean):
/// a tenth of its goal's tolerance (angle of repose 0.3 deg, heights 1%, fill and packing 0.5%,
/// held 0.002, overlap 0.1 mm, the piles' means 1%, the share in rest poses 0.01).
double convergence_resolution(const SceneMetric& metric);
/// Fills `scene.changes`, `scene.to_finest` and `scene.converged` from its levels.
void compare_levels(ConvergenceScene& scene);
/// The figures of the drop piles, per run: mean distance from the pile's centroid (m), mean
/// centre height (m), share of bodies in one of the table's rest poses.
std::vector<SceneMetric> pile_convergence_metrics();

/// Runs every scene of `options.scenes` (and the drop piles when `options.piles` and
/// `options.drops`) with the reference at each level. Throws std::invalid_argument on bad options.
ConvergenceResult run_convergence(const FidelityOptions& options);
/// The tables of a run (Markdown), one per scene, with the verdict.
std::string convergence_table(const ConvergenceResult& result);
std::string convergence_json(const ConvergenceResult& result);
/// A run read back from convergence_json() (its seeds' figures), compared again with
/// compare_levels(). Throws std::runtime_error on a malformed file.
ConvergenceResult convergence_from_json(const std::string& text);

}  // namespace statsim::tools::fidelity
