// The `statsim` host command: one executable, one subcommand per job.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

#include "common/commands.hpp"

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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    // A subcommand failed (bad options, unreadable input, unwritable output): one line that names
    // it, and exit code 1.
    const std::string name = app.get_subcommands().empty() ? "" : app.get_subcommands().front()->get_name();
    std::string message = e.what();
    if (!name.empty() && message.rfind(name + ": ", 0) == 0) message.erase(0, name.size() + 2);
    std::fprintf(stderr, "statsim %s: error: %s\n", name.c_str(), message.c_str());
    return 1;
  }
  return 0;
}
