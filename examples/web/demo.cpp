// The web page's live scene (examples/web): bodies of one shape poured onto the ground from a
// column above it, in worlds of fixed capacity (10,000 bodies) in static storage. Built to
// WebAssembly (statsim.wasm) it exports the C functions below to the page's script (app.js);
// built for the host with WEB_DEMO_MAIN (web_demo_host) it runs the same scene from the command
// line, so that the page's step times and state hash can be set beside the native ones:
//   web_demo_host [--shape bunny|box|lshape|square] [--n N] [--steps S] [--seed S] [--no-rest] [--warmup W]
// prints "web_demo SHAPE bodies N steps S ms_per_step T asleep A hash 0x...". The timed pour
// follows an untimed one of W steps (default 60), as the page's does: a browser first runs
// WebAssembly from a quickly compiled baseline and swaps in optimised code while it runs.
//
// The pour draws from the runtime's Pcg32 with arithmetic only (no trigonometry, whose library
// rounding differs between the host's libm and emscripten's), so a host build and the wasm build
// compute the same bits.

#include <statsim/config.hpp>
#ifdef __EMSCRIPTEN__
// Eigen's own assertion handler prints through stdio, which the wasm does not link.
#define eigen_assert(x) STATSIM_ASSERT(x)
#define EIGEN_NO_IO
#endif
#include <statsim/world2.hpp>
#include <statsim/world3.hpp>
#include <tables/box.hpp>
#include <tables/bunny.hpp>
#include <tables/lshape.hpp>
#include <tables/square2d.hpp>

#include <cmath>
#include <cstdint>
#include <new>

