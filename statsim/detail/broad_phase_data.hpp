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
#include "statsim/math.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <new>  // placement new: objects begun in the world's own storage block, nothing allocated

namespace statsim {

/// A candidate pair of bodies, by index, a < b: 8 bytes, as a pair buffer holds several per body.
/// (`b` and `witness` are bit-fields: copy them into an integer before binding a reference.)
struct Pair {
  std::uint32_t a;
  std::uint32_t b : 24;  ///< body indices have `body_index_bits` (20) bits
  /// With hull contacts, the candidate normal the impact pass found for a touching pair
  /// (`detail::find_hull_witness`), which the later passes of the step reuse; 0 in a new pair.
  std::uint32_t witness : 8;
};

/// One body's interval on the sweep axis: 12 bytes with float `Scalar`.
struct SweepEntry {
  Scalar lo;
  Scalar hi;
  std::uint32_t body : 31;
  std::uint32_t active : 1;  ///< 1 when awake: pairs of two inactive entries are not wanted
};

namespace detail {

/// A new candidate pair of bodies a < b, as the broad phases make it.
inline Pair make_pair(std::uint32_t a, std::uint32_t b)
{
  Pair p;
  p.a = a;
  p.b = b & 0xffffffu;
  p.witness = 0;
  return p;
}

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
/// interval.
template <class OnOverlap>
void sweep_active(const SweepEntry* entries, std::uint32_t count, Scalar max_width, OnOverlap&& overlap)
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

namespace statsim {

/// Which broad phase a world uses.
enum class BroadPhase : std::uint8_t {
  /// Uniform grid of cells as wide as the widest reach of two bodies (`detail::pair_radius`: the
  /// bounding radius with hull contacts, else about the collision sphere), hashed into a fixed
  /// table: each awake body looks at the 3^D cells around it. Cost grows with awake bodies times
  /// their neighbours.
  grid,
  /// Sweep-and-prune along one axis (paper 4.1). Cost grows with the bodies whose intervals
  /// overlap on that axis, which in a wide pile is many more than the true neighbours.
  sweep_and_prune,
  /// Sweep-and-prune up to `WorldDef::grid_above_bodies` bodies, the grid above: sweep-and-prune
  /// is the faster in small worlds, the grid in large ones (`statsim bench`, tools/bench/README.md).
  automatic,
};

namespace detail {

/// Number of buckets of the grid's hash table for `bodies` bodies: a power of two >= 2 bodies.
constexpr std::uint32_t grid_buckets(std::uint32_t bodies)
{
  std::uint32_t b = 1;
  while (b < 2 * bodies) b *= 2;
  return b;
}

/// One body as the grid's pair search sees it, stored in bucket order. The search reads these
/// records in sequence instead of gathering positions from the bodies: at 10,000 bodies the body
/// array is far larger than the cache, and each awake body visits about twenty others in its 3^D
/// cells.
template <int D>
struct GridItem {
  typename Space<D>::Vec position;  ///< centre, m
  Scalar radius;                    ///< `detail::pair_radius`, m
  /// The body's index, plus `asleep_key` for a sleeper: from awake body i the search wants the
  /// bodies with key > i (awake ones of higher index, and every sleeper) in one comparison. A
  /// bucket lists its bodies by key: the awake ones, then the sleepers.
  std::uint32_t key;
};

/// Added to a sleeper's index in `GridItem::key` (indices stay below it).
constexpr std::uint32_t asleep_key = std::uint32_t(1) << 31;

/// The storage of the broad phase of a world of `bodies` bodies, one phase at a time: the
/// sweep-and-prune entries; or, for the grid, the sweep order kept as body indices (so that a
/// world that goes back to sweep-and-prune finds its order), then the grid's items and bucket
/// starts. Byte offsets into one block (`broad_phase_bytes`).
template <int D>
struct BroadPhaseLayout {
  static constexpr std::size_t order(std::uint32_t) { return 0; }
  static constexpr std::size_t items(std::uint32_t bodies) { return sizeof(std::uint32_t) * std::size_t(bodies); }
  static constexpr std::size_t start(std::uint32_t bodies)
  {
    return items(bodies) + sizeof(GridItem<D>) * std::size_t(bodies);
  }
  static constexpr std::size_t bytes(std::uint32_t bodies)
  {
    const std::size_t grid = start(bodies) + sizeof(std::uint32_t) * (std::size_t(grid_buckets(bodies)) + 1);
    const std::size_t sweep = sizeof(SweepEntry) * std::size_t(bodies);
    return grid > sweep ? grid : sweep;
  }
  static_assert(alignof(GridItem<D>) <= alignof(std::uint32_t) && alignof(SweepEntry) <= alignof(std::uint32_t) * 4,
                "the block is aligned for its widest record");
};

/// Hashed uniform grid over caller-owned arrays: `start` has max_buckets + 1 entries, `items` one
/// per body. Built from scratch every step by a counting sort of the bodies by bucket.
template <int D>
struct SpatialHash {
  std::uint32_t* start;
  GridItem<D>* items;
  std::uint32_t max_buckets;  ///< `start` holds max_buckets + 1 entries; a power of two
  std::uint32_t buckets = 1;  ///< in use since the last build(): a power of two <= max_buckets
  Scalar inv_cell = 1;

