// The 3D reference (Bullet) subcommands of the `statsim` host command.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace statsim::tools {

/// Runs `statsim gather ARGS...` (for tests): returns the exit code; messages go to `out` / `err`.
int run_gather_command(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace statsim::tools
