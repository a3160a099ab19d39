#include "export/gltf_export.hpp"
#include "common/commands.hpp"

#include "render/frames.hpp"
#include "render/render.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

namespace statsim::tools {

namespace {

struct ExportArgs {
  std::string in, gltf, shapes, detail = "full", meshes;
  int every = 1;
};

int run_export(const ExportArgs& a)
{
  render::LoadedFrames in;
  std::string error;
  if (!render::load_frames(a.in, a.shapes, a.detail, a.meshes, in, error)) {
    std::fprintf(stderr, "export: %s\n", error.c_str());
    return 1;
  }
  render::Frames& frames = in.frames;
  if (a.every > 1) {
    std::vector<render::Frame> kept;
    for (std::size_t i = 0; i < frames.frames.size(); i += std::size_t(a.every)) kept.push_back(frames.frames[i]);
    frames.frames = kept;
  }
  if (!exporter::export_glb(frames, in.shapes, a.gltf, error)) {
    std::fprintf(stderr, "export: %s\n", error.c_str());
    return 1;
  }
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(a.gltf, ec);
  std::printf("export: %d bodies, %zu keyframes (%.3f to %.3f s) -> %s (%.1f KB)\n", frames.body_count(),
              frames.frames.size(), frames.frames.front().time, frames.frames.back().time, a.gltf.c_str(),
              ec ? 0.0 : double(bytes) / 1024.0);
  return 0;
}

}  // namespace

void register_export_commands(CLI::App& app)
{
  auto a = std::make_shared<ExportArgs>();
  a->meshes = render::default_meshes_dir();
  CLI::App* e = app.add_subcommand("export", "Write a frame file as binary glTF 2.0 (meshes and keyframe animation)");
  e->add_option("--in", a->in, "frame file (CSV: frame,time,body,shape,x,y,z,qw,qx,qy,qz,state[,radius])")->required();
  e->add_option("--gltf", a->gltf, "output .glb file")->required();
  e->add_option("--every", a->every, "keep every k-th frame of the file")->check(CLI::Range(1, 1000000));
  e->add_option("--shapes", a->shapes, "names of numeric shape ids 0,1,... (files that store ids)");
  e->add_option("--detail", a->detail, "bunny mesh: full or low (bunny_low.obj, for big scenes)")
      ->check(CLI::IsMember({"full", "low"}))
      ->capture_default_str();
  e->add_option("--meshes", a->meshes, "directory of the shape meshes")->capture_default_str();
  e->callback([a]() {
    const int rc = run_export(*a);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace statsim::tools
