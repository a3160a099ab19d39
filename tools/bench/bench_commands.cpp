// `statsim bench`: command-line front end of tools/bench.
#include "bench/bench.hpp"
#include "common/commands.hpp"

#include "common/atomic_file.hpp"
#include "common/plot.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace statsim::tools {
namespace {

struct BenchCommand {
  BenchOptions options;
  std::string dt = "1/60";
  std::string csv;
  std::string chart;
  std::string replot;
  bool shape_given = false;
  bool quiet = false;
};

/// "1/60", "0.0166", "1e-2": a positive time step in seconds.
double parse_dt(const std::string& text)
{
  auto number = [&](const std::string& t) {
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v))
      throw std::invalid_argument("--dt: '" + text + "' is not a number or a fraction like 1/60");
    return v;
  };
  const auto slash = text.find('/');
  const double v = slash == std::string::npos ? number(text) : number(text.substr(0, slash)) / number(text.substr(slash + 1));
  if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument("--dt must be positive (got '" + text + "')");
  return v;
}

void make_parent(const std::string& file)
{
  const std::filesystem::path parent = std::filesystem::path(file).parent_path();
  if (!parent.empty()) ensure_writable_directory(parent);
}

// Errors propagate to main, which prints "statsim bench: error: ..." and exits with 1.
void run_bench_command(BenchCommand& cmd)
{
  if (!cmd.replot.empty()) {
    // Redraw the chart of an earlier run from its CSV, without running anything.
    if (cmd.chart.empty()) throw std::invalid_argument("--replot needs --chart FILE.png");
    std::vector<std::string> args{cmd.replot, "--out", cmd.chart};
    // The CSV does not hold the shape: the title names the one given, else the script's default
    // (bunny; square for a 2D run, which it tells from the CSV).
    if (cmd.shape_given) args.insert(args.end(), {"--shape", cmd.options.shape});
    if (cmd.options.chart_cpu) args.push_back("--cpu");
    make_parent(cmd.chart);
    plot::run_script("bench.py", args);
    std::printf("wrote %s and %s\n", cmd.chart.c_str(), plot::svg_of(cmd.chart).c_str());
    return;
  }
  cmd.options.dt = parse_dt(cmd.dt);
  cmd.options.progress = !cmd.quiet;
  if (cmd.options.dim == 2 && cmd.options.shape == "bunny") cmd.options.shape = "square";
  validate_bench_options(cmd.options);
  // Fail on unwritable outputs before the run, not after it.
  if (!cmd.csv.empty()) make_parent(cmd.csv);
  if (!cmd.chart.empty()) {
    make_parent(cmd.chart);
    plot::find_python();  // a missing matplotlib too
  }
  const BenchResult result = run_bench(cmd.options);
  std::fputs(bench_markdown(result).c_str(), stdout);
  if (!cmd.csv.empty()) {
    write_file_atomic(cmd.csv, bench_csv(result));
    std::printf("\nwrote %s\n", cmd.csv.c_str());
  }
  if (!cmd.chart.empty()) {
    write_bench_chart(result, cmd.chart);
    std::printf("wrote %s and %s\n", cmd.chart.c_str(), plot::svg_of(cmd.chart).c_str());
  }
  std::fflush(stdout);
}

}  // namespace

void register_bench_commands(CLI::App& app)
{
  auto cmd = std::make_shared<BenchCommand>();
  CLI::App* b = app.add_subcommand(
      "bench",
      "Paper Table 1 against real engines in one run: time per step of N dropped bodies for Bullet "
      "representations (full, low, hull, spheres7, sphere) and statsim (statistical); --dim 2: Box2D vs statsim");
  BenchOptions& o = cmd->options;
  b->add_option("--dim", o.dim, "2 (Box2D vs statsim, squares) or 3 (Bullet vs statsim)")->capture_default_str();
  CLI::Option* shape = b->add_option("--shape", o.shape, "3D: bunny, box or lshape; 2D: square")->capture_default_str();
  b->add_option("--n", o.counts, "Body counts, comma-separated")->delimiter(',')->capture_default_str();
  b->add_option("--methods", o.methods,
                "Comma-separated; 3D: full, low, hull, spheres7, sphere, statistical (default: all but hull); "
                "2D: polygon, circle, statistical")
      ->delimiter(',');
  b->add_option("--broadphase", o.broadphases, "Bullet broad phases: sap (btAxisSweep3), dbvt (btDbvtBroadphase)")
      ->delimiter(',')
      ->capture_default_str();
  b->add_option("--dt", cmd->dt, "Time step in s: a number or a fraction such as 1/60")->capture_default_str();
  b->add_option("--steps", o.steps, "K: timed steps per repeat")->capture_default_str();
  b->add_option("--warmup", o.warmup, "W: untimed steps before the first repeat of each cell")->capture_default_str();
  b->add_option("--repeat", o.repeats, "R: timed repeats per cell, each from the initial states")->capture_default_str();
  b->add_option("--limit-ms", o.limit_ms, "Skip a cell (and its larger N) whose step takes longer than this")
      ->capture_default_str();
  b->add_option("--budget-s", o.budget_s, "Stop repeating a cell once its timed runs took this long (>= 1 repeat)")
      ->capture_default_str();
  b->add_option("--seed", o.seed, "Scene seed (and statsim's random streams)")->capture_default_str();
  b->add_option("--meshes", o.meshes_dir, "Directory of bunny.obj etc. (default: the source tree's tools/meshes)");
  b->add_option("--csv", cmd->csv, "Write the CSV here");
  b->add_option("--chart", cmd->chart, "Write the log-log chart here as PNG, and as SVG beside it (FILE.svg)");
  b->add_option("--replot", cmd->replot, "Only redraw --chart from the CSV of an earlier run (--shape names the shape in the title)");
  b->add_flag("--quiet", cmd->quiet, "No progress on stderr");
  b->add_option("--body-contacts", o.hull_contacts,
                "statsim: where bodies touch each other, hulls (the library's default, WorldDef::body_contacts = "
                "automatic: hulls where the table has body-body data) or spheres (the paper's collision spheres)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, bool>{{"hulls", true}, {"spheres", false}}))
      ->default_str("hulls");
  b->add_flag("--all-features", o.all_features,
              "statsim 3D: worlds compiled with every feature (Features::all) instead of the smallest set that covers "
              "the scene (statsim/features.hpp); the same bits, more code in the step");
  b->add_option("--workers", o.workers, "statsim: threads stepping each world (WorldDef::workers), 1 to 64")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  b->add_flag("--chart-cpu", cmd->options.chart_cpu,
              "Chart the thread CPU time per step instead of the wall-clock median (a machine shared with other work)");
  b->callback([cmd, shape]() {
    cmd->shape_given = shape->count() > 0;
    run_bench_command(*cmd);
  });
}

}  // namespace statsim::tools
