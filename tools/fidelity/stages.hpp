// What the stages of `statsim fidelity` share: the methods and how their worlds are built (the
// set-up), and the stage functions fidelity.cpp runs in order (single drops, drop piles, the pile
// scenes, the step time). Internal to tools/fidelity; the command's types are in fidelity.hpp.
#pragma once

#include "bench/bench_internal.hpp"
#include "fidelity/fidelity.hpp"
#include "ref3d/reference.hpp"
#include "ref3d/signature_json.hpp"
#include "scenes/scenes.hpp"
#include "statsim/signature.hpp"

#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace statsim::tools::fidelity {

// A run is at rest once slower than this (centre, and farthest point by spin) for kQuietTime.
constexpr double kQuietSpeed = 0.01;   // m/s
constexpr double kQuietTime = 0.5;     // s

/// The splitmix64 stream seed of run `r` of `seed`.
std::uint64_t mix(std::uint64_t seed, std::uint64_t r);

/// What a method is and how to build its world.
struct MethodSpec {
  std::string name;
  std::string description;
  bool bullet = false;
  bool gather_reference = false;  // tools/ref3d's Bullet world (single drops only)
  std::string bullet_method;  // full, low, hull, spheres7, sphere
  int solver_iterations = 10;  // Bullet's solver iterations per step (statsim bench's worlds)
  SignatureView<3> table{};
  bench::StatsimVariant variant;
  long long table_bytes = -1;
};

struct Setup {
  bench::Body3 body;
  // --mix: the second shape of the mixed scenes and its compiled table (every statistical method
  // takes it for that shape's bodies).
  bench::Body3 mix_body;
  SignatureView<3> mix_table{};
  bool mixed = false;
  SignatureView<3> poses;  // the signature whose rest poses classify every run
  std::vector<LoadedSignature3> loaded;
  std::vector<MethodSpec> methods;
  double radius = 0;
  // --reference gather: the shape as the gathering builds it (same body frame as `body`: both
  // are the mesh's principal frame about its centre of mass) and the gathering's settings.
  std::unique_ptr<ref3d::ShapeModel> model;
  ref3d::ReferenceSettings reference_settings;
};

// The gathering's reference as a bench::Sim of one body (single drops): a Reference of its own,

/// The piles' and scenes' reference: Bullet with the full mesh and statsim bench's settings, its
/// solver at `solver_iterations` per step.
MethodSpec pile_reference_method(int solver_iterations);
/// The set-up of a run: the shape's bodies and tables, and each method to compare.
Setup make_setup(const FidelityOptions& o);
/// The world of method `m` for `scene`, statsim's seeded with `seed`, stepped at `dt`.
std::unique_ptr<bench::Sim> build(const Setup& setup, const MethodSpec& m, const scenes::DropScene3& scene,
                                  std::uint64_t seed, double dt);
/// The gathering's reference settings, one per line (as tables/NAME.hpp's header lists them).
std::vector<std::string> gather_settings_lines(const ref3d::ShapeModel& m, const ref3d::ReferenceSettings& r);
/// Thread CPU ms per step of method `m` on the benchmark scene of `n` bodies.
double measure_step_ms(const Setup& setup, const MethodSpec& m, int n, int steps);

/// The rest configuration of orientation `q`: the nearest rest pose of `sig` within 15 degrees,
/// else the pose count ("other").
int classify(const Eigen::Quaterniond& q, const SignatureView<3>& sig);
/// max(|v|, |w| R) of a body state.
double speed(const scenes::BodyState3& s, double radius);

/// Single drop `stream` of method `m` at `dt`, up to `limit` s; a statsim method's world is
/// seeded with `world_seed`.
DropRun run_single(const Setup& setup, const MethodSpec& m, std::uint64_t stream, double dt, double limit,
                   std::uint64_t world_seed);
/// The drop pile of `seed` of method `m`.
PileRun run_pile(const Setup& setup, const MethodSpec& m, std::uint64_t seed, int count, double dt, double limit,
                 std::uint64_t world_seed);
/// The scene kinds of --scenes in order, "stack" as column and wall.
std::vector<std::string> scene_kinds(const std::vector<std::string>& names);
/// The pile scene `kind` in one line (its set-up, as the report prints it).
std::string scene_description(const Setup& setup, const FidelityOptions& o, const std::string& kind);
/// One run of the pile scene `kind` (heap, bin, column, wall) of `seed`, method `m` at `dt`.
SceneRun run_scene_seed(const Setup& setup, const MethodSpec& m, const FidelityOptions& o, const std::string& kind,
                        std::uint64_t seed, double dt);
/// The pile scenes of --scenes, every method against the reference.
std::vector<SceneResult> run_scenes(const Setup& setup, const FidelityOptions& o, unsigned threads);

}  // namespace statsim::tools::fidelity
