// Firmware example: a 3D world of boxes (or L-shapes, or bunnies) and a 2D world of squares from
// the committed tables, and a small 3D world of the other response models, each stepped
// FIRMWARE_STEPS times, then one line per world with the step
// count and the FNV-1a hash of its whole state (`state_hash()`: positions, orientations,
// velocities, sleep states, random streams). The same file builds for the host (firmware_host)
// and, with startup.cpp and mps2-an386.ld, for a Cortex-M4F under QEMU (see CMakeLists.txt here),
// and for WebAssembly (examples/web: hash.wasm, hash_i16.wasm); all must print the same lines,
// bit for bit.
//
// Build-time choices (-D...): FIRMWARE_BODIES (bodies per world, 64), FIRMWARE_STEPS (2000),
// FIRMWARE_SHAPE (0 box, 1 L-shape, 2 bunny), FIRMWARE_I16 (1: response tables as 16-bit
// integers, quantised at compile time by `statsim::quantize16`, the rule of `statsim gather --precision i16`).
// FIRMWARE_SNAPSHOT (1; 0 for the footprint variants): the snapshot round trip below.
// FIRMWARE_FEATURES (0: `Features::all`, the default; 1: `Features::piles`, the smallest set that
// covers these scenes with the library's default hull contacts): what the worlds' steps are
// compiled with (statsim/features.hpp); the hashes are the same either way. FIRMWARE_ONLY3 (0; 1
// needs FIRMWARE_SNAPSHOT=0): the 3D world alone, as a program that steps one scene of one shape
// would be.
// FIRMWARE_TRACE (defined): also print the hash after every step. STATSIM_FIRMWARE is defined by
// the Cortex-M build, STATSIM_WEB by the WebAssembly build.
//
// Snapshots (statsim/snapshot.hpp): the 3D and 2D worlds are saved while their bodies land
// (saving reads the world only: the run and its hashes are the same), and after the run each is
// loaded back from its snapshot and stepped `continued` steps; the snapshot is printed in hex
// ("snap3 data ...") with the hash of its continuation ("snap3 continued ..."). The host build
// given such output (`firmware_host --snapshots FILE`) loads those bytes into its own worlds,
// steps as many steps and prints its hashes: compare.cmake checks that they are the firmware's.

#include <statsim/config.hpp>
#if defined(STATSIM_FIRMWARE) || defined(STATSIM_WEB)
// Eigen's own assertion handler prints through stdio: route its checks to statsim's handler.
#define eigen_assert(x) STATSIM_ASSERT(x)
#define EIGEN_NO_IO
#endif
#include <statsim/snapshot.hpp>
#include <statsim/world2.hpp>
#include <statsim/world3.hpp>
#include <tables/square2d.hpp>
#include <tools/scenes/synthetic_signatures.hpp>

#ifndef FIRMWARE_BODIES
#define FIRMWARE_BODIES 64
#endif
#ifndef FIRMWARE_STEPS
#define FIRMWARE_STEPS 2000
#endif
#ifndef FIRMWARE_SHAPE
#define FIRMWARE_SHAPE 0
#endif
#ifndef FIRMWARE_I16
#define FIRMWARE_I16 0
#endif
#ifndef FIRMWARE_SNAPSHOT
#define FIRMWARE_SNAPSHOT 1
#endif
#ifndef FIRMWARE_FEATURES
#define FIRMWARE_FEATURES 0
#endif
#ifndef FIRMWARE_ONLY3
#define FIRMWARE_ONLY3 0
#endif
#if FIRMWARE_ONLY3 && FIRMWARE_SNAPSHOT
#error "FIRMWARE_ONLY3 needs FIRMWARE_SNAPSHOT=0"
#endif

