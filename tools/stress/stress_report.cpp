// `statsim stress`'s report: the cells as a Markdown table on stdout and as JSON, and the command
// that runs the matrix (stress.cpp) and reports it.
#include "stress/stress.hpp"
#include "common/commands.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace statsim::tools {

std::string stress_json(const std::vector<StressCell>& cells)
{
  nlohmann::json j = nlohmann::json::array();
  for (const auto& c : cells)
    j.push_back({{"scene", c.scene}, {"method", c.method}, {"pass", c.pass}, {"figure", c.figure},
                 {"criterion", c.criterion}});
  return j.dump(2) + "\n";
}

std::string stress_markdown(const std::vector<StressCell>& cells)
{
  std::string s = "| scene | method | result | figure | criterion |\n|---|---|---|---|---|\n";
  for (const auto& c : cells)
    s += "| " + c.scene + " | " + c.method + " | " + (c.pass ? "pass" : "**FAIL**") + " | " + c.figure + " | " +
         c.criterion + " |\n";
  return s;
}

void register_stress_commands(CLI::App& app)
{
  auto opts = std::make_shared<StressOptions>();
  auto json = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "stress", "Stress matrix: fast impacts, large steps, a deep pile, energy, out-of-range states, a long run, "
                "bad input and slopes, for every method");
  cmd->add_option("--methods", opts->methods,
                  "Methods (default all): full, low, spheres7, sphere (Bullet), statistical (statsim 3D), polygon "
                  "(Box2D), statistical2d (statsim 2D)")
      ->delimiter(',');
  cmd->add_option("--scenes", opts->scenes,
                  "Scenes (default all): bad-input, fast-impact, large-dt, out-of-range, energy, deep-pile, long-run, "
                  "slopes, small-dt, mass-ratio, snapshot, spawn-remove, sizes")
      ->delimiter(',');
  cmd->add_option("--json", *json, "Write the cells as JSON to FILE");
  cmd->add_flag("--quick", opts->quick, "Smaller scenes: 1,000-bunny pile, 2,000 energy steps, 120 s long run, 36 bunnies per slope");
  cmd->add_option("--budget", opts->budget_s, "Wall-clock seconds one Bullet cell of the pile or energy scene may take")
      ->capture_default_str();
  cmd->add_option("--meshes", opts->meshes_dir, "Directory of bunny.obj, bunny_low.obj, bunny_spheres7.txt");
  cmd->add_option("--body-contacts", opts->hull_contacts,
                  "statsim: where bodies touch each other, hulls (the library's default, where the tables have "
                  "body-body data) or spheres (the paper's collision spheres)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, bool>{{"hulls", true}, {"spheres", false}}))
      ->default_str("hulls");
  cmd->add_flag("--ground-hulls", opts->ground_hulls,
                "statsim: bodies meet level ground with their hull after the first impact (WorldDef::ground_hulls)");
  cmd->callback([opts, json]() {
    const std::vector<StressCell> cells = run_stress(*opts);
    std::cout << stress_markdown(cells);
    std::size_t failed = 0, stat_failed = 0;
    for (const auto& c : cells) {
      failed += !c.pass;
      stat_failed += !c.pass && (c.method == "statistical" || c.method == "statistical2d");
    }
    std::cout << "\n" << cells.size() << " cells, " << failed << " failed (" << stat_failed << " of them statsim)\n";
    if (!json->empty()) {
      std::ofstream out(*json);
      out << stress_json(cells);
      if (!out) throw std::runtime_error("cannot write " + *json);
    }
  });
}

}  // namespace statsim::tools
