#pragma once
/// @file
/// The broad phase's records as an index for the queries (statsim/queries.hpp): what the
/// index holds (`QueryIndex`) and how a step and the calls between steps keep it conservative
/// (`made_records`, `note_moved`, `measure_drift`). Searching it is query_search.hpp's.

#include "statsim/detail/grid.hpp"
#include "statsim/detail/sweep.hpp"
#include "statsim/math.hpp"
#include "statsim/world_def.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

namespace statsim {
namespace detail {

/// What the queries (statsim/queries.hpp) need to search the broad phase's records instead of
/// every body: the records are those of the last broad phase that ran, made before the contact
/// passes moved bodies, so a query widens its search by how far a body has moved since.
struct QueryIndex {
  static constexpr std::uint32_t max_moved = 16;  ///< bodies listed in `moved`
  bool valid = false;  ///< the broad phase's block holds records of bodies [0, `count`)
  bool grid = false;   ///< the records are the grid's (else sweep-and-prune entries)
  bool overflow = false;  ///< more bodies were moved than `moved` holds: queries scan every body
  int axis = 0;  ///< the sweep axis the entries were made on
  std::uint64_t step = 0;  ///< `WorldData::step_count` of the step that made the records
  std::uint32_t count = 0;  ///< bodies in the records; those added after them are searched one by one
  std::uint32_t moved_count = 0;
  /// Bodies given a new place between steps (`set_transform`, a reused slot's `add_body`):
  /// their records are not where they are, so queries test them one by one.
  std::uint32_t moved[max_moved];
  /// m: no body of the records has moved farther from its record since (along the sweep axis for
  /// sweep-and-prune), but for the `moved` ones. Not finite: queries scan every body.
  Scalar drift = 0;
};

template <int D>
struct WorldData;

/// Records that body `i` was given a new place between steps: its broad phase record (if it has
/// one) no longer tells where it is.
template <int D>
void note_moved(WorldData<D>& w, std::uint32_t i)
{
  QueryIndex& q = w.index;
  if (i >= q.count) return;  // beyond the records: queries test it anyway
  if (q.moved_count < QueryIndex::max_moved) q.moved[q.moved_count++] = i;
  else q.overflow = true;
}

/// Notes that the broad phase has just made a record of every body where it is now.
template <int D>
void made_records(WorldData<D>& w, bool grid)
{
  QueryIndex& q = w.index;
  q.valid = true;
  q.grid = grid;
  q.overflow = false;
  q.axis = w.def.sweep_axis;
  q.count = w.body_count;
  q.moved_count = 0;
  q.drift = 0;
  q.step = w.step_count;
}

/// After the contact passes: widens `QueryIndex::drift` to the farthest a body has moved from its
/// record. Only bodies awake at some time in the step move (a sleeper's inverse mass is 0 in the
/// passes): those awake now and those that fell asleep in it (`flagged`). The records are read
/// in their own order, at one bit test each, so a step costs one read of them; it is made only
/// in steps that made them (in others no body is awake and none moved).
/// A body gone non-finite is left out: no query can meet it. (The bounds are measured on the
/// same float sums the records were made of; the queries' margin covers the rest of the rounding.)
template <int D>
void measure_drift(WorldData<D>& w)
{
  QueryIndex& q = w.index;
  if (!q.valid || w.step_count != q.step) return;
  const auto moved = [&w](std::uint32_t i) {
    const std::uint32_t bit = std::uint32_t(1) << (i % 32);
    return ((w.awake[i / 32] | w.flagged[i / 32]) & bit) != 0 && finite(w.bodies[i].position);
  };
  Scalar drift = q.drift;
  bool lost = false;
  if (q.grid) {
    for (std::uint32_t k = 0; k < q.count; ++k) {
      const GridItem<D>& it = w.grid.items[k];
      const std::uint32_t i = it.key & ~asleep_key;
      if (!moved(i)) continue;
      const Scalar d = (w.bodies[i].position - it.position).norm();
      if (d > drift) drift = d;
      else lost = lost || !(d <= drift);  // a record not finite: queries scan
    }
  } else {
    const Scalar common = w.common_bound;
    for (std::uint32_t k = 0; k < q.count; ++k) {
      const SweepEntry& e = w.entries[k];
      // An entry of a body gone non-finite leaves the entries out of order, where the queries'
      // binary search would miss others: it makes the drift non-finite, and queries scan.
      lost = lost || !(e.lo <= e.hi);
      if (!moved(e.body)) continue;
      const Body<D>& b = w.bodies[e.body];
      // The entry's interval against the one the body would have now: the larger shift of its ends.
      const Scalar bound = common > 0 ? common : w.shapes[b.shape].bounding_radius;
      const Scalar lo = std::fabs(b.position[q.axis] - bound - e.lo);
      const Scalar hi = std::fabs(b.position[q.axis] + bound - e.hi);
      const Scalar d = lo > hi ? lo : hi;
      if (d > drift) drift = d;
      else lost = lost || !(d <= drift);  // a record not finite: queries scan
    }
  }
  q.drift = lost ? std::numeric_limits<Scalar>::quiet_NaN() : drift;
}

}  // namespace detail
}  // namespace statsim
