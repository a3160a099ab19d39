// The 3D reference (Bullet) subcommands of the `statsim` host command.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace statsim::tools {

/// Adds `gather` to `app`: a shape's statistical signature measured with Bullet, written as a
/// C++ table (tables/NAME.hpp) and optionally as JSON; see ref3d/gather.hpp.
void register_ref3d_commands(CLI::App& app);

/// Runs `statsim gather ARGS...` (for tests): returns the exit code; messages go to `out` / `err`.
int run_gather_command(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace statsim::tools
