// The subcommands of the `statsim` host command, one registration function per module: each adds
// its subcommands (with their options and help) to the CLI11 app. tools/statsim/main.cpp calls
// them all; tests call one to run a subcommand as a user would.
#pragma once

namespace CLI {
class App;
}

namespace statsim::tools {

/// `mesh` with `info`, `decimate`, `spheres`, `box`, `wedge` and `lshape` (tools/mesh).
void register_mesh_commands(CLI::App& app);
/// Box2D experiments: `fig3` (the paper's Figure 3), then `gather2d` and `compare2d` (tools/ref2d).
void register_ref2d_commands(CLI::App& app);
/// `gather2d` (a 2D shape's signature tables), `compare2d` (Box2D vs statsim's World2) and
/// `gather-pairs2d` (body-body statistics with Box2D).
void register_gather2d_commands(CLI::App& app);
/// `gather`: a shape's statistical signature measured with Bullet, written as a C++ table and
/// optionally as JSON; `gather-pairs`: body-body statistics with Bullet (tools/ref3d).
void register_ref3d_commands(CLI::App& app);
/// `bench`: time per step against Bullet and Box2D (tools/bench).
void register_bench_commands(CLI::App& app);
/// `render` (PNG frames, GIF, side by side) and `reference-run` (tools/render).
void register_render_commands(CLI::App& app);
/// `export`: a frame file as binary glTF 2.0 (tools/export).
void register_export_commands(CLI::App& app);
/// `stress`: the stability matrix (tools/stress).
void register_stress_commands(CLI::App& app);

namespace fidelity {
/// `fidelity`: accuracy against speed, against a Bullet reference (tools/fidelity).
void register_fidelity_commands(CLI::App& app);
}  // namespace fidelity

}  // namespace statsim::tools
