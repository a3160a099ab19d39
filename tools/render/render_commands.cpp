#include "render/render.hpp"
#include "common/commands.hpp"

#include "common/format.hpp"
#include "common/progress.hpp"
#include "render/frames.hpp"
#include "render/reference_run.hpp"

#include <CLI/CLI.hpp>

#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace statsim::tools {

namespace {

struct RenderArgs {
  std::string in, out, gif, side, camera, shapes, detail = "auto", labels = "statsim,reference", meshes;
  std::string size = "640x360";
  int every = 1;
  int frame = 0;
  bool single = false;
  bool spheres = false;
  bool no_shadows = false;
  int supersample = 2;
  int gif_delay = 4;
  double fit_share = 1.0;
  unsigned threads = 0;
};

bool parse_numbers(const std::string& s, std::vector<double>& v)
{
  v.clear();
  for (const std::string& item : split_list(s)) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(x)) return false;
    v.push_back(x);
  }
  return true;
}

// Runs `gifsicle -O3 --batch FILE` when gifsicle is installed (it only shrinks the file).
void optimise_gif(const std::string& path)
{
  std::vector<std::string> args = {"gifsicle", "--no-warnings", "-O3", "--batch", path};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, "gifsicle", nullptr, nullptr, argv.data(), environ) != 0) {
    std::fprintf(stderr, "render: gifsicle not found; the GIF is not optimised (tools/setup.sh installs it)\n");
    return;
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) std::fprintf(stderr, "render: gifsicle failed on %s\n", path.c_str());
  // gifsicle --batch replaces the file with one only its owner may read: give it the usual rights.
  std::error_code ec;
  std::filesystem::permissions(path,
                               std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                                   std::filesystem::perms::group_read | std::filesystem::perms::others_read,
                               ec);
}

bool load(const std::string& path, const RenderArgs& a, render::LoadedFrames& l)
{
  std::string error;
  if (render::load_frames(path, a.shapes, a.detail, a.meshes, l, error)) return true;
  std::fprintf(stderr, "render: %s\n", error.c_str());
  return false;
}

std::vector<std::size_t> select(const render::Frames& f, const RenderArgs& a)
{
  std::vector<std::size_t> out;
  const long count = long(f.frames.size());
  if (a.single) {
    long i = a.frame < 0 ? count + a.frame : a.frame;
    i = std::max(0L, std::min(count - 1, i));
    out.push_back(std::size_t(i));
  } else {
    for (long i = 0; i < count; i += a.every) out.push_back(std::size_t(i));
  }
  return out;
}

