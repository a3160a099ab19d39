#pragma once
/// @file
/// The broad phase of a step: candidate pairs of bodies whose bounding spheres overlap, from the
/// hashed grid or sweep-and-prune (`broadphase.hpp`), into the world's pair buffer. Pairs with a
/// sleeping body are found only from the awake one; two sleepers are never a pair.

#include "statsim/world_data.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// Records a candidate pair if the bounding spheres overlap; counts it either way it fits.
template <int D>
void candidate(WorldData<D>& w, std::uint32_t a, std::uint32_t b, std::uint32_t& found)
{
  const Body<D>& ba = w.bodies[a];
  const Body<D>& bb = w.bodies[b];
  const Scalar reach = ba.bounding_radius + bb.bounding_radius;
  if ((bb.position - ba.position).squaredNorm() > reach * reach) return;
  if (found < w.max_pairs) w.pairs[found] = a < b ? Pair{a, b} : Pair{b, a};
  ++found;
}

/// Pairs from the grid of cells one widest bounding diameter wide: each awake body looks at the
/// bodies in the 3^D cells around its own. Returns how many were found (also those that did not
/// fit the buffer).
template <int D>
std::uint32_t find_pairs_grid(WorldData<D>& w, StepResult& result)
{
  SpatialHash<D>& grid = w.grid;
  Scalar widest = 0;
  for (std::uint32_t i = 0; i < w.body_count; ++i)
    widest = 2 * w.bodies[i].bounding_radius > widest ? 2 * w.bodies[i].bounding_radius : widest;
  grid.inv_cell = Scalar(1) / widest;
  const auto cell = [&w, &grid](std::uint32_t i, std::int32_t* c) {
    for (int k = 0; k < 3; ++k) c[k] = k < D ? grid.cell_of(w.bodies[i].position[k], grid.inv_cell) : 0;
  };
  const auto item = [&w](std::uint32_t i) {
    const Body<D>& b = w.bodies[i];
    return GridItem<D>{b.position, b.bounding_radius, i, b.state != MotionState::asleep ? 1u : 0u};
  };
  grid.build(w.body_count, cell, item);
  result.broad_phase_bodies += w.body_count;
  std::uint32_t found = 0, examined = 0;
  constexpr int neighbours = D == 3 ? 27 : 9;
  for_each_set(w.awake, w.body_count, [&](std::uint32_t i) {
    const Body<D>& bi = w.bodies[i];
    std::int32_t c[3];
    cell(i, c);
    std::uint32_t seen[neighbours];
    int seen_count = 0;
    // Buckets seen so far, by their low 6 bits: a clear bit proves a bucket new without
    // comparing it with every one before (neighbouring cells rarely share a bucket).
    std::uint64_t seen_bits = 0;
    for (int n = 0; n < neighbours; ++n) {
      const std::int32_t dx = n % 3 - 1, dy = (n / 3) % 3 - 1, dz = D == 3 ? n / 9 - 1 : 0;
      const std::uint32_t b = grid.bucket(c[0] + dx, c[1] + dy, c[2] + dz);
      // Two neighbouring cells can share a bucket: visit each bucket once.
      const std::uint64_t bit = std::uint64_t(1) << (b & 63u);
      if (seen_bits & bit) {
        bool repeat = false;
        for (int k = 0; k < seen_count; ++k) repeat = repeat || seen[k] == b;
        if (repeat) continue;
      }
      seen_bits |= bit;
      seen[seen_count++] = b;
      const GridItem<D>* it = grid.items + grid.start[b];
      const GridItem<D>* const end = grid.items + grid.start[b + 1];
      examined += std::uint32_t(end - it);
      for (; it != end; ++it) {
        const std::uint32_t j = it->body;
        // An awake pair is found once, from its lower index; a sleeper never looks itself. As
        // `candidate`, from the grid's copy of body j. Both tests are taken together, so that
        // the one branch is nearly always the same way (the index test alone goes either way).
        const bool wanted = j > i || (j < i && !it->awake);
        const Scalar reach = bi.bounding_radius + it->reach;
        const bool near = !((it->position - bi.position).squaredNorm() > reach * reach);
        if (!(wanted & near)) continue;
        if (found < w.max_pairs) w.pairs[found] = Pair{i < j ? i : j, i < j ? j : i};
        ++found;
      }
    }
  });
  result.pairs_examined += examined;
  return found;
}

/// Pairs from sweep-and-prune along `WorldDef::sweep_axis`. The entries keep last step's order,
/// so the insertion sort has little to do. Returns how many pairs were found.
template <int D>
std::uint32_t find_pairs_sweep(WorldData<D>& w, StepResult& result)
{
  // With no body awake there is no pair; if the entries were sorted on the bodies' present
  // places (a sweep with none awake, after which nothing moved) the sweep would not change them.
  if (w.awake_count == 0 && w.sweep_current && w.entry_count == w.body_count) return 0;
  // Bodies added since the last sweep join at the end, in order of creation.
  for (; w.entry_count < w.body_count; ++w.entry_count)
    w.entries[w.entry_count] = SweepEntry{0, 0, w.entry_count, 1};
  const int axis = w.def.sweep_axis;
  Scalar widest = 0;
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    SweepEntry& e = w.entries[i];
    const Body<D>& b = w.bodies[e.body];
    e.lo = b.position[axis] - b.bounding_radius;
    e.hi = b.position[axis] + b.bounding_radius;
    e.active = b.state != MotionState::asleep ? 1u : 0u;
    widest = 2 * b.bounding_radius > widest ? 2 * b.bounding_radius : widest;
  }
  result.broad_phase_bodies += w.body_count;
  insertion_sort(w.entries, w.body_count);
  // Nothing moves in a step without awake bodies: the order stays valid for the next.
  w.sweep_current = w.awake_count == 0;
  std::uint32_t found = 0, examined = 0;
  sweep_active(w.entries, w.body_count, widest, [&](std::uint32_t a, std::uint32_t b) {
    ++examined;
    candidate(w, a, b, found);
  });
  result.pairs_examined += examined;
  return found;
}

/// Fills the pair buffer with this step's candidate pairs, up to its capacity; the result tells
/// how many were found and how many did not fit.
template <int D>
void find_pairs(WorldData<D>& w, StepResult& result)
{
  const bool grid = w.def.broad_phase == BroadPhase::grid ||
                    (w.def.broad_phase == BroadPhase::automatic && w.body_count > w.def.grid_above_bodies);
  std::uint32_t found = 0;
  if (grid) {
    // The grid keeps nothing from step to step but its sizes; bodies move under the entries.
    w.sweep_current = false;
    // Two sleepers are never a pair.
    if (w.awake_count > 0) found = find_pairs_grid(w, result);
  } else {
    found = find_pairs_sweep(w, result);
  }
  result.pairs_found = found;
  if (found > w.max_pairs) {
    result.pairs_dropped = found - w.max_pairs;
    result.overflow |= overflow_pairs;
  }
  w.pair_count = found < w.max_pairs ? found : w.max_pairs;
}

}  // namespace detail
}  // namespace statsim