namespace {

constexpr std::uint32_t capacity = 10000;
// Candidate pairs per body: a bunny's bounding radius is over twice the height it rests at, so
// its piles have many more candidate pairs per body than piles of boxes
// (examples/firmware/README.md).
using World3 = statsim::World3<capacity, 1, 8 * capacity, 1>;
using World2 = statsim::World2<capacity, 3, 3 * capacity, 1>;
World3 world3;
World2 world2;

/// Shapes, in the order of the page's menu.
enum Shape : int { bunny = 0, box = 1, lshape = 2, square = 3 };

/// What the page draws: per body x, y, z, the orientation (quaternion x, y, z, w; in 2D the turn
/// as cos, sin, 0, 0) and the motion state.
float transforms[capacity * 8];

int current = bunny;

const statsim::SignatureView<3> signature3(int shape)
{
  return shape == box ? statsim::tables::box.view() : shape == lshape ? statsim::tables::lshape.view()
                                                                       : statsim::tables::bunny.view();
}

float mass3(int shape)
{
  return shape == box ? statsim::tables::box.mass : shape == lshape ? statsim::tables::lshape.mass
                                                                     : statsim::tables::bunny.mass;
}

/// A point uniform in the unit disc, by rejection from the square around it.
void disc_point(statsim::Pcg32& rng, float& x, float& y)
{
  do {
    x = rng.uniform(-1, 1);
    y = rng.uniform(-1, 1);
  } while (x * x + y * y > 1);
}

/// A uniformly distributed unit quaternion: a point uniform in the 4-ball (by rejection),
/// normalised; points too near the centre are redrawn, as their direction is poorly rounded.
statsim::Quaternion random_orientation(statsim::Pcg32& rng)
{
  for (;;) {
    const float w = rng.uniform(-1, 1);
    const float x = rng.uniform(-1, 1);
    const float y = rng.uniform(-1, 1);
    const float z = rng.uniform(-1, 1);
    const float n2 = w * w + x * x + y * y + z * z;
    if (n2 <= 1 && n2 > 0.01f) return statsim::detail::normalized(statsim::Quaternion(w, x, y, z));
  }
}

/// 3D: a column of radius 0.1 sqrt(n) m over the ground plane (the heap of paper Figure 6), one
/// body per `rise` of height from 0.3 m up.
statsim::Status pour3(int shape, std::uint32_t n, bool rest, std::uint32_t seed)
{
  world3.~World3();
  statsim::WorldDef3 def;
  def.seed = seed;
  def.rest_conditions = rest;
  ::new (static_cast<void*>(&world3)) World3(def);
  const auto added = world3.add_shape(signature3(shape));
  if (!added.ok()) return added.status;
  const statsim::Status ground = world3.add_plane(statsim::Vector3(0, 0, 1), 0).status;
  if (ground != statsim::Status::ok) return ground;
  statsim::Pcg32 rng(seed, 1);
  const float radius = 0.1f * std::sqrt(float(n));
  const float rise = 2.0f / float(n) + 0.0004f;
  for (std::uint32_t i = 0; i < n; ++i) {
    statsim::BodyDef3 b;
    b.shape = added.id;
    float x = 0, y = 0;
    disc_point(rng, x, y);
    const float z = 0.3f + rise * float(i) + rng.uniform(0, rise);
    b.position = statsim::Vector3(radius * x, radius * y, z);
    b.orientation = random_orientation(rng);
    const float vx = rng.uniform(-0.5f, 0.5f);
    const float vy = rng.uniform(-0.5f, 0.5f);
    b.linear_velocity = statsim::Vector3(vx, vy, 0);
    const float wx = rng.uniform(-5, 5);
    const float wy = rng.uniform(-5, 5);
    const float wz = rng.uniform(-5, 5);
    b.angular_velocity = statsim::Vector3(wx, wy, wz);
    b.mass = mass3(shape);
    const statsim::Status s = world3.add_body(b).status;
    if (s != statsim::Status::ok) return s;
  }
  return statsim::Status::ok;
}

/// 2D: unit squares poured into a bin 1.2 sqrt(n) + 2 m wide, one per `rise` of height.
statsim::Status pour2(std::uint32_t n, bool rest, std::uint32_t seed)
{
  world2.~World2();
  statsim::WorldDef2 def;
  def.seed = seed;
  def.rest_conditions = rest;
  ::new (static_cast<void*>(&world2)) World2(def);
  const auto added = world2.add_shape(statsim::tables::square2d.view());
  if (!added.ok()) return added.status;
  const float half = 0.6f * std::sqrt(float(n)) + 1;
  if (!world2.add_plane(statsim::Vector2(0, 1), 0).ok() || !world2.add_plane(statsim::Vector2(1, 0), -half).ok() ||
      !world2.add_plane(statsim::Vector2(-1, 0), -half).ok())
    return statsim::Status::capacity_exceeded;
  statsim::Pcg32 rng(seed, 2);
  const float rise = 1.2f * 4 / (half + 1);
  for (std::uint32_t i = 0; i < n; ++i) {
    statsim::BodyDef2 b;
    b.shape = added.id;
    const float x = rng.uniform(-1, 1);
    const float y = 1 + rise * float(i) + rng.uniform(0, rise);
    b.position = statsim::Vector2((half - 0.75f) * x, y);
    float c = 0, s = 0;
    do {
      c = rng.uniform(-1, 1);
      s = rng.uniform(-1, 1);
    } while (c * c + s * s > 1 || c * c + s * s < 0.01f);
    b.orientation = statsim::detail::normalized(statsim::Rot2{c, s});
    const float vx = rng.uniform(-1, 1);
    b.linear_velocity = statsim::Vector2(vx, 0);
    b.angular_velocity = rng.uniform(-3, 3);
    b.mass = statsim::tables::square2d.mass;
    const statsim::Status st = world2.add_body(b).status;
    if (st != statsim::Status::ok) return st;
  }
  return statsim::Status::ok;
}

statsim::WorldCore3& core3() { return world3; }
statsim::WorldCore2& core2() { return world2; }

}  // namespace

