#pragma once
/// @file
/// The broad phase of a step: candidate pairs of bodies whose spheres of `pair_radius` overlap,
/// from the hashed grid (grid.hpp) or sweep-and-prune (sweep.hpp), into the world's pair buffer.
/// Pairs with a sleeping body are found only from the awake one; two sleepers are never a pair.

#include "statsim/detail/query_index.hpp"
#include "statsim/detail/workers.hpp"
#include "statsim/detail/world_data.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <new>  // placement new: objects begun in the world's own storage block, nothing allocated

namespace statsim {
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

/// Records a candidate pair if the spheres of their `pair_radius` overlap, as the grid finds
/// them; counts it either way it fits. The bounding spheres are tested first: most pairs of a
/// sweep are apart, and that test needs no radius of the pair when every shape has the same
/// bounding radius (`common_reach`: twice `WorldData::common_bound`, or 0). `bounding`: the pair
/// radii are the bounding radii (hull contacts, every shape with a hull), times `reach_scale`
/// (`pair_reach`).
template <class FS, int D>
void candidate(WorldData<D>& w, std::uint32_t a, std::uint32_t b, Scalar common_reach, bool bounding,
               Scalar reach_scale, std::uint32_t& found)
{
  const Body<D>& ba = w.bodies[a];
  const Body<D>& bb = w.bodies[b];
  const Scalar bound = common_reach > 0 ? common_reach
                                        : w.shapes[ba.shape].bounding_radius + w.shapes[bb.shape].bounding_radius;
  const Scalar d2 = (bb.position - ba.position).squaredNorm();
  if (d2 > bound * bound) return;
  const Scalar reach = bounding ? bound * reach_scale : pair_radius<FS>(w, ba) + pair_radius<FS>(w, bb);
  if (d2 > reach * reach) return;
  if (found < w.max_pairs) w.pairs[found] = a < b ? make_pair(a, b) : make_pair(b, a);
  ++found;
}

/// What the grid's pair search of one step reads besides the grid: fixed once the grid is built.
template <int D>
struct GridSearch {
  WorldData<D>* w;
  Scalar widest;  ///< the largest `pair_radius` of the bodies, m (half a cell)
  bool regular;   ///< no body in a clamped cell (else every neighbouring cell is visited)
  Scalar reach;   ///< `pair_reach`: the records' and the searching body's radii are scaled by it
};

/// The cell of body i, as `SpatialHash::build` sorted it.
template <int D>
void grid_cell(const SpatialHash<D>& grid, const typename Space<D>::Vec& p, std::int32_t* c)
{
  for (int k = 0; k < 3; ++k) c[k] = k < D ? grid.cell_of(p[k], grid.inv_cell) : 0;
}

/// The pairs that awake bodies of the bit words [first_word, end_word) find around their cells,
/// in body order, written to `out` while fewer than `capacity`; `found` counts them all and
/// `examined` the records read.
///
/// A cell is as wide as the widest reach of two bodies, so a body can touch only bodies of the
/// 3^D cells around its own. Each pair is found once: two bodies of one bucket from the awake one
/// of lower key (a sleeper's key is above every awake one's); two bodies of neighbouring cells in
/// different buckets from the one whose cell comes first in the order (z, y, x), unless that one
/// sleeps, when the awake one looks back for sleepers. A bucket holds the cells of one hash,
/// so a body met in a neighbour's bucket counts only if it lies in that very cell. Each awake
/// body reads the records of its own bucket, the buckets of the cells after its own and the
/// sleepers at the end of those before: about half of the records around it while bodies fall.
template <int D>
void search_grid(const GridSearch<D>& s, std::uint32_t first_word, std::uint32_t end_word, Pair* out,
                 std::uint32_t capacity, std::uint32_t& found, std::uint32_t& examined)
{
  using Vec = typename Space<D>::Vec;
  const WorldData<D>& w = *s.w;
  const SpatialHash<D>& grid = w.grid;
  constexpr int neighbours = D == 3 ? 27 : 9;
  constexpr int own = neighbours / 2;
  const auto add = [&](std::uint32_t i, std::uint32_t j) {
    if (found < capacity) out[found] = make_pair(i < j ? i : j, i < j ? j : i);
    ++found;
  };
  // With no sleeper in the world the cells before a body's hold nothing it looks for.
  const bool sleepers = w.awake_count < w.body_count;
  const auto search = [&](std::uint32_t i) {
    const Body<D>& bi = w.bodies[i];
    const Vec p = bi.position;
    const Scalar radius = pair_radius(w, bi, s.reach);
    std::int32_t c[3];
    grid_cell(grid, p, c);
    // Where the body is in its cell, in cells: a neighbouring cell holds a body it can touch only
    // if the cell comes within the body's reach (its radius and the widest one). Cells beyond it
    // are skipped, with a margin for the rounding of x / cell. gap[k][d + 1]: the squared gap to
    // the cell at offset d along axis k; hash[k][d + 1]: that cell's term of the bucket's hash.
    Scalar gap[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    std::uint32_t hash[3][3];
    Scalar margin = Scalar(0.01);
    for (int k = 0; k < 3; ++k) {
      if (k < D) {
        const Scalar u = p[k] * grid.inv_cell;
        const Scalar low = u - std::floor(u), high = 1 - low;
        gap[k][0] = low * low;
        gap[k][2] = high * high;
        margin += std::fabs(u) * Scalar(1e-6);
      }
      for (int d = 0; d < 3; ++d) hash[k][d] = SpatialHash<D>::hash_term(k, c[k] + d - 1);
    }
    const Scalar r = (radius + s.widest) * grid.inv_cell + margin;
    const Scalar r2 = s.regular ? r * r : std::numeric_limits<Scalar>::infinity();
    const Scalar reach_max = radius + s.widest;
    const Scalar reach_max2 = reach_max * reach_max;
    const std::uint32_t mask = grid.buckets - 1;
    const std::uint32_t home = (hash[0][1] ^ hash[1][1] ^ hash[2][1]) & mask;
    int n = 0;
    for (int z = 0; z < (D == 3 ? 3 : 1); ++z)
      for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 3; ++x, ++n) {
          const int dz = D == 3 ? z : 1;
          // The order of the tests matters for speed only: this one is the same for every body
          // of a step, the gap's differs from body to body and cell to cell.
          if (n < own && !sleepers) continue;
          if (!(gap[0][x] + gap[1][y] + gap[2][dz] <= r2)) continue;
          const std::uint32_t b = n == own ? home : (hash[0][x] ^ hash[1][y] ^ hash[2][dz]) & mask;
          if (n != own && b == home) continue;  // its bodies are the own bucket's
          const GridItem<D>* const first = grid.items + grid.start[b];
          const GridItem<D>* it = first;
          const GridItem<D>* const end = grid.items + grid.start[b + 1];
          if (n < own) {
            // A cell before the body's: only its sleepers, at the end of the bucket.
            for (it = end; it != first && (it[-1].key & asleep_key) != 0;) --it;
          }
          examined += std::uint32_t(end - it);
          for (; it != end; ++it) {
            if (n == own && it->key <= i) continue;
            const Scalar d2 = (it->position - p).squaredNorm();
            if (d2 > reach_max2) continue;
            const Scalar reach = radius + it->radius;
            if (d2 > reach * reach) continue;
            if (n != own) {
              std::int32_t e[3];
              grid_cell(grid, it->position, e);
              if (e[0] != c[0] + x - 1 || e[1] != c[1] + y - 1 || e[2] != c[2] + dz - 1) continue;
            }
            add(i, it->key & ~asleep_key);
          }
        }
  };
  for (std::uint32_t k = first_word; k < end_word; ++k)
    for (std::uint32_t bits = w.awake[k]; bits != 0; bits &= bits - 1) search(k * 32 + lowest_bit(bits));
}

/// The number of bits set in x.
inline std::uint32_t bit_count(std::uint32_t x)
{
  x = x - ((x >> 1) & 0x55555555u);
  x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
  return (((x + (x >> 4)) & 0x0f0f0f0fu) * 0x01010101u) >> 24;
}

/// The fewest awake bodies worth a part of the grid's search of their own (a few tenths of a
/// millisecond of it), and the parts per worker.
constexpr std::uint32_t awake_per_part = 512;
constexpr std::uint32_t grid_parts_per_worker = 4;

/// One part of the grid's pair search on a worker: a run of awake bodies and its share of the
/// pair buffer.
struct GridPart {
  std::uint32_t first_word, end_word;  ///< bit words of `WorldData::awake`
  std::uint32_t offset, capacity;      ///< its share: pairs [offset, offset + capacity)
  std::uint32_t found, examined;
};

template <int D>
struct GridTask {
  const GridSearch<D>* search;
  GridPart* parts;
};

template <int D>
void run_grid_parts(std::uint32_t begin, std::uint32_t end, void* context)
{
  const GridTask<D>& t = *static_cast<const GridTask<D>*>(context);
  for (std::uint32_t p = begin; p < end; ++p) {
    GridPart& part = t.parts[p];
    search_grid(*t.search, part.first_word, part.end_word, t.search->w->pairs + part.offset, part.capacity, part.found,
                part.examined);
  }
}

/// The search on `Workers::count` workers. The awake bodies are cut into runs of about equal
/// numbers, and each run gets a share of the pair buffer in proportion. Joined in order, the runs'
/// pairs are those of one search over all bodies; when a run found more pairs than its share
/// holds, its pairs are incomplete, and the search runs again on the calling thread. Returns
/// false when it did not run (too few awake bodies to split); else `found` and `examined`.
template <int D>
bool search_grid_parts(const GridSearch<D>& s, std::uint32_t& found, std::uint32_t& examined)
{
  WorldData<D>& w = *s.w;
  const Workers& workers = w.def.workers;
  const std::uint32_t words = bit_words(w.body_count);
  // More parts than workers: the work per body varies (a body in a pile reads many more records
  // than one falling alone), and a worker done early takes the next part.
  std::uint32_t parts = workers.count * grid_parts_per_worker;
  if (parts > limits::max_workers) parts = limits::max_workers;
  if (parts > words) parts = words;
  // Parts of at least `awake_per_part` bodies: fewer would cost more to hand out than they save.
  if (w.awake_count / awake_per_part < parts) parts = w.awake_count / awake_per_part;
  if (parts < 2) return false;
  GridPart part[limits::max_workers];
  // Cut where the running count of awake bodies passes p / parts of them: one pass over the words.
  std::uint32_t p = 0, seen = 0;
  part[0].first_word = 0;
  for (std::uint32_t k = 0; k < words && p + 1 < parts; ++k) {
    seen += bit_count(w.awake[k]);
    if (std::uint64_t(seen) * parts >= std::uint64_t(p + 1) * w.awake_count) {
      part[p].end_word = k + 1;
      part[++p].first_word = k + 1;
    }
  }
  part[p].end_word = words;
  parts = p + 1;
  // Shares in proportion to the awake bodies up to the end of each run.
  std::uint32_t offset = 0, before = 0;
  for (std::uint32_t q = 0; q < parts; ++q) {
    for (std::uint32_t k = part[q].first_word; k < part[q].end_word; ++k) before += bit_count(w.awake[k]);
    const std::uint32_t end = q + 1 == parts ? w.max_pairs
                                             : std::uint32_t(std::uint64_t(w.max_pairs) * before / w.awake_count);
    part[q].offset = offset;
    part[q].capacity = end - offset;
    part[q].found = part[q].examined = 0;
    offset = end;
  }
  GridTask<D> task{&s, part};
  run_on_workers(w, parts, 1, &run_grid_parts<D>, &task);
  found = examined = 0;
  bool short_share = false;
  for (std::uint32_t q = 0; q < parts; ++q) {
    examined += part[q].examined;
    short_share = short_share || part[q].found > part[q].capacity;
  }
  if (short_share) {
    examined = 0;
    search_grid(s, 0, words, w.pairs, w.max_pairs, found, examined);
    return true;
  }
  for (std::uint32_t q = 0; q < parts; ++q) {
    // Moved down to the end of the pairs before: the gap only opens forward, so a copy from the
    // front never overwrites a pair it has yet to read.
    for (std::uint32_t k = 0; k < part[q].found; ++k) w.pairs[found + k] = w.pairs[part[q].offset + k];
    found += part[q].found;
  }
  return true;
}

/// Pairs from the grid of cells one widest reach (twice the largest `pair_radius`) wide: each
/// awake body looks at the bodies in the 3^D cells around its own. Returns how many were found
/// (also those that did not fit the buffer).
template <class FS, int D>
std::uint32_t find_pairs_grid(WorldData<D>& w, StepResult& result)
{
  SpatialHash<D>& grid = w.grid;
  // The widest reach of this step. Collision spheres change size with spin, so it is measured
  // afresh; it is never above the widest bounding diameter. It is taken without `pair_reach`:
  // the cell's size sets the order in which pairs are found, and so the order of the impacts.
  const Scalar reach = pair_reach<FS>(w);
  Scalar widest = 0;
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    const Scalar r = pair_radius<FS>(w, w.bodies[i]);
    widest = r > widest ? r : widest;
  }
  if (!(widest > 0)) widest = Scalar(0.5) * w.widest;
  grid.inv_cell = Scalar(1) / (2 * widest);
  // Bodies far out (or not finite) share clamped cells: then every neighbouring cell is visited.
  bool regular = true;
  const auto cell = [&w, &grid, &regular](std::uint32_t i, std::int32_t* c) {
    grid_cell(grid, w.bodies[i].position, c);
    for (int k = 0; k < 3; ++k) regular = regular && c[k] > -100000000 && c[k] < 100000000;
  };
  // The awake bit set tells the sleepers without reading the bodies; each record is made once.
  const auto asleep = [&w](std::uint32_t i) { return !bit_set(w.awake, i); };
  const auto item = [&w, &asleep, reach](std::uint32_t i) {
    const Body<D>& b = w.bodies[i];
    return GridItem<D>{b.position, pair_radius<FS>(w, b, reach), asleep(i) ? i + asleep_key : i};
  };
  grid.build(w.body_count, cell, item, asleep);
  made_records(w, true);
  result.broad_phase_bodies += w.body_count;
  const GridSearch<D> s{&w, widest, regular, reach};
  std::uint32_t found = 0, examined = 0;
#if STATSIM_WORKERS
  // (The parts' records are on the stack of `search_grid_parts`, called only with workers.)
  if (w.def.workers.count < 2 || !search_grid_parts(s, found, examined))
#endif
    search_grid(s, 0, bit_words(w.body_count), w.pairs, w.max_pairs, found, examined);
  result.pairs_examined += examined;
  return found;
}

