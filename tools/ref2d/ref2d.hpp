// Box2D reference experiments (2D), as subcommands of the `statsim` host command.
#pragma once

namespace CLI {
class App;
}

namespace statsim::tools {

/// Adds the Box2D subcommands to `app`:
///   fig3  the paper's Figure 3: collision height of a 1x1 square vs |w|/|v| (see fig3.hpp).
///   gather2d  a 2D shape's signature tables (see gather2d.hpp).
///   compare2d Box2D vs statsim's World2 on the same drop (see compare2d.hpp).
void register_ref2d_commands(CLI::App& app);

}  // namespace statsim::tools