int run_render(const RenderArgs& a)
{
  int w = 0, h = 0;
  if (std::sscanf(a.size.c_str(), "%dx%d", &w, &h) != 2 || w < 8 || h < 8 || w > 8192 || h > 8192) {
    std::fprintf(stderr, "render: --size must be WxH (8..8192), got '%s'\n", a.size.c_str());
    return 2;
  }
  if (a.out.empty() && a.gif.empty()) {
    std::fprintf(stderr, "render: give --out DIR (or FILE.png for one frame) and/or --gif FILE\n");
    return 2;
  }
  std::vector<render::LoadedFrames> runs(a.side.empty() ? 1 : 2);
  if (!load(a.in, a, runs[0])) return 1;
  if (!a.side.empty() && !load(a.side, a, runs[1])) return 1;

  // Keep only the selected frames: the camera frames exactly what is drawn.
  std::vector<std::vector<std::size_t>> picks;
  for (render::LoadedFrames& l : runs) {
    const std::vector<std::size_t> pick = select(l.frames, a);
    render::Frames kept = l.frames;
    kept.frames.clear();
    for (std::size_t i : pick) kept.frames.push_back(l.frames.frames[i]);
    l.frames = kept;
    picks.push_back(pick);
  }
  render::RenderOptions ro;
  ro.width = w;
  ro.height = h;
  ro.supersample = a.supersample;
  ro.spheres = a.spheres;
  ro.shadows = !a.no_shadows;
  ro.threads = a.threads;

  std::vector<const render::Frames*> all;
  std::vector<std::vector<const render::RenderShape*>> all_shapes;
  for (const render::LoadedFrames& l : runs) {
    all.push_back(&l.frames);
    all_shapes.push_back(l.shapes);
  }
  render::Camera camera;
  std::vector<double> cv;
  if (!parse_numbers(a.camera, cv) || !(cv.empty() || cv.size() == 2 || cv.size() == 3 || cv.size() == 7)) {
    std::fprintf(stderr, "render: --camera takes AZ,EL[,FOV] (degrees) or EX,EY,EZ,TX,TY,TZ,FOV\n");
    return 2;
  }
  if (cv.size() == 7) {
    camera.eye = Eigen::Vector3d(cv[0], cv[1], cv[2]);
    camera.target = Eigen::Vector3d(cv[3], cv[4], cv[5]);
    camera.fov_deg = cv[6];
  } else {
    render::CameraView view;
    if (cv.size() >= 2) {
      view.azimuth_deg = cv[0];
      view.elevation_deg = cv[1];
    }
    if (cv.size() == 3) view.fov_deg = cv[2];
    view.fit_share = a.fit_share;
    camera = render::frame_camera(all, all_shapes, view, double(w) / double(h));
  }
  if (!(camera.fov_deg > 1 && camera.fov_deg < 170)) {
    std::fprintf(stderr, "render: field of view must be in (1, 170) degrees\n");
    return 2;
  }

  const bool one_file = a.out.size() > 4 && a.out.compare(a.out.size() - 4, 4, ".png") == 0;
  const std::size_t count = std::max(runs[0].frames.frames.size(), runs.size() > 1 ? runs[1].frames.frames.size() : 0);
  if (one_file && count != 1) {
    std::fprintf(stderr, "render: --out FILE.png needs exactly one frame (use --frame I); %zu selected\n", count);
    return 2;
  }
  if (!a.out.empty() && !one_file) {
    std::error_code ec;
    std::filesystem::create_directories(a.out, ec);
    if (ec) {
      std::fprintf(stderr, "render: cannot create %s: %s\n", a.out.c_str(), ec.message().c_str());
      return 1;
    }
  }
  const std::vector<std::string> labels = split_list(a.labels);
  std::vector<render::Image> gif_frames;
  Progress progress("render", count);
  double seconds = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<render::Image> panels;
    for (const render::LoadedFrames& l : runs) {
      const render::Frame& f = l.frames.frames[std::min(k, l.frames.frames.size() - 1)];
      panels.push_back(render::render_frame(f, l.shapes, camera, ro));
    }
    render::Image img = panels.size() == 1 ? panels[0]
                                           : render::side_by_side(panels[0], panels[1], labels.size() > 0 ? labels[0] : "",
                                                                  labels.size() > 1 ? labels[1] : "");
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!a.out.empty()) {
      std::string path = a.out;
      if (!one_file) {
        char name[64];
        std::snprintf(name, sizeof name, "/frame_%05zu.png", picks[0][std::min(k, picks[0].size() - 1)]);
        path += name;
      }
      if (!render::write_png(path, img)) {
        std::fprintf(stderr, "render: cannot write %s\n", path.c_str());
        return 1;
      }
    }
    if (!a.gif.empty()) gif_frames.push_back(std::move(img));
    progress.add();
  }
  progress.finish();
  if (!a.gif.empty()) {
    std::string error;
    if (!render::write_gif(a.gif, gif_frames, a.gif_delay, error)) {
      std::fprintf(stderr, "render: %s\n", error.c_str());
      return 1;
    }
    optimise_gif(a.gif);
  }
  std::printf("render: %zu frame(s) of %zu bodies, %dx%d%s, %.3f s per frame (rendering only)\n", count,
              runs[0].frames.frames.empty() ? std::size_t(0) : runs[0].frames.frames.back().bodies.size(),
              runs.size() > 1 ? 2 * w : w, h, runs.size() > 1 ? " side by side" : "", seconds / double(count));
  std::printf("  camera: eye (%.3f, %.3f, %.3f), target (%.3f, %.3f, %.3f), fov %.1f deg%s\n", camera.eye.x(),
              camera.eye.y(), camera.eye.z(), camera.target.x(), camera.target.y(), camera.target.z(), camera.fov_deg,
              camera.orthographic ? " (orthographic)" : "");
  return 0;
}

}  // namespace

