// `statsim stress`: see stress.hpp. Every scene is built from fixed seeds, so a run is
// repeatable; wall-clock figures (ms per step) are the only ones that vary between runs.
//
// Methods. 3D: full, low, spheres7, sphere = the benchmark's Bullet simulator (tools/bench: its
// representations of the bunny and its settings, with the scene's planes, gravity and material,
// and btDbvtBroadphase); statistical = statsim World3 with tables/bunny.hpp and the runtime's
// defaults.
// 2D: polygon = Box2D 2.4.1 unit square (velocity 8, position 3 iterations, its default CCD);
// statistical2d = statsim World2 with tables/square2d.hpp.
#include "stress/stress.hpp"

#include "stress/matrix.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace statsim::tools {

std::vector<StressCell> run_stress(const StressOptions& options)
{
  for (const auto& m : options.methods)
    if (std::find(stress::kMethods3.begin(), stress::kMethods3.end(), m) == stress::kMethods3.end() &&
        std::find(stress::kMethods2.begin(), stress::kMethods2.end(), m) == stress::kMethods2.end())
      throw std::invalid_argument("unknown method '" + m + "' (full, low, spheres7, sphere, statistical, polygon, "
                                  "statistical2d)");
  if (!(options.budget_s > 0)) throw std::invalid_argument("--budget must be positive");
  const std::string dir = options.meshes_dir.empty() ? std::string(STATSIM_STRESS_MESHES_DIR) : options.meshes_dir;
  const std::vector<std::pair<std::string, void (stress::Matrix::*)()>> scenes = {
      {"bad-input", &stress::Matrix::bad_input}, {"fast-impact", &stress::Matrix::fast_impact},
      {"large-dt", &stress::Matrix::large_time_step}, {"out-of-range", &stress::Matrix::out_of_range},
      {"energy", &stress::Matrix::energy}, {"deep-pile", &stress::Matrix::deep_pile},
      {"long-run", &stress::Matrix::long_run}, {"slopes", &stress::Matrix::slopes},
      {"small-dt", &stress::Matrix::small_time_step}, {"mass-ratio", &stress::Matrix::mass_ratio},
      {"snapshot", &stress::Matrix::snapshot}, {"spawn-remove", &stress::Matrix::spawn_remove}, {"sizes", &stress::Matrix::sizes}};
  for (const auto& name : options.scenes)
    if (std::none_of(scenes.begin(), scenes.end(), [&name](const auto& s) { return s.first == name; }))
      throw std::invalid_argument("unknown scene '" + name + "' (bad-input, fast-impact, large-dt, out-of-range, "
                                  "energy, deep-pile, long-run, slopes, small-dt, mass-ratio, snapshot, spawn-remove, "
                                  "sizes)");
  stress::Matrix mx(options, bench::load_body3("bunny", dir), dir);
  for (const auto& s : scenes)
    if (options.scenes.empty() ||
        std::find(options.scenes.begin(), options.scenes.end(), s.first) != options.scenes.end())
      (mx.*s.second)();
  return mx.take();
}

}  // namespace statsim::tools