#if FIRMWARE_SHAPE == 0
#include <tables/box.hpp>
#define FIRMWARE_TABLE statsim::tables::box
#elif FIRMWARE_SHAPE == 1
#include <tables/lshape.hpp>
#define FIRMWARE_TABLE statsim::tables::lshape
#elif FIRMWARE_SHAPE == 2
#include <tables/bunny.hpp>
#define FIRMWARE_TABLE statsim::tables::bunny
#else
#error "FIRMWARE_SHAPE must be 0 (box), 1 (L-shape) or 2 (bunny)"
#endif
#if FIRMWARE_FEATURES == 0
#define FIRMWARE_FEATURE_SET statsim::Features::all
#elif FIRMWARE_FEATURES == 1
#define FIRMWARE_FEATURE_SET statsim::Features::piles
#else
#error "FIRMWARE_FEATURES must be 0 (all) or 1 (piles)"
#endif

#include <cstdint>

// ---- platform: output and failure (startup.cpp on the Cortex-M, stdio on the host) -------------
#ifdef STATSIM_FIRMWARE
namespace platform {
void write(const char* text);
[[noreturn]] void fail();
std::uint64_t clock_ticks();  ///< SysTick counts at 25 MHz; 40 instructions each under -icount shift=0
std::uint32_t stack_used();   ///< high-water mark, bytes
std::uint32_t stack_size();   ///< bytes
}  // namespace platform
#elif defined(STATSIM_WEB)
// WebAssembly (examples/web): the page or Node gives the output function as an import.
extern "C" __attribute__((import_module("env"), import_name("statsim_write"))) void statsim_web_write(const char* text);
namespace platform {
void write(const char* text) { statsim_web_write(text); }
[[noreturn]] void fail() { __builtin_trap(); }
}  // namespace platform
#else
#include <cstdio>
#include <cstdlib>
#include <cstring>
namespace platform {
void write(const char* text) { std::fputs(text, stdout); }
[[noreturn]] void fail() { std::exit(1); }
}  // namespace platform
#endif

namespace {

constexpr std::uint32_t bodies = FIRMWARE_BODIES;
constexpr int steps = FIRMWARE_STEPS;
constexpr statsim::Scalar dt = statsim::Scalar(1) / 60;
// Candidate pairs per body (with the default hull contacts the broad phase pairs the bounding
// spheres, `detail::pair_radius`), each shape's measured peak with a margin of a third or more
// (examples/firmware/README.md). A step reports an overflow, and this program then fails.
constexpr std::uint32_t pairs3 = (FIRMWARE_SHAPE == 0 ? 25 * bodies / 4 : (FIRMWARE_SHAPE == 1 ? 6 : 8) * bodies);
constexpr std::uint32_t pairs2 = 7 * bodies / 2;
// Scenes that grow with the body count: columns of bodies four high in 3D (k x k columns, k a
// multiple of 4) and eight high in 2D.
constexpr std::uint32_t grid_side(std::uint32_t n, std::uint32_t height, std::uint32_t step, std::uint32_t power)
{
  std::uint32_t k = step;
  while ((power == 2 ? k * k : k) * height < n) k += step;
  return k;
}
constexpr std::uint32_t columns3 = grid_side(bodies, 4, 4, 2);
constexpr std::uint32_t columns2 = grid_side(bodies, 8, 8, 1);

#if FIRMWARE_I16
// Quantised at compile time (a committed table already in 16 bits is kept as it is): only the
// 16-bit tables are in the image.
constexpr auto table3 = statsim::quantize16(FIRMWARE_TABLE);
constexpr auto table2 = statsim::quantize16(statsim::tables::square2d);
constexpr auto correlated = statsim::quantize16(statsim::testing::cube_correlated_synthetic);
constexpr auto empirical = statsim::quantize16(statsim::testing::cube_empirical_synthetic);
constexpr auto energy = statsim::quantize16(statsim::testing::cube_energy_synthetic);
constexpr const char* precision = "i16";
#else
// Float tables, also from a committed table in 16 bits, so that both builds step both paths.
constexpr auto table3 = statsim::dequantize(FIRMWARE_TABLE);
constexpr const auto& table2 = statsim::tables::square2d;
constexpr const auto& correlated = statsim::testing::cube_correlated_synthetic;
constexpr const auto& empirical = statsim::testing::cube_empirical_synthetic;
constexpr const auto& energy = statsim::testing::cube_energy_synthetic;
constexpr const char* precision = "f32";
#endif
// The committed tables hold the default response model and spin measure; a small third world
// steps the others (hand-made cubes, tools/scenes/synthetic_signatures.hpp: the correlated and
// empirical models, and the spin by energy of a body with unequal moments) so that every
// sampler is compared.
constexpr std::uint32_t model_bodies = 16;

// ---- output without printf (newlib's printf allocates) -------------------------------------------
class Line {
 public:
  Line& text(const char* s)
  {
    while (*s && n_ + 1 < sizeof buf_) buf_[n_++] = *s++;
    return *this;
  }
  Line& dec(std::uint64_t v)
  {
    // Long division by 10 over 16-bit pieces, in 32-bit arithmetic: a 64-bit division would link
    // libgcc's __udivmoddi4, as much code as a phase of the step.
    std::uint32_t piece[4] = {std::uint32_t(v >> 48), std::uint32_t(v >> 32) & 0xffffu, std::uint32_t(v >> 16) & 0xffffu,
                              std::uint32_t(v) & 0xffffu};
    char digits[20];
    int k = 0;
    do {
      std::uint32_t rest = 0;
      for (std::uint32_t& p : piece) {
        const std::uint32_t x = rest << 16 | p;
        p = x / 10;
        rest = x % 10;
      }
      digits[k++] = char('0' + rest);
    } while (piece[0] | piece[1] | piece[2] | piece[3]);
    while (k > 0 && n_ + 1 < sizeof buf_) buf_[n_++] = digits[--k];
    return *this;
  }
  Line& hex(std::uint64_t v)
  {
    text("0x");
    for (int shift = 60; shift >= 0 && n_ + 1 < sizeof buf_; shift -= 4) buf_[n_++] = "0123456789abcdef"[(v >> shift) & 0xfu];
    return *this;
  }
  void emit()
  {
    buf_[n_++] = '\n';
    buf_[n_] = '\0';
    platform::write(buf_);
    n_ = 0;
  }

