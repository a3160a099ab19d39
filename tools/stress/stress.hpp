// `statsim stress`: the stress matrix, scenes where approximate methods fail (fast
// impacts, large time steps, a deep pile, energy in a closed elastic box, states beyond the
// table's range, a long run, bad input through the public API, rest and sliding on slopes) against every method: Bullet's
// reference representations (full, low, spheres7, sphere) and statsim (statistical) in 3D; Box2D
// (polygon) and statsim (statistical2d) in 2D where the scene applies. Each cell prints pass or
// fail, its figure and its pass criterion; --json writes the cells.
#pragma once

#include <string>
#include <vector>

namespace statsim::tools {

struct StressOptions {
  std::vector<std::string> methods;  ///< empty: all
  /// Scenes to run (bad-input, fast-impact, large-dt, out-of-range, energy, deep-pile, long-run,
  /// slopes); empty: all.
  std::vector<std::string> scenes;
  bool quick = false;                ///< smaller scenes and budgets (about a minute)
  double budget_s = 60.0;            ///< wall-clock budget of one reference-engine cell
  std::string meshes_dir;            ///< empty: the source tree's tools/meshes
  /// statsim's worlds with the library's default body contacts (`BodyContacts::automatic`: hulls
  /// where the tables have body-body data); false: the paper's collision spheres.
  bool hull_contacts = true;
  /// statsim's worlds with `WorldDef::ground_hulls` (off: the library's default).
  bool ground_hulls = false;
  bool progress = true;
};

struct StressCell {
  std::string scene;      ///< e.g. "fast impact 20 m/s"
  std::string method;     ///< full, low, spheres7, sphere, statistical, polygon, statistical2d
  bool pass = false;
  std::string figure;     ///< the measured figures, one line
  std::string criterion;  ///< what pass means
};

/// Runs the matrix. Throws std::runtime_error (missing mesh, ...) or std::invalid_argument.
std::vector<StressCell> run_stress(const StressOptions& options);
/// The cells as a JSON array of {scene, method, pass, figure, criterion}.
std::string stress_json(const std::vector<StressCell>& cells);
/// The cells as a Markdown table.
std::string stress_markdown(const std::vector<StressCell>& cells);

}  // namespace statsim::tools