void register_render_commands(CLI::App& app)
{
  auto a = std::make_shared<RenderArgs>();
  a->meshes = render::default_meshes_dir();
  CLI::App* r = app.add_subcommand("render", "Draw a frame file as PNG frames (and a GIF): shaded shapes on the ground");
  r->add_option("--in", a->in, "frame file (CSV: frame,time,body,shape,x,y,z,qw,qx,qy,qz,state[,radius])")->required();
  r->add_option("--out", a->out, "directory for frame_NNNNN.png, or FILE.png when one frame is drawn");
  r->add_option("--every", a->every, "draw every k-th frame of the file")->check(CLI::Range(1, 1000000));
  r->add_option("--frame", a->frame, "draw only frame I of the file (0 first, -1 last)")
      ->each([a](const std::string&) { a->single = true; });
  r->add_option("--size", a->size, "image size WxH (each panel's with --side-by-side)")->capture_default_str();
  r->add_option("--camera", a->camera,
                "AZ,EL[,FOV]: default camera's azimuth, elevation, field of view (deg; default -60,25,35), "
                "or EX,EY,EZ,TX,TY,TZ,FOV: eye, target (m), field of view");
  r->add_option("--fit", a->fit_share, "share of the bodies the default camera fits (nearest their median; 1: all)")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  r->add_option("--gif", a->gif, "also write an animated GIF of the drawn frames (giflib; gifsicle -O3 if installed)");
  r->add_option("--gif-delay", a->gif_delay, "GIF frame time, 1/100 s")->check(CLI::Range(1, 1000))->capture_default_str();
  r->add_option("--side-by-side", a->side, "a second frame file drawn on the right (same camera; paper Figure 8)");
  r->add_option("--labels", a->labels, "labels of the left and right panels")->capture_default_str();
  r->add_flag("--spheres", a->spheres, "draw the collision spheres, translucent (paper Figure 7)");
  r->add_flag("--no-shadows", a->no_shadows, "no contact shadows under the bodies");
  r->add_option("--shapes", a->shapes, "names of numeric shape ids 0,1,... (files that store ids)");
  r->add_option("--detail", a->detail, "bunny mesh: full, low (bunny_low.obj) or auto (low above 1,000 bodies)")
      ->check(CLI::IsMember({"auto", "full", "low"}))
      ->capture_default_str();
  r->add_option("--supersample", a->supersample, "samples per pixel along each axis")->check(CLI::Range(1, 4))->capture_default_str();
  r->add_option("--threads", a->threads, "threads (0: all cores); the images do not depend on it");
  r->add_option("--meshes", a->meshes, "directory of the shape meshes")->capture_default_str();
  r->callback([a]() {
    const int rc = run_render(*a);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });

  auto o = std::make_shared<render::ReferenceRunOptions>();
  o->meshes_dir = render::default_meshes_dir();
  CLI::App* rr = app.add_subcommand("reference-run", "Run a shared scene with Bullet or statsim and write its frame file");
  rr->add_option("--scene", o->scene, "bunniesN: N bunnies dropped from the shared cylinder (tools/scenes)")->capture_default_str();
  rr->add_option("--engine", o->engine, "bullet (full mesh) or statsim (tables/bunny.hpp)")
      ->check(CLI::IsMember({"bullet", "statsim"}))
      ->capture_default_str();
  rr->add_option("--frames", o->frames, "frame file to write")->required();
  rr->add_option("--seconds", o->seconds, "simulated seconds")->check(CLI::PositiveNumber)->capture_default_str();
  rr->add_option("--every", o->every, "write every k-th step of 1/60 s")->check(CLI::Range(1, 100000))->capture_default_str();
  rr->add_option("--seed", o->seed, "scene seed")->capture_default_str();
  rr->add_option("--substeps", o->substeps, "Bullet: internal steps per step of 1/60 s (16: 1/960 s, the converged step)")
      ->capture_default_str();
  rr->add_option("--meshes", o->meshes_dir, "directory of the meshes")->capture_default_str();
  rr->add_option("--body-contacts", o->hull_contacts,
                 "statsim: where bodies touch each other, hulls (the library's default, as statsim bench and fidelity "
                 "run them) or spheres (the paper's collision spheres)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, bool>{{"hulls", true}, {"spheres", false}}))
      ->default_str("hulls");
  rr->callback([o]() {
    std::string error;
    if (!render::reference_run(*o, error)) {
      std::fprintf(stderr, "reference-run: %s\n", error.c_str());
      throw CLI::RuntimeError(1);
    }
  });
}

}  // namespace statsim::tools
