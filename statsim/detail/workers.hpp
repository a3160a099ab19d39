#pragma once
/// @file
/// Work of a step that runs on the user's workers (`WorldDef::workers`) besides the grid's pair
/// search (find_pairs.hpp): the impact pass's search of the pairs' hull candidates.

#include "statsim/hull_contact.hpp"
#include "statsim/world_data.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// The fewest pairs worth a part of their own (a few tenths of a millisecond of searching).
constexpr std::uint32_t witnesses_per_part = 512;

template <int D>
void search_witnesses(std::uint32_t begin, std::uint32_t end, void* context)
{
  WorldData<D>& w = *static_cast<WorldData<D>*>(context);
  for (std::uint32_t k = begin; k < end; ++k) {
    Pair& pair = w.pairs[k];
    const Body<D>& a = w.bodies[pair.a];
    const Body<D>& b = w.bodies[pair.b];
    if (!hull_pair(w, a, b)) continue;
    const Shape<D>& sa = w.shapes[a.shape];
    const Shape<D>& sb = w.shapes[b.shape];
    Scalar dist;
    typename Space<D>::Vec e;
    if (centre_line(sa, sb, typename Space<D>::Vec(b.position - a.position), dist, e))
      search_witness(sa, a, sb, b, e, dist, pair);
  }
}

/// With workers and hull contacts, the impact pass's hull candidates of every candidate pair
/// (`search_witness`), searched before the pass on the workers: the pass changes velocities only
/// (overlaps are corrected there only without `WorldDef::shock_propagation`), so the candidates
/// are the ones it would find pair by pair. Returns false when the pass must search them itself.
template <int D>
bool search_witnesses_first(WorldData<D>& w)
{
#if STATSIM_WORKERS
  if (w.def.workers.count < 2 || w.def.body_contacts != BodyContacts::hulls || !w.def.shock_propagation ||
      w.pair_count < 2 * witnesses_per_part)
    return false;
  run_on_workers(w, w.pair_count, witnesses_per_part, &search_witnesses<D>, &w);
  return true;
#else
  (void)w;
  return false;
#endif
}

}  // namespace detail
}  // namespace statsim
