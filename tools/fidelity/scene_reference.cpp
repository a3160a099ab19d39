// `statsim fidelity --scene-reference`: see scene_reference.hpp.
#include "fidelity/scene_reference.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace statsim::tools::fidelity {
namespace {

using json = nlohmann::json;

std::vector<SceneRun> runs_of(const json& sample, const std::vector<SceneMetric>& metrics)
{
  std::vector<SceneRun> out;
  for (const json& r : sample.at("runs")) {
    SceneRun run;
    for (const SceneMetric& m : metrics) run.values.push_back(r.at(m.name).get<double>());
    run.all_asleep = r.at("all_asleep").get<bool>();
    run.time_limited = r.at("time_limited").get<bool>();
    run.seconds = r.at("seconds").get<double>();
    run.step_ms = r.value("step_ms", 0.0);
    out.push_back(std::move(run));
  }
  return out;
}

std::string seconds_text(double dt)
{
  char b[64];
  std::snprintf(b, sizeof b, "%.6g s", dt);
  return b;
}

}  // namespace

StoredSceneReference stored_scene_reference(const std::string& json_text, const std::string& shape,
                                            const std::string& kind, const std::string& description,
                                            const std::vector<SceneMetric>& metrics, std::size_t seeds, double dt)
{
  const std::string where = "--scene-reference: ";
  try {
    const json j = json::parse(json_text);
    if (j.at("shape").get<std::string>() != shape)
      throw std::runtime_error(where + "the file's shape is " + j.at("shape").get<std::string>() + ", not " + shape);
    if (!j.contains("scenes") || !j.at("scenes").contains(kind))
      throw std::runtime_error(where + "the file has no " + kind + " scene");
    const json& sc = j.at("scenes").at(kind);
    if (sc.at("description").get<std::string>() != description)
      throw std::runtime_error(where + "the file's " + kind + " is another scene: '" +
                               sc.at("description").get<std::string>() + "', not '" + description + "'");
    const json& names = sc.at("metrics");
    if (names.size() != metrics.size())
      throw std::runtime_error(where + "the file's " + kind + " has other figures");
    for (std::size_t k = 0; k < metrics.size(); ++k)
      if (names[k].at("name").get<std::string>() != metrics[k].name)
        throw std::runtime_error(where + "the file's " + kind + " has other figures");
    StoredSceneReference out;
    out.dt = sc.at("reference").at("dt").get<double>();
    // Steps written as 1/N round-trip through the JSON's shortest decimal form exactly.
    if (!(std::fabs(out.dt - dt) <= 1e-12 * dt))
      throw std::runtime_error(where + "the file's " + kind + " reference ran at " + seconds_text(out.dt) +
                               ", this run's at " + seconds_text(dt) + " (--pile-reference-dt)");
    out.a = runs_of(sc.at("reference"), metrics);
    out.b = runs_of(sc.at("noise_floor"), metrics);
    if (out.a.size() != seeds || out.b.size() != seeds)
      throw std::runtime_error(where + "the file's " + kind + " reference has " + std::to_string(out.a.size()) +
                               " seeds per sample, this run " + std::to_string(seeds) + " (--scene-seeds)");
    return out;
  } catch (const json::exception& e) {
    throw std::runtime_error(where + "not a statsim fidelity JSON with scenes: " + e.what());
  }
}

}  // namespace statsim::tools::fidelity
