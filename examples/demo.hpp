// Shared by the 3D demos: dropping bodies from a cylinder pattern, timing the steps, printing the
// summary, and writing per-frame transforms. Not a demo itself.
//
// Frame files are CSV with the header line
//   frame,time,body,shape,x,y,z,qw,qx,qy,qz,state,radius
// one row per body per written frame: the step, the time after it (s), the body's index, its
// shape's name (the signature's: box, lshape, bunny; sphere for a plain sphere), position in metres (centre of mass, z up),
// orientation as a unit quaternion (body to world), state 0 moving, 1 settling, 2 asleep, and the
// current collision-sphere radius (m). `statsim render` and `statsim export` read these files
// (README "Pictures" documents the format).
#pragma once

#include "statsim/world3.hpp"

#include <chrono>
#include <cmath>
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
};

inline bool parse(int argc, char** argv, Options& o, const char* usage)
{
  for (int i = 1; i < argc; ++i) {
    const bool has = i + 1 < argc;
    if (!std::strcmp(argv[i], "--n") && has) o.n = std::strtol(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--frames") && has) o.frames = argv[++i];
    else if (!std::strcmp(argv[i], "--every") && has) o.every = int(std::strtol(argv[++i], nullptr, 10));
    else if (!std::strcmp(argv[i], "--steps") && has) o.steps = int(std::strtol(argv[++i], nullptr, 10));
    else if (!std::strcmp(argv[i], "--seed") && has) o.seed = std::strtoull(argv[++i], nullptr, 10);
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

/// Drops `n` bodies of `shape` from a cylinder of radius `radius` above the ground, stacked in
/// height (`rise` metres per body), with random orientations, small sideways velocities and
/// spins (paper Figures 1, 5, 6).
inline bool drop_cylinder(WorldCore3& w, ShapeId shape, long n, float radius, float base, float rise, Pcg32& rng)
{
  for (long i = 0; i < n; ++i) {
    BodyDef3 b;
    b.shape = shape;
    const float a = rng.uniform(0, 6.2831853f);
    const float r = radius * std::sqrt(rng.uniform());
    const float z = base + rise * float(i) + rng.uniform(0, rise);
    b.position = Vector3(r * std::cos(a), r * std::sin(a), z);
    const float ax = rng.uniform(-1, 1), ay = rng.uniform(-1, 1), az = rng.uniform(-1, 1);
    const float angle = rng.uniform(0, 3.14159265f);
    const Vector3 axis = Vector3(ax, ay, az).norm() > 1e-3f ? Vector3(ax, ay, az).normalized() : Vector3(0, 0, 1);
    b.orientation = Quaternion(Eigen::AngleAxisf(angle, axis));
    const float vx = rng.uniform(-0.5f, 0.5f), vy = rng.uniform(-0.5f, 0.5f);
    b.linear_velocity = Vector3(vx, vy, 0);
    const float wx = rng.uniform(-5, 5), wy = rng.uniform(-5, 5), wz = rng.uniform(-5, 5);
    b.angular_velocity = Vector3(wx, wy, wz);
    const Status s = w.add_body(b).status;
    if (s != Status::ok) {
      std::fprintf(stderr, "add_body: %s\n", to_string(s));
      return false;
    }
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
    std::fprintf(f, "frame,time,body,shape,x,y,z,qw,qx,qy,qz,state,radius\n");
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
    if (f && s % o.every == 0)
      for (std::uint32_t i = 0; i < w.body_count(); ++i) {
        const Body3& b = w.body(i);
        std::fprintf(f, "%d,%.5f,%u,%s,%.6f,%.6f,%.6f,%.7f,%.7f,%.7f,%.7f,%d,%.6f\n", s, double(s + 1) * double(dt), i,
                     w.shape(b.shape).statistical ? w.shape(b.shape).signature.name : "sphere", double(b.position.x()), double(b.position.y()),
                     double(b.position.z()), double(b.orientation.w()), double(b.orientation.x()),
                     double(b.orientation.y()), double(b.orientation.z()), int(b.state), double(b.radius));
      }
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
    if (b.shape != shape) continue;
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

}  // namespace demo