  static std::int32_t cell_of(Scalar x, Scalar inv_cell)
  {
    Scalar c = std::floor(x * inv_cell);
    // Clamp so the conversion is defined for bodies far out; cells there merely share buckets.
    // Written so that NaN (a body gone non-finite) also lands on -1e9: converting NaN is undefined.
    c = !(c > Scalar(-1e9)) ? Scalar(-1e9) : (c > Scalar(1e9) ? Scalar(1e9) : c);
    return std::int32_t(c);
  }
  /// The term of cell coordinate c along axis k in a bucket's hash (the three are XORed).
  static std::uint32_t hash_term(int k, std::int32_t c)
  {
    return std::uint32_t(c) * (k == 0 ? 73856093u : (k == 1 ? 19349663u : 83492791u));
  }
  std::uint32_t bucket(std::int32_t x, std::int32_t y, std::int32_t z) const
  {
    return (hash_term(0, x) ^ hash_term(1, y) ^ hash_term(2, z)) & (buckets - 1);
  }

  /// Sorts `count` bodies into buckets; `cell(i, c)` writes body i's integer cell coordinates,
  /// `item(i)` returns its record and `asleep(i)` tells whether its key has `asleep_key`. Within
  /// a bucket the records are in increasing key order.
  template <class CellOf, class ItemOf, class Asleep>
  void build(std::uint32_t count, CellOf&& cell, ItemOf&& item, Asleep&& asleep)
  {
    // Size the table to the bodies present, not to the capacity: every build walks all buckets
    // three times, and a world of 100 bodies with room for 10,000 would spend most of its step
    // clearing empty buckets.
    const std::uint32_t wanted = grid_buckets(count);
    buckets = wanted < max_buckets ? wanted : max_buckets;
    for (std::uint32_t b = 0; b <= buckets; ++b) new (&start[b]) std::uint32_t(0);
    for (std::uint32_t i = 0; i < count; ++i) {
      std::int32_t c[3];
      cell(i, c);
      ++start[bucket(c[0], c[1], c[2]) + 1];
    }
    for (std::uint32_t b = 0; b < buckets; ++b) start[b + 1] += start[b];
    // Fill from the back, sleepers first, so each bucket lists its bodies in increasing key order.
    for (int sleepers = 1; sleepers >= 0; --sleepers)
      for (std::uint32_t i = count; i-- > 0;) {
        if (asleep(i) != (sleepers != 0)) continue;
        std::int32_t c[3];
        cell(i, c);
        const std::uint32_t b = bucket(c[0], c[1], c[2]);
        // Placement: the block held sweep-and-prune entries when that phase last ran.
        new (&items[--start[b + 1]]) GridItem<D>(item(i));
      }
    // The descending fill left start[b + 1] at the first item of bucket b: shift it to start[b],
    // so that bucket b is items[start[b]] .. items[start[b + 1] - 1].
    for (std::uint32_t b = 0; b < buckets; ++b) start[b] = start[b + 1];
    start[buckets] = count;
  }
};

}  // namespace detail
}  // namespace statsim
