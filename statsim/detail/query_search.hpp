#pragma once
/// @file
/// How the queries of statsim/queries.hpp find the bodies near a ray or a sphere through the
/// broad phase's records (`detail::QueryIndex`) instead of testing every body slot, and hand
/// them on in slot order.
///
/// The records are those the last step's broad phase made, before its contact passes moved
/// bodies. They are a conservative index because the step measures, after those passes, the
/// farthest any body moved from its record (`QueryIndex::drift`, `measure_drift`), and a query
/// widens its search by it: a body that can meet the query lies within (query radius + largest
/// bounding radius) of the ray or centre now, so its record lies within that plus the drift.
/// Bodies added since the records, and those moved between steps (`set_transform`, a reused
/// slot), are tested one by one. What is found is only a candidate: the query then tests the
/// body as it is now, with the same arithmetic as a test of every slot, so the hits are the same.

#include "statsim/detail/world_data.hpp"

#include <cmath>
#include <cstdint>

namespace statsim {

/// What a query examined, for tests and profiling (the count, not a time).
struct QueryStats {
  /// Broad phase records and bodies read; a query that scans reads every body slot.
  std::uint32_t bodies_examined = 0;
  std::uint32_t cells = 0;  ///< grid cells visited
  bool scanned = false;     ///< the query tested every body slot instead of searching the records
};

namespace detail {

/// Largest |coordinate| of a query in grid cells at which the grid is searched: beyond it the
/// rounding of a float cell coordinate (2^-24 of it) nears the margin of the search.
constexpr Scalar max_query_cells = Scalar(1e5);

/// Calls `box(lo, hi)` with boxes of grid cells (integer coordinates, bounds included; the third
/// 0 in 2D) that together hold every cell with a point within `r` of the segment from `a` to `b`
/// (all in cells; `a == b` for a ball). One box per layer of cells across the segment's longest
/// axis k: a point P of layer m (m <= P_k < m + 1) with |P - S(t)| <= r for a point S(t) =
/// a + t (b - a) of the segment has |P_k - S_k(t)| <= r, so t lies where S_k is in
/// [m - r, m + 1 + r]; P's other coordinates lie within r of what S spans over those t.
template <int D, class Vec, class Box>
void segment_cell_boxes(const Vec& a, const Vec& b, Scalar r, Box&& box)
{
  const Vec ab = b - a;
  int k = 0;
  for (int j = 1; j < D; ++j)
    if (std::fabs(ab[j]) > std::fabs(ab[k])) k = j;
  const std::int32_t m0 = std::int32_t(std::floor((a[k] < b[k] ? a[k] : b[k]) - r));
  const std::int32_t m1 = std::int32_t(std::floor((a[k] < b[k] ? b[k] : a[k]) + r));
  for (std::int32_t m = m0; m <= m1; ++m) {
    Scalar t0 = 0, t1 = 1;
    if (ab[k] != 0) {
      const Scalar ta = (Scalar(m) - r - a[k]) / ab[k], tb = (Scalar(m + 1) + r - a[k]) / ab[k];
      t0 = ta < tb ? ta : tb;
      t1 = ta < tb ? tb : ta;
      t0 = t0 > 0 ? t0 : Scalar(0);
      t1 = t1 < 1 ? t1 : Scalar(1);
      // The margin in r covers the rounding of t: an empty range is a layer out of reach.
      if (t0 > t1) continue;
    }
    std::int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    lo[k] = hi[k] = m;
    for (int j = 0; j < D; ++j) {
      if (j == k) continue;
      const Scalar p0 = a[j] + ab[j] * t0, p1 = a[j] + ab[j] * t1;
      lo[j] = std::int32_t(std::floor((p0 < p1 ? p0 : p1) - r));
      hi[j] = std::int32_t(std::floor((p0 < p1 ? p1 : p0) + r));
    }
    box(lo, hi);
  }
}

/// Squared distance from `p` to the segment from `a` along `ab` (m^2).
template <class Vec>
Scalar segment_distance2(const Vec& a, const Vec& ab, Scalar ab2, const Vec& p)
{
  Scalar t = ab2 > 0 ? (p - a).dot(ab) / ab2 : Scalar(0);
  t = t < 0 ? Scalar(0) : (t > 1 ? Scalar(1) : t);
  return (a + ab * t - p).squaredNorm();
}

/// Offers `visit(i)` every body i whose centre may now lie within `pad` (m) plus its bounding
/// radius of the segment from `a` to `b` (a ball about `a` when `a == b`): from the records, the
/// bodies added after them and the ones moved between steps. A body may be offered more than
/// once (grid cells that share a bucket), and bodies beyond reach may be offered too. Returns
/// false, having offered none, when the records cannot answer (none made, too many bodies moved,
/// a drift that is not finite, or a grid search that would visit more cells than the records
/// hold bodies): the caller then tests every slot.
template <int D, class Visit>
bool search_records(const WorldData<D>& w, const typename Space<D>::Vec& a, const typename Space<D>::Vec& b,
                    Scalar pad, QueryStats& stats, Visit&& visit)
{
  using Vec = typename Space<D>::Vec;
  const QueryIndex& q = w.index;
  if (!q.valid || q.overflow || !(q.drift <= limits::coordinate)) return false;
  // Rounding: every sum and product above is within a few float ulps (2^-24) of its value, of
  // magnitudes up to the coordinates and reaches involved; 1e-5 of them covers it many times.
  const Scalar scale = Scalar(1) + a.cwiseAbs().maxCoeff() + b.cwiseAbs().maxCoeff() + pad + w.widest + q.drift;
  const Scalar margin = Scalar(1e-5) * scale;
  if (q.grid) {
    const SpatialHash<D>& grid = w.grid;
    const Scalar reach = pad + Scalar(0.5) * w.widest + q.drift + margin;
    const Scalar inv = grid.inv_cell;
    const Vec ac = a * inv, bc = b * inv;
    const Scalar r = reach * inv * Scalar(1 + 1e-5) + Scalar(1e-5) * (1 + ac.cwiseAbs().maxCoeff() + bc.cwiseAbs().maxCoeff());
    if (!(ac.cwiseAbs().maxCoeff() <= max_query_cells) || !(bc.cwiseAbs().maxCoeff() <= max_query_cells) ||
        !(r <= max_query_cells))
      return false;
    // Count the cells first: a search of more cells than the records hold bodies is no cheaper
    // than testing every slot. The layers alone are bounded before they are walked.
    const Scalar budget = Scalar(q.count);
    if ((ac - bc).cwiseAbs().maxCoeff() + 2 * r + 1 > budget) return false;
    Scalar cells = 0;
    segment_cell_boxes<D>(ac, bc, r, [&cells](const std::int32_t* lo, const std::int32_t* hi) {
      Scalar n = 1;
      for (int j = 0; j < 3; ++j) n *= Scalar(hi[j] - lo[j] + 1);
      cells += n;
    });
    if (cells > budget) return false;
    stats.cells += std::uint32_t(cells);
    const Vec ab = b - a;
    const Scalar ab2 = ab.squaredNorm(), reach2 = reach * reach;
    segment_cell_boxes<D>(ac, bc, r, [&](const std::int32_t* lo, const std::int32_t* hi) {
      for (std::int32_t z = lo[2]; z <= hi[2]; ++z)
        for (std::int32_t y = lo[1]; y <= hi[1]; ++y)
          for (std::int32_t x = lo[0]; x <= hi[0]; ++x) {
            const std::uint32_t bucket = grid.bucket(x, y, z);
            const GridItem<D>* it = grid.items + grid.start[bucket];
            const GridItem<D>* const end = grid.items + grid.start[bucket + 1];
            stats.bodies_examined += std::uint32_t(end - it);
            for (; it != end; ++it)
              if (segment_distance2(a, ab, ab2, it->position) <= reach2) visit(it->key & ~asleep_key);
          }
    });
  } else {
    // Entries sorted by lo, each at most `widest` long (and rounding): those reaching the query's
    // interval on the axis start after its low end less that.
    const int axis = q.axis;
    const Scalar widen = pad + q.drift + margin;
    const Scalar lo = (a[axis] < b[axis] ? a[axis] : b[axis]) - widen;
    const Scalar hi = (a[axis] < b[axis] ? b[axis] : a[axis]) + widen;
    const Scalar first_lo = lo - w.widest - margin;
    std::uint32_t begin = 0, end = q.count;
    while (begin < end) {
      const std::uint32_t mid = begin + (end - begin) / 2;
      if (w.entries[mid].lo < first_lo) begin = mid + 1;
      else end = mid;
    }
    for (std::uint32_t k = begin; k < q.count && w.entries[k].lo <= hi; ++k) {
      ++stats.bodies_examined;
      if (w.entries[k].hi >= lo) visit(w.entries[k].body);
    }
  }
  for (std::uint32_t i = q.count; i < w.body_count; ++i) visit(i);
  for (std::uint32_t k = 0; k < q.moved_count; ++k) visit(q.moved[k]);
  stats.bodies_examined += (w.body_count - q.count) + q.moved_count;
  return true;
}

/// Calls `emit(i)` for the bodies i that `search(offer)` offers and `hits(i)` accepts, once each,
/// in increasing i, as a test of every slot in order would: in rounds, each collecting the
/// `batch` lowest indices above the last round's in a fixed array (no heap). Returns 0 when the
/// first search could not answer (nothing emitted), 1 when all were emitted, 2 when `emit`
/// returned false.
template <class Search, class Hits, class Emit>
int in_slot_order(Search&& search, Hits&& hits, Emit&& emit)
{
  constexpr std::uint32_t batch = 32;
  std::uint32_t idx[batch];
  std::uint32_t after = 0;
  bool first = true;
  for (;;) {
    std::uint32_t n = 0;
    const bool answered = search([&](std::uint32_t i) {
      if (!first && i <= after) return;
      if (n == batch && i >= idx[batch - 1]) return;
      std::uint32_t p = n;
      while (p > 0 && idx[p - 1] > i) --p;
      if (p > 0 && idx[p - 1] == i) return;  // offered again
      if (!hits(i)) return;
      if (n < batch) ++n;
      for (std::uint32_t k = n - 1; k > p; --k) idx[k] = idx[k - 1];
      idx[p] = i;
    });
    if (!answered) return 0;  // the search is the same each round: only the first can fail
    for (std::uint32_t k = 0; k < n; ++k)
      if (!emit(idx[k])) return 2;
    if (n < batch) return 1;
    after = idx[batch - 1];
    first = false;
  }
}

}  // namespace detail
}  // namespace statsim
