// `statsim fidelity --scene-reference FILE.json`: the pile scenes' reference samples of an earlier
// run stand in for running Bullet again. A converged reference of a heap costs minutes of CPU per
// seed (tools/fidelity/README.md, "Is the reference converged?"); a pile model is compared against
// the same reference many times, so its runs are read back from the JSON of the run that made
// them, after checking that they describe the same scene: shape, scene set-up, figures, seeds and
// step.
#pragma once

#include "fidelity/fidelity.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace statsim::tools::fidelity {

/// Reference A's and B's runs of one scene, as an earlier run measured them.
struct StoredSceneReference {
  std::vector<SceneRun> a;  ///< seeds 1..N
  std::vector<SceneRun> b;  ///< seeds N+1..2N (the noise floor)
  double dt = 0;            ///< s, the reference's step
};

/// The reference of scene `kind` in `json_text` (written by `statsim fidelity --json` with
/// --scenes). Throws std::runtime_error naming the first thing that differs from this run: the
/// shape, a scene missing, its description (counts, geometry, time limit), its figures, the number
/// of seeds or the reference's step `dt` (s).
StoredSceneReference stored_scene_reference(const std::string& json_text, const std::string& shape,
                                            const std::string& kind, const std::string& description,
                                            const std::vector<SceneMetric>& metrics, std::size_t seeds, double dt);

}  // namespace statsim::tools::fidelity
