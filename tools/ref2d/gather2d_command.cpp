// `statsim gather2d`: its command line (CLI11), which runs the gathering and writes the header,
// the JSON and the summary; registered through register_gather2d_commands (common/commands.hpp).
#include "ref2d/gather2d.hpp"

#include "common/atomic_file.hpp"
#include "common/commands.hpp"
#include "common/progress.hpp"
#include "ref2d/compare2d.hpp"
#include "ref2d/pairs2d.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace statsim::tools {

namespace {

struct Gather2dCommand {
  Gather2dOptions options;
  std::string out;
  std::string json;
  std::string name;
  std::string name_space = "statsim::tables";
  std::vector<std::pair<std::string, CLI::Option*>> recorded;  // options written into the command line
  bool no_body_contacts = false;
  CLI::Option* shape_opt = nullptr;
  CLI::Option* polygon_opt = nullptr;
};

// --out is written as the target records paths (a table of this repository as given, any other
// as its file name).
std::string recorded_command(const Gather2dCommand& cmd, const TableTarget& target)
{
  std::string s = target.program() + " gather2d";
  for (const auto& [flag, opt] : cmd.recorded) {
    if (opt->count() == 0) {
      continue;
    }
    if (opt->get_expected_max() == 0) {  // a flag
      s += " " + flag;
      continue;
    }
    for (const std::string& value : opt->results()) {
      s += " " + flag + " " + shell_quote(flag == "--out" ? target.path(value) : value);
    }
  }
  return s;
}

void run_gather2d_command(Gather2dCommand& cmd)
{
  try {
    Gather2dOptions& o = cmd.options;
    o.progress = true;
    const bool has_shape = cmd.shape_opt->count() > 0;
    const bool has_polygon = cmd.polygon_opt->count() > 0;
    if (has_shape == has_polygon) {
      throw std::invalid_argument("give exactly one of --shape square|lshape and --polygon \"x1,y1 x2,y2 ...\"");
    }
    if (has_polygon) {
      o.shape = "polygon";
    }
    const std::filesystem::path out(cmd.out);
    o.name = cmd.name.empty() ? out.stem().string() : cmd.name;
    o.body_contacts = !cmd.no_body_contacts;
    o.target = table_target(cmd.out, cmd.name_space);
    validate_gather2d_options(o);  // fail before a long run
    const std::filesystem::path dir = out.parent_path().empty() ? std::filesystem::path(".") : out.parent_path();
    if (!std::filesystem::is_directory(dir)) {
      throw std::invalid_argument("the directory of --out, '" + dir.string() + "', does not exist");
    }
    const std::string command = recorded_command(cmd, o.target);
    const auto start = std::chrono::steady_clock::now();
    const Gather2dResult r = run_gather2d(o);
    const std::string header = gather2d_header(r, command);
    write_file_atomic(out, header);
    if (!cmd.json.empty()) {
      write_file_atomic(cmd.json, gather2d_json(r, command));
    }
    std::fputs(gather2d_summary(r).c_str(), stdout);
    const double seconds = seconds_since(start);
    std::printf("wrote %s (%zu bytes) in %.1f s\n", out.c_str(), header.size(), seconds);
    std::fflush(stdout);
  } catch (const std::exception& e) {
    std::string message = e.what();
    std::fprintf(stderr, "statsim gather2d: error: %s\n", message.c_str());
    throw CLI::RuntimeError(1);
  }
}

}  // namespace

