// The `statsim` host command: one executable, one subcommand per job.
#include <CLI/CLI.hpp>

#include "bench/bench.hpp"
#include "export/export_commands.hpp"
#include "fidelity/fidelity.hpp"
#include "mesh/mesh_commands.hpp"
#include "ref2d/ref2d.hpp"
#include "ref3d/ref3d.hpp"
#include "render/render_commands.hpp"
#include "stress/stress.hpp"

int main(int argc, char** argv)
{
  CLI::App app{"statsim host tools: reference simulations, signature tables, benchmarks"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "statsim 0.1.0");
  statsim::tools::register_mesh_commands(app);
  statsim::tools::register_ref2d_commands(app);
  statsim::tools::register_bench_commands(app);
  statsim::tools::register_ref3d_commands(app);
  statsim::tools::register_render_commands(app);
  statsim::tools::register_export_commands(app);
  statsim::tools::register_stress_commands(app);
  statsim::tools::fidelity::register_fidelity_commands(app);
  CLI11_PARSE(app, argc, argv);
  return 0;
}