/// Pairs from sweep-and-prune along `WorldDef::sweep_axis`. The entries keep last step's order,
/// so the insertion sort has little to do. Returns how many pairs were found.
template <class FS, int D>
std::uint32_t find_pairs_sweep(WorldData<D>& w, StepResult& result)
{
  // With no body awake there is no pair; if the entries were sorted on the bodies' present
  // places (a sweep with none awake, after which nothing moved) the sweep would not change them.
  if (w.awake_count == 0 && w.sweep_current && w.entry_count == w.body_count) return 0;
  // Bodies added since the last sweep join at the end, in order of creation.
  for (; w.entry_count < w.body_count; ++w.entry_count)
    new (&w.entries[w.entry_count]) SweepEntry(sweep_entry(w.entry_count, true));
  const int axis = w.def.sweep_axis;
  const Scalar common = w.common_bound;
  Scalar widest = 0;
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    SweepEntry& e = w.entries[i];
    const Body<D>& b = w.bodies[e.body];
    const Scalar bound = common > 0 ? common : w.shapes[b.shape].bounding_radius;
    e.lo = b.position[axis] - bound;
    e.hi = b.position[axis] + bound;
    e.active = b.state != MotionState::asleep ? 1u : 0u;
    widest = 2 * bound > widest ? 2 * bound : widest;
  }
  result.broad_phase_bodies += w.body_count;
  insertion_sort(w.entries, w.body_count);
  made_records(w, false);
  // Nothing moves in a step without awake bodies: the order stays valid for the next.
  w.sweep_current = w.awake_count == 0;
  // Its overlaps are not counted in `StepResult::pairs_examined`: a counter in the sweep's inner
  // loop costs it more than the count is worth.
  std::uint32_t found = 0;
  // With hull contacts every pair radius is the bounding radius where every shape has a hull.
  bool bounding = FS::hull_contacts && hull_contacts_on(w);
  for (std::uint32_t k = 0; k < w.shape_count; ++k) bounding = bounding && has_hull(w.shapes[k]);
  const Scalar reach_scale = pair_reach<FS>(w);
  const Scalar common_reach = common + common;
  const Scalar common_reach2 = common_reach * common_reach;
  const Body<D>* bodies = w.bodies;
  sweep_active(w.entries, w.body_count, widest,
               [&w, &found, bodies, common_reach, common_reach2, bounding, reach_scale](std::uint32_t a, std::uint32_t b) {
    // `candidate`'s first test, here where the sweep can keep body a's centre at hand: most pairs
    // whose intervals overlap are apart, and with one bounding radius for every shape the test
    // reads nothing else.
    if (common_reach > 0 && (bodies[b].position - bodies[a].position).squaredNorm() > common_reach2) return;
    candidate<FS>(w, a, b, common_reach, bounding, reach_scale, found);
  });
  return found;
}

