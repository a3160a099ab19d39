#pragma once
/// @file
/// `detail::WorldStorage`: every array of a `World<>`, sized by its template arguments.

#include "statsim/detail/events.hpp"
#include "statsim/detail/world_data.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace statsim {
namespace detail {

static_assert(body_index_bits <= 24, "Pair::b holds a body index in 24 bits");

/// Storage of a World, a base class so that it is constructed before the core that points into it.
template <int D, std::uint32_t MaxBodies, std::uint32_t MaxPlanes, std::uint32_t MaxPairs, std::uint32_t MaxShapes,
          std::uint32_t MaxImpacts, BroadPhase Phases>
struct WorldStorage {
  static constexpr bool grid = Phases != BroadPhase::sweep_and_prune;
  static constexpr std::size_t broad_phase_bytes =
      grid ? BroadPhaseLayout<D>::bytes(MaxBodies) : sizeof(SweepEntry) * std::size_t(MaxBodies);
  std::array<Body<D>, MaxBodies> body_store;
  alignas(16) std::array<unsigned char, broad_phase_bytes> broad_phase_store;
  std::array<Pair, MaxPairs> pair_store;
  // Room for the touching pairs of a pile (tools/bench/README.md counts them); beyond it, contacts
  // are found afresh in every pass.
  static constexpr std::uint32_t pair_hulls = 2 * MaxBodies < MaxPairs ? 2 * MaxBodies : MaxPairs;
  std::array<PairHull<D>, STATSIM_HULL_CACHE ? pair_hulls : 0> pair_hull_store;
  std::array<Plane<D>, MaxPlanes> plane_store;
  std::array<Shape<D>, MaxShapes> shape_store;
  std::array<std::uint32_t, bit_words(MaxBodies)> awake_store;
  std::array<std::uint32_t, bit_words(MaxBodies)> flagged_store;
  std::array<std::uint32_t, bit_words(MaxBodies)> rolled_store;
  std::array<std::uint32_t, bit_words(MaxBodies)> hull_ground_store;
  std::array<std::uint32_t, bit_words(MaxBodies)> paired_store;
  std::array<Impact<D>, MaxImpacts> impact_store;
  std::array<std::uint16_t, MaxBodies> generation_store;
  std::array<std::uint32_t, bit_words(MaxBodies)> free_store;
};

}  // namespace detail
}  // namespace statsim
