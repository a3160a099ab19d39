#pragma once
/// @file
/// Result codes of the runtime. Every call that can fail returns one; a call that fails changes
/// nothing.

#include <cstdint>

namespace statsim {

/// Outcome of a public call.
enum class [[nodiscard]] Status : std::uint8_t {
  ok = 0,
  capacity_exceeded,     ///< the fixed pool is full: raise the world's template capacity
  non_finite,            ///< a position, velocity, mass, radius or gravity was NaN or infinite
  zero_quaternion,       ///< orientation had (near) zero length
  non_unit_quaternion,   ///< orientation length differed from 1 by more than 1e-3
  invalid_time_step,     ///< dt was not finite and positive, or above `limits::time_step` (1 s)
  invalid_plane,         ///< plane normal was zero or not finite, or offset not finite
  invalid_radius,        ///< a radius not positive (in a snapshot: below limits::min_radius, or not a plain sphere's own), or bounding < collision radius
  invalid_mass,          ///< mass was not positive (or 0 with a shape that records none)
  invalid_material,      ///< restitution outside [0, 1] or friction negative
  invalid_shape,         ///< shape id does not name a shape of this world (another world's, or past the end), or a malformed signature
  invalid_body,          ///< body id does not name a body of this world
  invalid_parameter,     ///< a world parameter is out of its documented range
  out_of_range,          ///< a finite value beyond the runtime's limits (`statsim::limits`)
  /// Only from `WorldCore::construction_status()`: this build fuses multiply and add (or keeps
  /// excess precision), so results are valid but not bit-identical to other builds. Compile
  /// with `-ffp-contract=off` (the CMake targets add it).
  float_contraction,
  /// Only from `load`: the bytes are not a snapshot (magic), or are truncated, too long or
  /// damaged (size field, checksum), or hold a value no world can have (see statsim/snapshot.hpp).
  invalid_snapshot,
  /// Only from `load`: a snapshot of another format version, dimension or `Scalar` width, or of
  /// a world with the other broad-phase storage (`World`'s `Phases`).
  snapshot_incompatible,
  /// Only from `load`: the world's shapes differ from the snapshot's (count, order or data).
  shape_mismatch,
  /// The call asks for what the world's `Features` (its template parameter, statsim/features.hpp)
  /// leave out: a statistical shape, hull contacts, a tilted plane, a query; from `load`, a
  /// snapshot of a world with hull contacts or tilted planes.
  not_compiled,
};

/// Short, stable name of a status, for messages ("capacity_exceeded").
constexpr const char* to_string(Status s)
{
  switch (s) {
    case Status::ok: return "ok";
    case Status::capacity_exceeded: return "capacity_exceeded";
    case Status::non_finite: return "non_finite";
    case Status::zero_quaternion: return "zero_quaternion";
    case Status::non_unit_quaternion: return "non_unit_quaternion";
    case Status::invalid_time_step: return "invalid_time_step";
    case Status::invalid_plane: return "invalid_plane";
    case Status::invalid_radius: return "invalid_radius";
    case Status::invalid_mass: return "invalid_mass";
    case Status::invalid_material: return "invalid_material";
    case Status::invalid_shape: return "invalid_shape";
    case Status::invalid_body: return "invalid_body";
    case Status::invalid_parameter: return "invalid_parameter";
    case Status::out_of_range: return "out_of_range";
    case Status::float_contraction: return "float_contraction";
    case Status::invalid_snapshot: return "invalid_snapshot";
    case Status::snapshot_incompatible: return "snapshot_incompatible";
    case Status::shape_mismatch: return "shape_mismatch";
    case Status::not_compiled: return "not_compiled";
  }
  return "unknown";
}

/// Pools that can overflow during a step. `StepResult::overflow` is a bit set of these; each
/// names the template argument to raise.
enum Overflow : std::uint32_t {
  overflow_none = 0,
  /// More candidate pairs than the pair buffer holds: raise the world's `MaxPairs`. The pairs
  /// beyond it were not resolved this step (their count is in `StepResult::pairs_dropped`).
  overflow_pairs = 1u << 0,
  /// More impacts above `WorldDef::impact_threshold` than the impact buffer holds: raise the
  /// world's `MaxImpacts`. The first ones were kept (`StepResult::impacts_dropped` counts the
  /// rest); the simulation is the same either way.
  overflow_impacts = 1u << 1,
};

/// What a call to `step()` did.
struct [[nodiscard]] StepResult {
  Status status = Status::ok;        ///< ok, or invalid_time_step (then nothing was stepped)
  std::uint32_t overflow = overflow_none;  ///< bit set of `Overflow`
  std::uint32_t pairs_found = 0;     ///< candidate pairs from the broad phase (incl. dropped)
  std::uint32_t pairs_dropped = 0;   ///< candidate pairs that did not fit the pair buffer
  std::uint32_t contacts = 0;        ///< body-body and body-plane contacts resolved
  std::uint32_t energy_clamps = 0;   ///< sampled responses the energy guard scaled down
  std::uint32_t statistical_responses = 0;  ///< sampled responses applied (body-plane and body-body)
  std::uint32_t impacts_found = 0;    ///< impacts above the threshold (incl. dropped); 0 without a buffer
  std::uint32_t impacts_dropped = 0;  ///< impacts that did not fit the impact buffer
  /// Work of the step, for tests and profiling: bodies integrated (the awake ones), bodies the
  /// broad phase read, and candidate pairs the grid examined (bounding-sphere tests;
  /// sweep-and-prune does not count its own). A world whose bodies are all asleep does none of it.
  std::uint32_t bodies_integrated = 0;
  std::uint32_t broad_phase_bodies = 0;
  std::uint32_t pairs_examined = 0;
  /// True when the step ran and nothing overflowed.
  constexpr bool ok() const { return status == Status::ok && overflow == overflow_none; }
};

}  // namespace statsim