 private:
  char buf_[200];
  std::size_t n_ = 0;
};

void on_assert(const char* expression, const char* file, int line)
{
  Line().text("assertion failed: ").text(expression).text(" at ").text(file).text(":").dec(std::uint64_t(line)).emit();
  platform::fail();
}

// The worlds live in static storage: constructed by the start-up code before main, no heap.
// Up to `WorldDef::grid_above_bodies` (2,048 by default) bodies a world sweeps, so these keep
// storage for sweep-and-prune only.
constexpr statsim::BroadPhase sweep_only = statsim::BroadPhase::sweep_and_prune;
constexpr statsim::Features features = FIRMWARE_FEATURE_SET;
statsim::World3<bodies, 8, pairs3, 2, 0, sweep_only, features> world3;
#if !FIRMWARE_ONLY3
statsim::World2<bodies, 8, pairs2, 2, 0, sweep_only, features> world2;
statsim::World3<model_bodies, 1, 4 * model_bodies, 3, 0, sweep_only, features> world_models;
#endif

#if FIRMWARE_SNAPSHOT
// Snapshot buffers, sized for any snapshot of these worlds.
constexpr int continued = 120;
constexpr int snapshot_step = steps >= 90 ? 45 : steps / 2;  // 0.75 s: the first bodies are landing
unsigned char snapshot3[statsim::snapshot_capacity<3>(bodies, 8, 2)];
unsigned char snapshot2[statsim::snapshot_capacity<2>(bodies, 8, 2)];
std::size_t snapshot3_size = 0, snapshot2_size = 0;
#endif

/// A unit quaternion from four uniform draws (normalising a random 4-vector; no trigonometry).
statsim::Quaternion random_orientation(statsim::Pcg32& rng)
{
  const float w = rng.uniform(-1, 1);
  const float x = rng.uniform(-1, 1);
  const float y = rng.uniform(-1, 1);
  const float z = rng.uniform(-1, 1);
  return statsim::detail::normalized(statsim::Quaternion(w + 2, x, y, z));
}

bool build_world3()
{
  const auto shape = world3.add_shape(table3.view());
  if (!shape.ok()) return false;
  using statsim::Vector3;
  // A bin open at the top, 0.3 m per column of bodies: k x k columns, four bodies high (64 bodies:
  // 4 x 4 columns in 1.2 x 1.2 m), piling about two deep.
  const float half = 0.15f * float(columns3);
  const bool planes = world3.add_plane(Vector3(0, 0, 1), 0).ok() && world3.add_plane(Vector3(1, 0, 0), -half).ok() &&
                      world3.add_plane(Vector3(-1, 0, 0), -half).ok() && world3.add_plane(Vector3(0, 1, 0), -half).ok() &&
                      world3.add_plane(Vector3(0, -1, 0), -half).ok();
  if (!planes) return false;
  statsim::Pcg32 rng(7, 3);
  for (std::uint32_t i = 0; i < bodies; ++i) {
    statsim::BodyDef3 def;
    def.shape = shape.id;
    const std::uint32_t cx = i % columns3, cy = (i / columns3) % columns3, layer = i / (columns3 * columns3);
    def.position = Vector3(0.15f - half + 0.3f * float(cx), 0.15f - half + 0.3f * float(cy), 0.5f + 0.4f * float(layer));
    def.orientation = random_orientation(rng);
    const float vx = rng.uniform(-1, 1);
    const float vy = rng.uniform(-1, 1);
    const float wx = rng.uniform(-5, 5);
    const float wy = rng.uniform(-5, 5);
    const float wz = rng.uniform(-5, 5);
    def.linear_velocity = Vector3(vx, vy, 0);
    def.angular_velocity = Vector3(wx, wy, wz);
    def.mass = table3.mass;
    if (!world3.add_body(def).ok()) return false;
  }
  return true;
}

#if !FIRMWARE_ONLY3
bool build_world2()
{
  const auto shape = world2.add_shape(table2.view());
  if (!shape.ok()) return false;
  using statsim::Vector2;
  // A bin 1.25 m wide per column of 1 m squares, the columns eight squares high (64 bodies:
  // 8 columns in 10 m), piling about six deep.
  const float half = 0.625f * float(columns2);
  if (!world2.add_plane(Vector2(0, 1), 0).ok() || !world2.add_plane(Vector2(1, 0), -half).ok() ||
      !world2.add_plane(Vector2(-1, 0), -half).ok())
    return false;
  statsim::Pcg32 rng(7, 2);
  for (std::uint32_t i = 0; i < bodies; ++i) {
    statsim::BodyDef2 def;
    def.shape = shape.id;
    def.position = Vector2(0.8f - half + 1.2f * float(i % columns2), 1.0f + 1.6f * float(i / columns2));
    const float c = rng.uniform(-1, 1);
    const float s = rng.uniform(-1, 1);
    def.orientation = statsim::detail::normalized(statsim::Rot2{c + 1.5f, s});
    const float vx = rng.uniform(-2, 2);
    const float w = rng.uniform(-6, 6);
    def.linear_velocity = Vector2(vx, 0);
    def.angular_velocity = w;
    def.mass = table2.mass;
    if (!world2.add_body(def).ok()) return false;
  }
  return true;
}

bool build_world_models()
{
  const auto a = world_models.add_shape(correlated.view());
  const auto b = world_models.add_shape(empirical.view());
  const auto c = world_models.add_shape(energy.view());
  if (!a.ok() || !b.ok() || !c.ok() || !world_models.add_plane(statsim::Vector3(0, 0, 1), 0).ok()) return false;
  statsim::Pcg32 rng(7, 4);
  for (std::uint32_t i = 0; i < model_bodies; ++i) {
    statsim::BodyDef3 def;
    def.shape = i % 3 == 0 ? a.id : (i % 3 == 1 ? b.id : c.id);
    def.position = statsim::Vector3(0.3f * float(i % 4), 0.3f * float(i / 4), 0.3f + 0.1f * float(i % 3));
    def.orientation = random_orientation(rng);
    const float wx = rng.uniform(-5, 5);
    const float wy = rng.uniform(-5, 5);
    def.angular_velocity = statsim::Vector3(wx, wy, 0);
    if (!world_models.add_body(def).ok()) return false;
  }
  return true;
}
#endif  // !FIRMWARE_ONLY3

/// Steps a world and prints its line; returns false if a step failed or dropped pairs.
template <class World>
bool run(World& world, const char* label, const char* table, unsigned char* snapshot = nullptr,
         std::size_t snapshot_cap = 0, std::size_t* snapshot_size = nullptr)
{
  std::uint64_t dropped = 0;
  std::uint32_t peak_pairs = 0;
  bool ok = true;
#ifdef STATSIM_FIRMWARE
  const std::uint64_t t0 = platform::clock_ticks();
#endif
  for (int i = 0; i < steps; ++i) {
    const statsim::StepResult r = world.step(dt);
    ok = ok && r.status == statsim::Status::ok;
    dropped += r.pairs_dropped;
    peak_pairs = r.pairs_found > peak_pairs ? r.pairs_found : peak_pairs;
#if FIRMWARE_SNAPSHOT
    if (snapshot != nullptr && i + 1 == snapshot_step)
      ok = ok && statsim::save(world, snapshot, snapshot_cap, snapshot_size) == statsim::Status::ok;
#else
    (void)snapshot;
    (void)snapshot_cap;
    (void)snapshot_size;
#endif
#ifdef FIRMWARE_TRACE
    // To find where two builds part: the hash after every step.
    Line().text(label).text(" step ").dec(std::uint64_t(i + 1)).text(" hash ").hex(world.state_hash()).emit();
#endif
  }
#ifdef STATSIM_FIRMWARE
  const std::uint64_t ticks = platform::clock_ticks() - t0;
#endif
  Line()
      .text(label)
      .text(" ")
      .text(table)
      .text(" ")
      .text(precision)
      .text(" bodies ")
      .dec(world.body_count())
      .text(" steps ")
      .dec(world.step_count())
      .text(" asleep ")
      .dec(world.count(statsim::MotionState::asleep))
      .text(" peak_pairs ")
      .dec(peak_pairs)
      .text(" dropped ")
      .dec(dropped)
      .text(" hash ")
      .hex(world.state_hash())
      .emit();
#ifdef STATSIM_FIRMWARE
  Line().text("firmware: ").text(label).text(" systick ").dec(ticks).text(" steps ").dec(std::uint64_t(steps)).emit();
#endif
  return ok && dropped == 0;
}

#if FIRMWARE_SNAPSHOT
/// Loads a snapshot into `world` (built with the same shapes), steps it `continued` times and
/// prints its hash; with `print_data`, first the snapshot in hex, 64 bytes a line.
template <class World>
bool continue_snapshot(World& world, const char* label, const unsigned char* data, std::size_t size, bool print_data)
{
  for (std::size_t at = 0; print_data && at < size; at += 64) {
    Line line;
    line.text(label).text(" data ");
    for (std::size_t k = at; k < size && k < at + 64; ++k) {
      const char digits[3] = {"0123456789abcdef"[data[k] >> 4], "0123456789abcdef"[data[k] & 15u], '\0'};
      line.text(digits);
    }
    line.emit();
  }
  const statsim::Status s = statsim::load(world, data, size);
  if (s != statsim::Status::ok) {
    Line().text(label).text(" load failed: ").text(statsim::to_string(s)).emit();
    return false;
  }
  const std::uint64_t from = world.step_count();
  const std::uint32_t asleep = world.count(statsim::MotionState::asleep);
  bool ok = true;
  for (int i = 0; i < continued; ++i) ok = ok && world.step(dt).ok();
  Line().text(label).text(" continued from step ").dec(from).text(" asleep ").dec(asleep).text(" steps ").dec(std::uint64_t(continued)).text(" hash ").hex(world.state_hash()).emit();
  return ok;
}

#if !defined(STATSIM_FIRMWARE) && !defined(STATSIM_WEB)
/// The bytes of the lines "LABEL data HEX" of a firmware's output, into `out`; their count.
std::size_t read_snapshot(const char* path, const char* label, unsigned char* out, std::size_t cap)
{
  std::FILE* f = std::fopen(path, "r");
  if (f == nullptr) return 0;
  char text[512];
  char prefix[32] = {};
  std::size_t n = 0, p = 0;
  while (label[p] != '\0' && p + 7 < sizeof prefix) {
    prefix[p] = label[p];
    ++p;
  }
  for (const char* t = " data "; *t; ++t) prefix[p++] = *t;
  const auto hex = [](char c) { return c <= '9' ? c - '0' : c - 'a' + 10; };
  while (std::fgets(text, sizeof text, f) != nullptr) {
    const char* at = std::strstr(text, prefix);
    if (at == nullptr) continue;
    for (at += p; at[0] && at[1] && at[0] != '\n' && n < cap; at += 2) out[n++] = static_cast<unsigned char>(hex(at[0]) * 16 + hex(at[1]));
  }
  std::fclose(f);
  return n;
}
#endif
#endif  // FIRMWARE_SNAPSHOT

}  // namespace

