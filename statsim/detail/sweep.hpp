#pragma once
/// @file
/// Sweep-and-prune broad phase over fixed arrays (paper 3.3.1 and 4.1).
///
/// Each body is an interval [lo, hi] on one sweep axis, from its position and its bounding
/// (largest possible) radius, so the interval does not jump when the collision radius changes.
/// The intervals are kept sorted by lo with an insertion sort: between two steps bodies move
/// little, the array is nearly sorted, and the sort costs O(n + swaps). The sweep then visits
/// each body's successors until their lo passes its hi.

#include "statsim/config.hpp"

#include <cstdint>

namespace statsim {

/// One body's interval on the sweep axis: 12 bytes with float `Scalar`.
struct SweepEntry {
  Scalar lo;
  Scalar hi;
  std::uint32_t body : 31;
  std::uint32_t active : 1;  ///< 1 when awake: pairs of two inactive entries are not wanted
};

namespace detail {

/// An entry of a body that the next sweep places (its interval is filled in then).
inline SweepEntry sweep_entry(std::uint32_t body, bool active)
{
  SweepEntry e;
  e.lo = 0;
  e.hi = 0;
  e.body = body & 0x7fffffffu;
  e.active = active ? 1u : 0u;
  return e;
}

/// Sorts `entries` by `lo`, stably, in place. Returns the number of element moves, which is small
/// when the order is coherent from frame to frame.
inline std::uint32_t insertion_sort(SweepEntry* entries, std::uint32_t count)
{
  std::uint32_t moves = 0;
  for (std::uint32_t i = 1; i < count; ++i) {
    const SweepEntry e = entries[i];
    std::uint32_t j = i;
    while (j > 0 && entries[j - 1].lo > e.lo) {
      entries[j] = entries[j - 1];
      --j;
    }
    moves += i - j;
    entries[j] = e;
  }
  return moves;
}

/// Calls `overlap(body_a, body_b)` for every pair of entries whose intervals overlap and of which
/// at least one is active, at a cost that grows with the active entries rather than all of them
/// (a settled pile of sleepers costs nearly nothing). `entries` must be sorted by lo. From each
/// active entry it scans forward until lo passes its hi, and backward for inactive entries whose
/// interval reaches it: sorted by lo, those start no earlier than lo - `max_width`, the widest
/// interval. `overlap` is taken by value: a copy of its own, whose captures the compiler can keep
/// in registers through the loops (through a reference it reloads them at every pair).
template <class OnOverlap>
void sweep_active(const SweepEntry* entries, std::uint32_t count, Scalar max_width, OnOverlap overlap)
{
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!entries[i].active) continue;
    const Scalar lo = entries[i].lo, hi = entries[i].hi;
    const std::uint32_t a = entries[i].body;
    for (std::uint32_t j = i + 1; j < count && entries[j].lo <= hi; ++j) overlap(a, entries[j].body);
    const Scalar reach = lo - max_width;
    for (std::uint32_t j = i; j-- > 0 && entries[j].lo >= reach;)
      if (!entries[j].active && entries[j].hi >= lo) overlap(entries[j].body, a);
  }
}

}  // namespace detail
}  // namespace statsim