void register_gather2d_commands(CLI::App& app)
{
  auto cmd = std::make_shared<Gather2dCommand>();
  Gather2dOptions& o = cmd->options;
  CLI::App* g = app.add_subcommand(
      "gather2d",
      "Gather the statistical signature of a 2D shape with Box2D (collision heights, response tables, rest "
      "poses) into a C++ header tables/NAME2d.hpp");
  cmd->shape_opt = g->add_option("--shape", o.shape, "square (1 x 1 m) or lshape (1 m arms, 0.25 m thick)")
                       ->check(CLI::IsMember({"square", "lshape"}));
  cmd->polygon_opt = g->add_option("--polygon", o.polygon,
                                   "A simple polygon \"x1,y1 x2,y2 ...\" in metres (concave allowed; either orientation)");
  CLI::Option* out = g->add_option("--out", cmd->out, "Output header, e.g. tables/square2d.hpp")->required();
  CLI::Option* name = g->add_option("--name", cmd->name, "C++ name of the table (default: the file name's stem)");
  CLI::Option* name_space =
      g->add_option("--namespace", cmd->name_space, "C++ namespace of the table")->capture_default_str();
  CLI::Option* seed = g->add_option("--seed", o.seed, "Random seed")->capture_default_str();
  CLI::Option* trials =
      g->add_option("--trials", o.trials, "Trials per response cell")->capture_default_str()->check(CLI::Range(2, 100000));
  CLI::Option* height_trials = g->add_option("--height-trials", o.height_trials, "Drops per height-table spin ratio")
                                   ->capture_default_str()
                                   ->check(CLI::Range(2, 1000000));
  CLI::Option* rest = g->add_option("--rest-drops", o.rest_drops, "Drops for the rest poses")
                          ->capture_default_str()
                          ->check(CLI::Range(20, 10000000));
  CLI::Option* restitution = g->add_option("--restitution", o.restitution, "Restitution of body and ground")
                                 ->capture_default_str()
                                 ->check(CLI::Range(0.0, 1.0));
  CLI::Option* friction = g->add_option("--friction", o.friction, "Friction of body and ground")
                              ->capture_default_str()
                              ->check(CLI::Range(0.0, 10.0));
  CLI::Option* min_frequency =
      g->add_option("--rest-min-frequency", o.min_frequency,
                    "Rest poses: keep every pose of a family (poses equivalent under the shape's symmetry) seen in "
                    "more than this fraction of the drops together, in [0, 1)")
          ->capture_default_str();
  CLI::Option* max_dropped =
      g->add_option("--rest-max-dropped", o.max_dropped,
                    "Rest poses: then keep rarer families, most frequent first, while more than this fraction of the "
                    "settled drops is in poses not kept, in [0, 1] (1: never)")
          ->capture_default_str();
  CLI::Option* no_contacts = g->add_flag("--no-body-contacts", cmd->no_body_contacts,
                                         "Leave out the body-body data (a table of format 2.0, as written before it existed)");
  CLI::Option* support_size = g->add_option("--support-size", o.support_size, "Body-body: support map nodes a side, S")
                                  ->capture_default_str();
  CLI::Option* contact_faces =
      g->add_option("--contact-faces", o.contact_faces, "Body-body: longest hull edges stored")->capture_default_str();
  CLI::Option* pair_trials =
      g->add_option("--pair-trials", o.pair_trials, "Body-body: pair flights per height-table spin ratio")
          ->capture_default_str();
  CLI::Option* packing_piles =
      g->add_option("--packing-piles", o.packing_piles, "Body-body: Box2D piles for the packing ratios")
          ->capture_default_str();
  CLI::Option* packing_count =
      g->add_option("--packing-count", o.packing_count, "Body-body: bodies per pile")->capture_default_str();
  CLI::Option* packing_steps =
      g->add_option("--packing-steps", o.packing_steps, "Body-body: steps of 1/60 s per pile")->capture_default_str();
  g->add_option("--threads", o.threads, "Worker threads (0 = all); the output does not depend on it")
      ->capture_default_str();
  g->add_option("--json", cmd->json, "Also write a JSON summary (statistics, counts, timings) to this file");
  cmd->recorded = {{"--shape", cmd->shape_opt},
                   {"--polygon", cmd->polygon_opt},
                   {"--out", out},
                   {"--name", name},
                   {"--namespace", name_space},
                   {"--seed", seed},
                   {"--trials", trials},
                   {"--height-trials", height_trials},
                   {"--rest-drops", rest},
                   {"--restitution", restitution},
                   {"--friction", friction},
                   {"--rest-min-frequency", min_frequency},
                   {"--rest-max-dropped", max_dropped},
                   {"--no-body-contacts", no_contacts},
                   {"--support-size", support_size},
                   {"--contact-faces", contact_faces},
                   {"--pair-trials", pair_trials},
                   {"--packing-piles", packing_piles},
                   {"--packing-count", packing_count},
                   {"--packing-steps", packing_steps}};
  g->callback([cmd]() { run_gather2d_command(*cmd); });

  register_compare2d_command(app);
  register_pairs2d_command(app);
}

}  // namespace statsim::tools