#if !defined(STATSIM_FIRMWARE) && !defined(STATSIM_WEB)
int main(int argc, char** argv)
#else
int main()
#endif
{
  statsim::set_assert_handler(&on_assert);
#if FIRMWARE_ONLY3
  if (!build_world3()) {
#else
  if (!build_world3() || !build_world2() || !build_world_models()) {
#endif
    Line().text("firmware: could not build the worlds").emit();
    return 1;
  }
#if FIRMWARE_SNAPSHOT && !defined(STATSIM_FIRMWARE) && !defined(STATSIM_WEB)
  // The host continues another build's snapshots: a file of its output.
  if (argc == 3 && std::strcmp(argv[1], "--snapshots") == 0) {
    snapshot3_size = read_snapshot(argv[2], "snap3", snapshot3, sizeof snapshot3);
    snapshot2_size = read_snapshot(argv[2], "snap2", snapshot2, sizeof snapshot2);
    const bool ok = continue_snapshot(world3, "snap3", snapshot3, snapshot3_size, false) &&
                    continue_snapshot(world2, "snap2", snapshot2, snapshot2_size, false);
    return ok ? 0 : 1;
  }
#elif !defined(STATSIM_FIRMWARE) && !defined(STATSIM_WEB)
  (void)argc;
  (void)argv;
#endif
#if FIRMWARE_SNAPSHOT
  const bool ok3 = run(world3, "world3", table3.name, snapshot3, sizeof snapshot3, &snapshot3_size);
  const bool ok2 = run(world2, "world2", table2.name, snapshot2, sizeof snapshot2, &snapshot2_size);
  const bool ok_models = run(world_models, "models", "cube_correlated_empirical_energy");
  const bool ok_snapshots = continue_snapshot(world3, "snap3", snapshot3, snapshot3_size, true) &&
                            continue_snapshot(world2, "snap2", snapshot2, snapshot2_size, true);
#elif FIRMWARE_ONLY3
  const bool ok3 = run(world3, "world3", table3.name);
  const bool ok2 = true, ok_models = true, ok_snapshots = true;
#else
  const bool ok3 = run(world3, "world3", table3.name);
  const bool ok2 = run(world2, "world2", table2.name);
  const bool ok_models = run(world_models, "models", "cube_correlated_empirical_energy");
  const bool ok_snapshots = true;
#endif
#ifdef STATSIM_FIRMWARE
  Line().text("firmware: stack used ").dec(platform::stack_used()).text(" of ").dec(platform::stack_size()).text(" bytes").emit();
#endif
  return ok3 && ok2 && ok_models && ok_snapshots ? 0 : 1;
}
