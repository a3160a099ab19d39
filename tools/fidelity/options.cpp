// The options of `statsim fidelity`: the default methods and the check of a FidelityOptions.
#include "fidelity/fidelity.hpp"

#include <stdexcept>
#include <string>

namespace statsim::tools::fidelity {

std::vector<std::string> default_methods()
{
  return {"full", "low", "spheres7", "sphere", "statistical", "statistical-norest", "statistical-independent"};
}

std::string shape_label(const FidelityOptions& o)
{
  std::string s = o.mesh.empty() ? o.shape : o.mesh;
  if (!o.mix.empty()) s += " and " + o.mix + " (mixed, half and half)";
  return s;
}

double pile_reference_step(const FidelityOptions& o, const std::string& kind)
{
  if (o.pile_reference_dt > 0) return o.pile_reference_dt;
  // The box's and the L-shape's heaps still move at 1/1920 s and 1/3840 s; the finest step
  // measured stands in for their limit.
  if (kind == "heap") return 1.0 / 3840.0;
  if (kind == "bin") return 1.0 / 960.0;
  if (kind == "column" || kind == "wall") return 1.0 / 480.0;
  return 1.0 / 960.0;  // the drop piles
}

void validate(const FidelityOptions& o)
{
  auto bad = [](const std::string& m) { throw std::invalid_argument(m); };
  if (o.runs < 1) bad("--runs must be at least 1");
  if (!(o.dt > 0) || o.dt > 0.1) bad("--dt must be in (0, 0.1] s");
  if (!(o.reference_dt > 0) || o.reference_dt > 0.1) bad("--reference-dt must be in (0, 0.1] s");
  if (!(o.pile_reference_dt >= 0) || o.pile_reference_dt > 0.1)
    bad("--pile-reference-dt must be in (0, 0.1] s, or 0 for each scene's own step");
  if (!(o.time_limit > 0) || o.time_limit > 600) bad("--time-limit must be in (0, 600] s");
  if (o.pile_seeds < 1) bad("--pile-seeds must be at least 1");
  if (o.pile_count < 1 || o.pile_count > 16384) bad("--pile-count must be in [1, 16384]");
  if (o.bench_n < 1 || o.bench_n > 16384) bad("--bench-n must be in [1, 16384]");
  if (o.bench_steps < 1) bad("--bench-steps must be at least 1");
  if (o.bootstrap < 0) bad("--bootstrap must be >= 0");
  if (o.reference != "gather" && o.reference != "bench") bad("--reference must be gather or bench");
  for (const std::string& k : o.scenes)
    if (k != "heap" && k != "bin" && k != "stack" && k != "column" && k != "wall")
      bad("--scenes takes heap, bin, stack, column, wall (got '" + k + "')");
  if (!o.drops && o.scenes.empty()) bad("--scenes-only needs --scenes");
  if (o.scene_seeds < 1) bad("--scene-seeds must be at least 1");
  if (o.heap_count < 1 || o.heap_count > 16384) bad("--heap-count must be in [1, 16384]");
  if (o.bin_count < 1 || o.bin_count > 16384) bad("--bin-count must be in [1, 16384]");
  if (o.bin_cells < 1 || o.bin_cells > 64) bad("--bin-cells must be in [1, 64]");
  if (o.column_height < 1 || o.column_height > 1000) bad("--column-height must be in [1, 1000]");
  if (o.wall_columns < 1 || o.wall_columns > 100) bad("--wall-columns must be in [1, 100]");
  if (o.wall_height < 1 || o.wall_height > 1000) bad("--wall-height must be in [1, 1000]");
  if (!(o.stack_time > 0) || o.stack_time > 600) bad("--stack-time must be in (0, 600] s");
  if (!o.scene_reference.empty() && o.scenes.empty()) bad("--scene-reference needs --scenes");
  if (!o.scene_reference.empty() && !o.scene_frames.empty())
    bad("--scene-frames needs the reference's final states: run the reference (no --scene-reference)");
  if (!o.scene_reference.empty() && !o.convergence.empty()) bad("--convergence runs the reference itself");
  if (!o.mesh.empty() && o.tables.empty()) bad("--mesh needs --table NAME=FILE.json (the shape has no compiled table)");
  for (const auto& t : o.tables)
    if (t.first.empty() || t.second.empty()) bad("--table takes NAME=FILE.json");
  if (!o.mix.empty()) {
    if (o.mix != "bunny" && o.mix != "box" && o.mix != "lshape") bad("--mix takes bunny, box or lshape");
    if (!o.mesh.empty() || !o.tables.empty()) bad("--mix needs a compiled shape (no --mesh, no --table)");
    if (o.drops) bad("--mix needs --scenes-only (it mixes the heap and the bin)");
    for (const std::string& k : o.scenes)
      if (k != "heap" && k != "bin") bad("--mix takes the heap and bin scenes only (got '" + k + "')");
  }
}

}  // namespace statsim::tools::fidelity