extern "C" {

/// Empties the world and pours `n` bodies (at most 10,000) of `shape` (0 bunny, 1 box, 2 L-shape,
/// 3 2D square), with resting conditions on or off, every random draw from `seed`. Returns 0, or
/// the `statsim::Status` that stopped the pour (the bodies before it stay).
int demo_reset(int shape, std::uint32_t n, int rest_conditions, std::uint32_t seed)
{
  if (shape < bunny || shape > square || n > capacity) return int(statsim::Status::invalid_parameter);
  current = shape;
  const statsim::Status s = shape == square ? pour2(n, rest_conditions != 0, seed) : pour3(shape, n, rest_conditions != 0, seed);
  return int(s);
}

/// Steps the world `count` times by 1/60 s. Returns 0, or the status of the first step that was
/// not ok, or -1 if a step dropped candidate pairs (the pair buffer was too small).
int demo_step(int count)
{
  constexpr float dt = 1.0f / 60;
  for (int i = 0; i < count; ++i) {
    const statsim::StepResult r = current == square ? core2().step(dt) : core3().step(dt);
    if (r.status != statsim::Status::ok) return int(r.status);
    if (r.pairs_dropped) return -1;
  }
  return 0;
}

std::uint32_t demo_body_count() { return current == square ? core2().body_count() : core3().body_count(); }

std::uint32_t demo_asleep()
{
  return current == square ? core2().count(statsim::MotionState::asleep) : core3().count(statsim::MotionState::asleep);
}

/// Halves of `state_hash()`: JavaScript numbers hold 53 bits.
std::uint32_t demo_hash_high()
{
  return std::uint32_t((current == square ? core2().state_hash() : core3().state_hash()) >> 32);
}
std::uint32_t demo_hash_low()
{
  return std::uint32_t(current == square ? core2().state_hash() : core3().state_hash());
}

/// Bounding radius of the current shape, m (what the page draws a body's size from).
float demo_body_size()
{
  return current == square ? core2().shape(statsim::ShapeId(0)).bounding_radius : core3().shape(statsim::ShapeId(0)).bounding_radius;
}

/// Fills the transform buffer (8 floats per body, see `transforms`) and returns its address.
const float* demo_transforms()
{
  const std::uint32_t n = demo_body_count();
  for (std::uint32_t i = 0; i < n; ++i) {
    float* t = transforms + 8 * i;
    if (current == square) {
      const statsim::Body2& b = core2().body(i);
      t[0] = b.position.x();
      t[1] = b.position.y();
      t[2] = 0;
      t[3] = b.orientation.c;
      t[4] = b.orientation.s;
      t[5] = 0;
      t[6] = 0;
      t[7] = float(b.state);
    } else {
      const statsim::Body3& b = core3().body(i);
      t[0] = b.position.x();
      t[1] = b.position.y();
      t[2] = b.position.z();
      t[3] = b.orientation.x();
      t[4] = b.orientation.y();
      t[5] = b.orientation.z();
      t[6] = b.orientation.w();
      t[7] = float(b.state);
    }
  }
  return transforms;
}

}  // extern "C"

#ifdef WEB_DEMO_MAIN
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

int main(int argc, char** argv)
{
  int shape = bunny;
  unsigned long n = capacity, steps = 600, seed = 1, warmup = 60;
  int rest = 1;
  const char* const names[] = {"bunny", "box", "lshape", "square"};
  for (int i = 1; i < argc; ++i) {
    const bool has = i + 1 < argc;
    if (!std::strcmp(argv[i], "--shape") && has) {
      const char* s = argv[++i];
      shape = -1;
      for (int k = 0; k < 4; ++k)
        if (!std::strcmp(s, names[k])) shape = k;
    } else if (!std::strcmp(argv[i], "--n") && has) n = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--steps") && has) steps = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--seed") && has) seed = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--warmup") && has) warmup = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--no-rest")) rest = 0;
    else shape = -1;
    if (shape < 0) {
      std::fprintf(stderr, "usage: web_demo_host [--shape bunny|box|lshape|square] [--n N<=10000] [--steps S] [--seed S] [--no-rest] "
                   "[--warmup W]\n");
      return 2;
    }
  }
  if (n > capacity || demo_reset(shape, std::uint32_t(n), rest, std::uint32_t(seed)) != 0 ||
      demo_step(int(warmup)) != 0 || demo_reset(shape, std::uint32_t(n), rest, std::uint32_t(seed)) != 0) {
    std::fprintf(stderr, "web_demo_host: could not pour %lu bodies\n", n);
    return 1;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const int status = demo_step(int(steps));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (status != 0) {
    std::fprintf(stderr, "web_demo_host: step failed (%d)\n", status);
    return 1;
  }
  std::printf("web_demo %s bodies %u steps %lu ms_per_step %.3f asleep %u hash 0x%08x%08x\n", names[shape],
              demo_body_count(), steps, steps ? ms / double(steps) : 0.0, demo_asleep(), demo_hash_high(),
              demo_hash_low());
  return 0;
}
#endif
