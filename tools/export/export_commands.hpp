// `statsim export`: a frame file as binary glTF 2.0.
#pragma once

namespace CLI {
class App;
}

namespace statsim::tools {

/// Adds the `export` subcommand.
void register_export_commands(CLI::App& app);

}  // namespace statsim::tools
