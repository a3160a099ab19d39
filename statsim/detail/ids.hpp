#pragma once
/// @file
/// Ids: the tags that tie shape ids to their world, and the body slots behind body ids, whose
/// generations keep an id of a removed body from naming the body that reuses its slot.

#include "statsim/world_def.hpp"

#include <atomic>
#include <cstdint>

namespace statsim {
namespace detail {

/// A tag for a new world, 1 to 65535 (0 is the bare-index tag of `ShapeId`). Worlds made one after
/// another get different tags until 65535 have been made; the tag never enters a simulation.
inline std::uint16_t next_world_tag()
{
  static std::atomic<std::uint32_t> made{0};
  return std::uint16_t(made.fetch_add(1, std::memory_order_relaxed) % 65535u + 1u);
}

/// A slot's generation once it has been removed `retired_generation` times: it is never reused,
/// so no id is ever issued twice (and none equals `no_body`).
constexpr std::uint16_t retired_generation = std::uint16_t(body_generation(no_body));

/// What names a body in a slot: each slot's generation, and the bit set of removed slots that
/// `add_body` may reuse (lowest first). Storage owned by `World<>`.
struct BodySlots {
  std::uint16_t* generation = nullptr;
  std::uint32_t* free = nullptr;
  std::uint32_t free_count = 0;  ///< removed slots waiting for reuse
  std::uint32_t removed = 0;     ///< slots without a body: free or retired

  bool live(std::uint32_t slot) const
  {
    return !(free[slot / 32] >> (slot % 32) & 1u) && generation[slot] != retired_generation;
  }
  /// The slot `id` names among the first `count`, or `no_slot`.
  std::uint32_t find(BodyId id, std::uint32_t count) const
  {
    const std::uint32_t slot = body_index(id);
    return slot < count && generation[slot] == body_generation(id) && live(slot) ? slot : no_slot;
  }
  /// The id of the body in `slot`, or `no_body` for a slot without one.
  BodyId id(std::uint32_t slot, std::uint32_t count) const
  {
    return slot < count && live(slot) ? make_body_id(slot, generation[slot]) : no_body;
  }
};

}  // namespace detail
}  // namespace statsim