/// Hands the broad phase's block from sweep-and-prune to the grid or back, keeping the sweep order:
/// entry k (12 bytes at 12 k) to index k (4 bytes at 4 k) in increasing k, and back in decreasing
/// k, so that nothing is overwritten before it is read.
template <class FS, int D>
void switch_broad_phase(WorldData<D>& w)
{
  if (!w.grid_layout) {
    for (std::uint32_t k = 0; k < w.entry_count; ++k) {
      const std::uint32_t body = w.entries[k].body;
      new (&w.order[k]) std::uint32_t(body);
    }
  } else {
    for (std::uint32_t k = w.entry_count; k-- > 0;) {
      const std::uint32_t body = w.order[k];
      new (&w.entries[k]) SweepEntry(sweep_entry(body, true));
    }
  }
  w.grid_layout = !w.grid_layout;
  w.index.valid = false;  // until the phase switched to makes its records
}

/// Fills the pair buffer with this step's candidate pairs, up to its capacity; the result tells
/// how many were found and how many did not fit.
template <class FS, int D>
void find_pairs(WorldData<D>& w, StepResult& result)
{
  std::uint32_t found = 0;
  bool grid = false;
  // A world without the grid's storage (`World`'s `Phases`) never holds the grid's layout.
  if constexpr (FS::grid) {
    grid = w.grid_storage && (w.def.broad_phase == BroadPhase::grid ||
                              (w.def.broad_phase == BroadPhase::automatic && w.body_count > w.def.grid_above_bodies));
    if (grid != w.grid_layout) switch_broad_phase<FS>(w);
    if (grid) {
      // The grid keeps nothing from step to step but its sizes; bodies move under the entries.
      w.sweep_current = false;
      // Two sleepers are never a pair.
      if (w.awake_count > 0) found = find_pairs_grid<FS>(w, result);
    }
  }
  if (!grid) found = find_pairs_sweep<FS>(w, result);
  result.pairs_found = found;
  if (found > w.max_pairs) {
    result.pairs_dropped = found - w.max_pairs;
    result.overflow |= overflow_pairs;
  }
  w.pair_count = found < w.max_pairs ? found : w.max_pairs;
}

}  // namespace detail
}  // namespace statsim
