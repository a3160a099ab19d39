#pragma once
/// @file
/// Impact events: the contacts of a step that approach faster than
/// `WorldDef::impact_threshold`, recorded into a fixed buffer the world owns (`World`'s
/// `MaxImpacts`). Recording only reads the world, before the impact pass responds to anything:
/// a world steps to the same bits whether it records or not.

#include "statsim/detail/hull.hpp"
#include "statsim/detail/narrow_phase.hpp"
#include "statsim/detail/slope.hpp"
#include "statsim/detail/world_data.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// The impact buffer of a world and what the last step put in it.
template <int D>
struct ImpactLog {
  Impact<D>* items = nullptr;
  std::uint32_t capacity = 0;
  std::uint32_t count = 0;  ///< recorded, <= capacity
  std::uint32_t found = 0;  ///< above the threshold, recorded or not

  void add(const Impact<D>& i)
  {
    if (count < capacity) items[count++] = i;
    ++found;
  }
};

/// Adds to `log` the impacts that the impact pass is about to resolve: awake bodies against
/// planes, in the pass's order, then the candidate pairs that touch, as `body_contact` finds them
/// (on copies: the pass finds them again itself). The slope contacts of bodies that rolled in
/// substeps are not the pass's: `roll_on_slopes` recorded their impacts. `id_of(slot)` is the id
/// of the body in a slot.
template <class FS, int D, class IdOf>
void record_impacts(const WorldData<D>& w, ImpactLog<D>& log, IdOf&& id_of)
{
  using Vec = typename Space<D>::Vec;
  if constexpr (!FS::events) {
    return;
  }
  if (log.capacity == 0) return;
  const Scalar threshold = w.def.impact_threshold;
  for_each_set(w.awake, w.body_count, [&](std::uint32_t i) {
    const Body<D>& b = w.bodies[i];
    for (std::uint32_t p = 0; p < w.plane_count; ++p) {
      const Plane<D>& plane = w.planes[p];
      Contact<D> c;
      if (hull_planes<FS>(w) && bit_set(w.rolled, i) && rolls_on<FS>(w, b, plane.normal)) continue;
      if (!sphere_plane_contact<D>(b.position, plane_radius<FS>(w, b, plane), plane, c)) continue;
      const Scalar approach = -b.linear_velocity.dot(c.normal);
      if (!(approach > threshold)) continue;
      const Vec foot = b.position - c.normal * (c.normal.dot(b.position) - plane.offset);
      log.add(Impact<D>{id_of(i), no_body, PlaneId(p), foot, c.normal, approach});
    }
  });
  // A pair approaches along its contact normal no faster than the two bodies move apart or
  // together at all, |v_a - v_b|: a pair slower than the threshold is passed over before its
  // contact is sought (in a pile almost every pair, whose search costs as much as the impact
  // pass's own). The margin keeps the rounding of the dot product below from ever reaching it.
  const Scalar slow2 = threshold * threshold * Scalar(1 - 1e-4);
  for (std::uint32_t k = 0; k < w.pair_count; ++k) {
    Pair pair = w.pairs[k];
    if ((w.bodies[pair.a].linear_velocity - w.bodies[pair.b].linear_velocity).squaredNorm() < slow2) continue;
    Body<D> a = w.bodies[pair.a];
    Body<D> b = w.bodies[pair.b];
    Contact<D> c;
    Scalar reach, slop;
    if (!body_contact<FS>(w, a, b, pair, true, Scalar(0), c, reach, slop)) continue;
    const Scalar approach = (a.linear_velocity - b.linear_velocity).dot(c.normal);
    if (!(approach > threshold)) continue;
    const Scalar gap = (b.position - a.position).norm();
    const Vec point = a.position + c.normal * (gap * (a.radius / (a.radius + b.radius)));
    log.add(Impact<D>{id_of(pair.a), id_of(pair.b), 0, point, c.normal, approach});
  }
}

}  // namespace detail
}  // namespace statsim
