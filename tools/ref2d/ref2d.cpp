#include "common/commands.hpp"

#include "common/atomic_file.hpp"
#include "common/plot.hpp"
#include "ref2d/fig3.hpp"
#include "ref2d/gather2d.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>

namespace statsim::tools {
namespace {

struct Fig3Command {
  std::filesystem::path out;
  Fig3Options options;
};

void run_fig3_command(const Fig3Command& cmd)
{
  Fig3Options options = cmd.options;
  options.progress = true;
  validate_fig3_options(options);      // fail before creating anything
  ensure_writable_directory(cmd.out);  // and before the run, not after it
  plot::find_python();                 // so is a missing matplotlib
  const Fig3Result result = run_fig3(options);
  write_fig3_outputs(result, cmd.out);
  std::fputs(fig3_summary(result).c_str(), stdout);
  std::printf("wrote %s, %s and %s\n", (cmd.out / "fig3.csv").c_str(), (cmd.out / "fig3.png").c_str(),
              (cmd.out / "fig3.svg").c_str());
  std::fflush(stdout);
}

}  // namespace

void register_ref2d_commands(CLI::App& app)
{
  auto cmd = std::make_shared<Fig3Command>();
  CLI::App* fig3 = app.add_subcommand(
      "fig3",
      "Paper Figure 3: centre height of a 1x1 square at its first contact with a line vs |w|/|v|, "
      "measured with Box2D (skin bias removed); writes DIR/fig3.csv, DIR/fig3.png and DIR/fig3.svg");
  fig3->add_option("--out", cmd->out, "Output directory (created if missing)")->required();
  fig3->add_option("--trials", cmd->options.trials, "Drops per |w|/|v| value")
      ->check(CLI::Range(2, std::numeric_limits<int>::max()))
      ->capture_default_str();
  fig3->add_option("--seed", cmd->options.seed, "Random seed (same seed, same CSV, any --threads)")
      ->capture_default_str();
  fig3->add_option("--speed", cmd->options.speed,
                   "Linear speed |v| in m/s (> 0), straight down; the heights depend only on |w|/|v|")
      ->capture_default_str();
  fig3->add_option("--dt", cmd->options.dt, "Box2D time step in s (> 0)")->capture_default_str();
  fig3->add_option("--threads", cmd->options.threads, "Worker threads (0 = all hardware threads)")
      ->capture_default_str();
  fig3->callback([cmd]() { run_fig3_command(*cmd); });

  register_gather2d_commands(app);  // gather2d and compare2d (gather2d.hpp, compare2d.hpp)
}

}  // namespace statsim::tools
