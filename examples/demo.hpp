// Shared by the 3D demos: parsing their options, timing the steps, printing the summary, and
// the main of the plain drop demos. Not a demo itself. The drop pattern and the frame-file
// writer are the project's shared ones (tools/scenes: drop_pattern.hpp, frames.hpp, which
// documents the format that `statsim render` and `statsim export` read).
#pragma once

#include "scenes/drop_pattern.hpp"
#include "scenes/frames.hpp"
#include "statsim/world3.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace demo {

using namespace statsim;

/// Command-line options every demo takes.
struct Options {
  long n = 0;                       ///< bodies (demo default if 0)
  const char* frames = nullptr;     ///< CSV file for per-frame transforms, or none
  int every = 6;                    ///< write every k-th step
  int steps = 60 * 20;              ///< at most this many steps of 1/60 s
  unsigned long long seed = 1;
  bool stop_when_asleep = true;     ///< end the run early once every body sleeps
  bool spheres = false;             ///< --spheres: bodies touch at their collision spheres (the paper's model)
};

/// The world's parameters of a demo: the defaults, the seed, and `--spheres`.
inline WorldDef3 demo_def(const Options& o)
{
  WorldDef3 def;
  def.seed = o.seed;
  if (o.spheres) def.body_contacts = BodyContacts::collision_spheres;
  return def;
}

inline bool parse(int argc, char** argv, Options& o, const char* usage)
{
  for (int i = 1; i < argc; ++i) {
    const bool has = i + 1 < argc;
    if (!std::strcmp(argv[i], "--n") && has) o.n = std::strtol(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--frames") && has) o.frames = argv[++i];
    else if (!std::strcmp(argv[i], "--every") && has) o.every = int(std::strtol(argv[++i], nullptr, 10));
    else if (!std::strcmp(argv[i], "--steps") && has) o.steps = int(std::strtol(argv[++i], nullptr, 10));
    else if (!std::strcmp(argv[i], "--seed") && has) o.seed = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--spheres")) o.spheres = true;
    else {
      std::fprintf(stderr, "usage: %s\n", usage);
      return false;
    }
  }
  if (o.every < 1 || o.steps < 1) {
    std::fprintf(stderr, "usage: %s\n", usage);
    return false;
  }
  return true;
}

/// Steps the world (at most o.steps, stopping early once every body sleeps), writing frames if
/// asked. Returns the mean milliseconds per step, or a negative value on error.
inline double run(WorldCore3& w, const Options& o, int& steps_done)
{
  std::FILE* f = nullptr;
  if (o.frames) {
    f = std::fopen(o.frames, "w");
    if (!f) {
      std::fprintf(stderr, "cannot write %s\n", o.frames);
      return -1;
    }
    statsim::tools::scenes::write_frames_header(f);
  }
  const float dt = 1.0f / 60;
  double seconds = 0;
  steps_done = 0;
  for (int s = 0; s < o.steps && !(o.stop_when_asleep && w.count(MotionState::asleep) == w.body_count()); ++s) {
    const auto t0 = std::chrono::steady_clock::now();
    const StepResult r = w.step(dt);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++steps_done;
    if (r.overflow) std::fprintf(stderr, "step %d: pair buffer overflow, %u pairs dropped\n", s, r.pairs_dropped);
    if (f && s % o.every == 0) statsim::tools::scenes::write_frame(f, w, s, double(s + 1) * double(dt));
  }
  if (f) std::fclose(f);
  return steps_done ? 1e3 * seconds / steps_done : 0;
}

/// Prints steps, time per step, sleepers, and the histogram of final rest poses of one shape
/// (bodies not resting in a pose: on other bodies, or still moving).
inline void summary(const char* name, const WorldCore3& w, ShapeId shape, int steps, double ms)
{
  const SignatureView<3>& sig = w.shape(shape).signature;
  std::uint32_t hist[256] = {}, none = 0, count = 0;
  for (std::uint32_t i = 0; i < w.body_count(); ++i) {
    const Body3& b = w.body(i);
    if (b.shape != shape.index) continue;
    ++count;
    if (b.rest_pose == no_rest_pose || b.state != MotionState::asleep) ++none;
    else ++hist[b.rest_pose];
  }
  std::printf("%s: %u bodies, %d steps of 1/60 s, %.4f ms per step, %u asleep\n", name, count, steps, ms,
              w.count(MotionState::asleep));
  std::printf("  rest poses (body-frame up, table frequency: bodies resting in it):\n");
  for (std::uint32_t p = 0; p < sig.rest.count; ++p) {
    const Vector3 n = sig.rest.normal(p);
    std::printf("    %u (%+.2f %+.2f %+.2f) %4.1f%%: %u\n", p, double(n.x()), double(n.y()), double(n.z()),
                100.0 * double(sig.rest.frequencies[p]), hist[p]);
  }
  std::printf("    on other bodies or not asleep: %u\n", none);
}

/// The demos' scene in the empty world `w` (tools/scenes/drop_pattern.hpp: drop_on_ground):
/// `sig`'s bodies dropped from `drop` onto the ground, from the random stream (def.seed, stream).
/// Sets `shape`; on failure prints the status and returns false.
inline bool drop(const char* name, WorldCore3& w, const WorldDef3& def, const SignatureView<3>& sig,
                 const tools::scenes::CylinderDrop& drop, std::uint64_t stream, ShapeId& shape)
{
  const Added<ShapeId> added = tools::scenes::drop_on_ground(w, def, sig, drop, stream);
  if (!added.ok()) {
    std::fprintf(stderr, "%s: %s\n", name, to_string(added.status));
    return false;
  }
  shape = added.id;
  return true;
}

/// A plain drop demo: its name, its table, and where its bodies fall from.
struct DropDemo {
  const char* name;
  SignatureView<3> signature;
  tools::scenes::CylinderDrop drop;  ///< `count` is the default of --n
};

/// The main of a plain drop demo: parses the options (--n at most the world's capacity), drops
/// the bodies with the seed given, runs and prints the summary. Returns the exit code.
inline int drop_main(int argc, char** argv, WorldCore3& w, const DropDemo& d)
{
  char usage[160];
  std::snprintf(usage, sizeof usage, "%s [--n N<=%u] [--frames FILE.csv] [--every K] [--steps S] [--seed S] [--spheres]",
                d.name, w.body_capacity());
  Options o;
  o.n = d.drop.count;
  if (!parse(argc, argv, o, usage)) return 2;
  if (o.n < 1 || o.n > long(w.body_capacity())) return 2;
  const WorldDef3 def = demo_def(o);
  tools::scenes::CylinderDrop drop = d.drop;
  drop.count = o.n;
  ShapeId shape{};
  if (!demo::drop(d.name, w, def, d.signature, drop, 0, shape)) return 1;
  int steps = 0;
  const double ms = run(w, o, steps);
  if (ms < 0) return 1;
  summary(d.name, w, shape, steps, ms);
  return 0;
}

}  // namespace demo
