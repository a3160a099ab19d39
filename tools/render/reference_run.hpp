// `statsim reference-run`: the shared bunny-drop scene (tools/scenes) run by Bullet (the full
// bunny mesh) or by statsim (the bunny's table), writing a frame file (render/frames.hpp), so the
// two can be drawn side by side (paper Figure 8).
#pragma once

#include <cstdint>
#include <string>

namespace statsim::tools::render {

struct ReferenceRunOptions {
  std::string scene = "bunnies50";  ///< "bunniesN": N bunnies dropped from the shared cylinder
  std::string engine = "bullet";    ///< bullet | statsim
  std::string frames;               ///< output frame file
  double seconds = 6.0;             ///< simulated time
  int every = 6;                    ///< write every k-th step of 1/60 s
  std::uint64_t seed = 1;           ///< scene layout (and statsim's world seed)
  /// statsim: the library's default, bodies touch at their hulls (`BodyContacts::automatic`, as
  /// `statsim bench` and `statsim fidelity` run them); false: at the paper's collision spheres
  bool hull_contacts = true;
  /// Bullet: internal steps per step of 1/60 s (4: 1/240 s; the 50-bunny piles' reference is
  /// converged at 16, 1/960 s: tools/fidelity/README.md, "Is the reference converged?").
  int substeps = 4;
  std::string meshes_dir;
};

/// Runs the scene and writes the frames; prints a summary line on stdout. Returns false with
/// `error` set on bad options or an unwritable file.
bool reference_run(const ReferenceRunOptions& options, std::string& error);

}  // namespace statsim::tools::render
