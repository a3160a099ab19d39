#pragma once
/// @file
/// The user's workers (`WorldDef::workers`): how a step hands them a job (`run_on_workers`), and
/// the impact pass's search of the pairs' hull candidates on them. The other job they take, the
/// grid's pair search in parts, is in broad_phase.hpp beside the search it cuts up.

#include "statsim/detail/hull.hpp"
#include "statsim/detail/world_data.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// Runs `task(begin, end, context)` over the items [0, count): in ranges of at least `min_range`
/// items on the world's workers, about four per worker (items differ in cost, and a worker done
/// early takes another range), or at once on the calling thread when there are no workers or too
/// few items to share (handing out a task costs a thread's wake-up, tens of microseconds).
template <int D>
void run_on_workers(const WorldData<D>& w, std::uint32_t count, std::uint32_t min_range, TaskCallback* task,
                    void* context)
{
  const Workers& k = w.def.workers;
  const std::uint32_t range = std::uint32_t((std::uint64_t(count) + 4 * k.count - 1) / (4 * k.count));
  if (k.count < 2 || count < 2 * min_range) {
    task(0, count, context);
    return;
  }
  void* handle = k.enqueue(task, count, range > min_range ? range : min_range, context, k.context);
  if (handle != nullptr) k.finish(handle, k.context);
}

/// The fewest pairs worth a part of their own (a few tenths of a millisecond of searching).
constexpr std::uint32_t witnesses_per_part = 512;

template <class FS, int D>
void search_witnesses(std::uint32_t begin, std::uint32_t end, void* context)
{
  WorldData<D>& w = *static_cast<WorldData<D>*>(context);
  for (std::uint32_t k = begin; k < end; ++k) {
    Pair& pair = w.pairs[k];
    const Body<D>& a = w.bodies[pair.a];
    const Body<D>& b = w.bodies[pair.b];
    if (!hull_pair<FS>(w, a, b)) continue;
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
template <class FS, int D>
bool search_witnesses_first(WorldData<D>& w)
{
#if STATSIM_WORKERS
  if (!(FS::hull_contacts && hull_contacts_on(w)) || w.def.workers.count < 2 || !w.def.shock_propagation ||
      w.pair_count < 2 * witnesses_per_part)
    return false;
  run_on_workers(w, w.pair_count, witnesses_per_part, &search_witnesses<FS, D>, &w);
  return true;
#else
  (void)w;
  return false;
#endif
}

}  // namespace detail
}  // namespace statsim
