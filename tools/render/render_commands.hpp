// `statsim render` (PNG frames, GIF, side by side) and `statsim reference-run`.
#pragma once

namespace CLI {
class App;
}

namespace statsim::tools {

/// Adds the `render` and `reference-run` subcommands.
void register_render_commands(CLI::App& app);

}  // namespace statsim::tools
