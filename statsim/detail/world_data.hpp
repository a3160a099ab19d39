#pragma once
/// @file
/// The data the phases of a step share: `WorldData` (the world's arrays, counts and parameters,
/// capacity-erased), `StepContext` (what one step counts as it goes), and what every phase asks of
/// a body: its shape's reach, lever arm and random stream. `wake` is here, not with the motion
/// states (sleep.hpp), because it keeps `WorldData::awake` and `awake_count` in step and every
/// phase that can wake a body calls it.

#include "statsim/detail/bits.hpp"
#include "statsim/detail/grid.hpp"
#include "statsim/detail/sweep.hpp"
#include "statsim/features.hpp"
#include "statsim/detail/ids.hpp"
#include "statsim/detail/query_index.hpp"
#include "statsim/random.hpp"
#include "statsim/world_def.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace statsim {
namespace detail {

/// A touching pair's hull contact at a face (`Pair::witness` >= 1, `STATSIM_HULL_CACHE`): its
/// normal (from a to b) and the separation of the centres along it at which the pair touches,
/// packing included (m). Both depend on the two orientations alone, which no pass of a step
/// changes, so the passes after the one that found them read them here (`body_contact`).
/// `reach` 0: none kept (a contact along the line of centres, whose normal moves with the
/// bodies, or a pair of collision spheres).
template <int D>
struct PairHull {
  typename Space<D>::Vec normal;
  Scalar reach;
};

/// A world's storage (owned by `World<>`), counts and parameters: what every phase reads.
template <int D>
struct WorldData {
  Body<D>* bodies;
  /// The sweep-and-prune order of the first `entry_count` bodies: in `entries` while
  /// sweep-and-prune runs, as body indices in `order` while the grid does (`grid_layout`); the
  /// two share their storage with the grid's (`BroadPhaseLayout`).
  SweepEntry* entries;
  std::uint32_t* order;
  Pair* pairs;
  Plane<D>* planes;
  Shape<D>* shapes;
  SpatialHash<D> grid;
  /// Bit set of the bodies that are not asleep: the phases of a step walk these, so a sleeping
  /// body costs nothing until it wakes.
  std::uint32_t* awake;
  /// Bit set of the bodies that fell asleep in the last step, whose `touching` and `on_ground`
  /// may still be set: the next step clears their flags with the awake bodies' and those of the
  /// last step's touching pairs (the only sleepers the passes mark).
  std::uint32_t* flagged;
  /// Bit set of the bodies that this step moved in substeps on a slope (`roll_on_slopes`): the
  /// contact passes leave their slope contacts alone. Scratch of the step, not part of the state:
  /// after the contact passes it holds the islands' marks (`WorldDef::sleep_islands`,
  /// `update_motion_states`), and the next step clears it before a substep writes it.
  std::uint32_t* rolled;
  /// With `WorldDef::ground_hulls`, bit set of the awake bodies that meet level ground with their
  /// hull in this step (`ground_hull`): those on the ground at its start (their `on_ground`
  /// before `forget_contacts` clears it) and those landing as slowly as a hop's landing
  /// (`slow_landing`); a body that arrives from flight faster gets the statistical
  /// response. Scratch of the step, written by `integrate` from the state at the step's start: a
  /// snapshot needs nothing.
  std::uint32_t* hull_ground;
  /// Bit set of the bodies in at least one of this step's candidate pairs (`mark_paired`, after
  /// the broad phase): a body with none has no other body near it, and its rest turn pivots
  /// about the point it stands on (`respond_alone`). Scratch of the step: a snapshot needs nothing.
  std::uint32_t* paired;
  std::uint32_t max_bodies, max_pairs, max_planes, max_shapes;
  std::uint32_t body_count = 0, pair_count = 0, plane_count = 0, shape_count = 0;
  /// Bodies that have a sweep entry: sweep-and-prune adds the entries of newer bodies when it
  /// next runs, so the grid never touches them.
  std::uint32_t entry_count = 0;
  std::uint32_t touching_pairs = 0;  ///< last step's touching pairs, at the front of `pairs`
  std::uint32_t awake_count = 0;  ///< bodies not asleep
  Scalar widest = 0;  ///< the largest bounding diameter of the bodies, m
  /// The bounding radius every shape of the world has, m, or 0 when they differ: the broad
  /// phase's tests then need not look up the shapes of the bodies they compare.
  Scalar common_bound = 0;
  /// The sweep-and-prune entries hold every body's interval, sorted, and no body has moved since:
  /// a sweep with no awake body would change nothing and find no pair.
  bool sweep_current = false;
  bool grid_layout = false;  ///< the broad phase's block holds the grid (see `entries`)
  bool grid_storage = true;  ///< the block has room for the grid (`World`'s `Phases`)
  /// What the world's step is compiled with (`World`'s `Features`): calls that need more are
  /// refused (`refuses_features`).
  Features features = Features::all;
  /// Some plane is tilted (`is_tilted_plane`): bodies meet tilted planes with their hulls.
  bool tilted_planes = false;
  std::uint64_t step_count = 0;
  std::uint64_t energy_clamps = 0;  ///< over the world's life
  std::uint64_t statistical_responses = 0;  ///< over the world's life
  WorldDef<D> def{};
  BodySlots slots{};  ///< what names the body in each slot (`remove_body`)
  QueryIndex index{};  ///< the broad phase's records as the queries see them
  /// The touching pairs' hull contacts, entry k for pair k, as the impact pass left them and,
  /// after the shock pass sorted the pairs, as it found them; `max_pair_hulls` 0 without them
  /// (`STATSIM_HULL_CACHE`). Scratch of the step, not part of the state.
  PairHull<D>* pair_hulls = nullptr;
  std::uint32_t max_pair_hulls = 0;
};

/// What one step counts as its phases run; the passes reset the counter they test. `FS`: the
/// world's `FeatureSet`, which the passes read from their context's type.
template <class FS>
struct StepContext {
  /// Body-body contacts of the impact pass: the pairs at the front of the pair buffer that the
  /// later passes visit.
  std::uint32_t touching = 0;
  std::uint32_t moves = 0;          ///< position corrections since the counter was reset
  std::uint32_t changes = 0;        ///< impulses and position corrections since it was reset
  std::uint32_t energy_clamps = 0;  ///< sampled responses the energy guard scaled down
  std::uint32_t statistical_responses = 0;  ///< sampled responses applied
  Scalar dt = 0;                    ///< the step's time step, s
  bool tilted_planes = false;       ///< `any_tilted_plane`: some contact may be on a slope
};

/// Records the bounding radius of a shape just added (`WorldData::common_bound`).
template <int D>
void note_bound(WorldData<D>& w, Scalar bound)
{
  w.common_bound = w.shape_count == 0 || bound == w.common_bound ? bound : Scalar(0);
}

/// True when body-body contacts of this shape can use its hull: a statistical shape whose table
/// has body-body data, or a plain sphere.
template <int D>
bool has_hull(const Shape<D>& s)
{
  return !s.statistical || s.signature.contact.present();
}

/// True when bodies meet at their hulls where both tables have body-body data: `BodyContacts::hulls`,
/// or `automatic` in a world compiled with `Features::hull_contacts` (a world without it refuses
/// `hulls`). The step's code tests its feature set first, `FS::hull_contacts && hull_contacts_on(w)`:
/// a constant, so that a step compiled without hull contacts has none of their code even where
/// nothing is inlined (tests/api/features_code.cmake).
template <int D>
bool hull_contacts_on(const WorldData<D>& w)
{
  return includes(w.features, Features::hull_contacts) && w.def.body_contacts != BodyContacts::collision_spheres;
}

/// How far beyond its collision sphere, as a fraction of its radius, the broad phase looks for a
/// body's contacts. The step's passes move bodies after the broad phase (out of the ground, out of
/// one another), and a pair they bring into touch is met in that step only if it is a candidate.
constexpr Scalar pair_margin = Scalar(0.1);

/// The radius within which the broad phase looks for a body's contacts, m: its bounding radius
/// where it may touch at its hull (`BodyContacts::hulls`), else its collision sphere's with
/// `pair_margin`, at most its bounding radius. A bunny's collision sphere is about 0.6 of its
/// bounding radius: the grid's cells shrink to 0.66 of the bounding diameter, and their volume
/// to 0.3; a pile's candidate pairs, and the pair buffer it needs, to a fifth.
/// `reach`: the factor on bounding radii of `pair_reach` (1 where not given).
template <class FS = AllFeatures, int D>
Scalar pair_radius(const WorldData<D>& w, const Body<D>& b, Scalar reach = 1)
{
  const Shape<D>& s = w.shapes[b.shape];
  if (FS::hull_contacts && hull_contacts_on(w) && has_hull(s)) return s.bounding_radius * reach;
  const Scalar r = b.radius * (1 + pair_margin);
  return r < s.bounding_radius ? r : s.bounding_radius;
}

/// The factor on bounding radii within which the broad phase looks for hull contacts: 1, or in a
/// world whose shapes are all statistical with body-body data, their largest packing ratio
/// (`Shape::largest_packing`, at most 1) with a margin. The impact pass's search takes such a
/// pair as apart beyond that ratio times the sum of their bounding radii (`search_witness`), so
/// the pairs the broad phase no longer lists are pairs that would never touch (for the bunny,
/// statsim/README.md). A plain sphere's ratio is 1, and a shape without a hull meets others at its
/// collision sphere, which this does not bound.
template <class FS = AllFeatures, int D>
Scalar pair_reach(const WorldData<D>& w)
{
  if (!FS::hull_contacts || !hull_contacts_on(w) || w.shape_count == 0) return 1;
  Scalar p = 0;
  for (std::uint32_t k = 0; k < w.shape_count; ++k) {
    const Shape<D>& s = w.shapes[k];
    if (!s.statistical || !has_hull(s)) return 1;
    p = s.largest_packing > p ? s.largest_packing : p;
  }
  // Ten times `search_witness`'s own margin, so that rounding in the two sums cannot part them.
  p *= Scalar(1.001);
  return p < 1 ? p : Scalar(1);
}

/// Lever arm of a body in the particle response: its radius for a sphere; 0 for a statistical
/// body, whose sphere is not its shape, so friction on the sphere must not spin it (a spin it
/// does not have would come back as speed).
template <int D>
Scalar contact_radius(const WorldData<D>& w, const Body<D>& b)
{
  return w.shapes[b.shape].statistical ? Scalar(0) : b.radius;
}

/// The body's random stream, where it left off.
template <int D>
Pcg32 rng_of(const WorldData<D>& w, const Body<D>& b)
{
  return Pcg32::resume(b.rng_state, body_stream(w.def.seed, std::uint32_t(&b - w.bodies)));
}

/// With hull contacts, a sleeper that an awake body presses more than this fraction of the
/// separation at which their hulls touch into wakes, however slowly they approach, if that body
/// moves or turns (its still time is 0, or it spins), and past twice this fraction whatever the
/// pressing body does. A hull's reach grows as its body turns (toward its rest pose, or
/// tipping), and asleep a neighbour cannot give way: held between it and other sleepers, the
/// awake body would be thrown from one to the next by the overlap correction in every step and
/// fall asleep inside whichever it last met. Collision spheres keep their reach when they turn.
/// A still body below twice the fraction does not wake its neighbour, so that two bodies held
/// together that deep by their own neighbours do not wake each other in turn for ever.
constexpr Scalar hull_wake_overlap = Scalar(0.1);

template <int D>
void wake(WorldData<D>& w, Body<D>& b)
{
  if (b.state == MotionState::asleep) {
    set_bit(w.awake, std::uint32_t(&b - w.bodies));
    ++w.awake_count;
  }
  b.state = MotionState::moving;
  b.slow_time = 0;
  b.step_start = b.position;  // a sleeper is not integrated: this is where it started the step
}

/// With `WorldDef::sleep_islands`, sleep times after which a still body falls asleep whatever its
/// island does (a still body out of its pose needs 3).
constexpr Scalar island_wait = 4;

/// With `WorldDef::sleep_islands`, at the end of a step: true when the sleeper `s` joins the
/// island of `b`, which touches it: `b` is awake and was not still in the step, and `s` did not
/// fall asleep in it (`flagged`: an island that has just come to rest is not woken again by a
/// neighbour that has not) nor by `island_wait` (it slept whatever its island did: joined again
/// whenever a neighbour stays restless, two bodies of a pile that keep each other restless would
/// hold it awake for ever).
template <int D>
bool joins_island(const WorldData<D>& w, const Body<D>& b, const Body<D>& s)
{
  return s.state == MotionState::asleep && b.state != MotionState::asleep && b.slow_time <= 0 &&
         s.slow_time < island_wait * w.def.sleep_time && !bit_set(w.flagged, std::uint32_t(&s - w.bodies));
}

/// Wakes a sleeper that an awake neighbour joins to its island (`WorldDef::sleep_islands`): as
/// `wake`, but it keeps its still time, since nothing has moved it yet, and it is settling, not
/// moving, so that with hull contacts it keeps its hull out of the ground (`hull_radius`) while
/// the pile presses on it.
template <int D>
void join_island(WorldData<D>& w, Body<D>& b)
{
  const Scalar still = b.slow_time;
  wake(w, b);
  b.slow_time = still;
  b.state = MotionState::settling;
}

/// True when the sleep test measures the body's centre from where its slow time began
/// (`update_motion_states`): with hull contacts, for a shape whose table has body-body data (an
/// older table steps exactly as with collision spheres).
template <class FS = AllFeatures, int D>
bool sleeps_from_anchor(const WorldData<D>& w, const Body<D>& b)
{
  const Shape<D>& s = w.shapes[b.shape];
  return FS::hull_contacts && hull_contacts_on(w) && s.statistical && s.signature.contact.present();
}

}  // namespace detail
}  // namespace statsim
