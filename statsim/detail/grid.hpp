#pragma once
/// @file
/// The hashed uniform grid of the broad phase (`BroadPhase::grid`): its records (`GridItem`), its
/// table (`SpatialHash`), rebuilt by a counting sort each step, and the one block of storage it
/// shares with the sweep-and-prune entries (`BroadPhaseLayout`). The search is broad_phase.hpp's.

#include "statsim/detail/sweep.hpp"
#include "statsim/math.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <new>  // placement new: objects begun in the world's own storage block, nothing allocated

namespace statsim {
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
