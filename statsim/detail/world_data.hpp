#pragma once
/// @file
/// The data the phases of a step share: `WorldData` (the world's arrays, counts and parameters,
/// capacity-erased), `StepContext` (what one step counts as it goes), the first phase
/// (`integrate`) and the state hash.

#include "statsim/world_def.hpp"
#include "statsim/world_ids.hpp"
#include "statsim/random.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace statsim {
namespace detail {

/// Words of a bit set of `n` bodies.
constexpr std::uint32_t bit_words(std::uint32_t n)
{
  return (n + 31) / 32;
}

/// Index of the lowest set bit of `x` (not 0).
inline std::uint32_t lowest_bit(std::uint32_t x)
{
#if defined(__GNUC__) || defined(__clang__)
  return std::uint32_t(__builtin_ctz(x));
#else
  std::uint32_t i = 0;
  while (!(x & 1u)) {
    x >>= 1;
    ++i;
  }
  return i;
#endif
}

/// Calls `f(i)` for every body i whose bit is set in the first `bit_words(count)` words, in
/// increasing order, at a cost of one word per 32 bodies plus the bodies set. Each word is read
/// once, before its bodies are visited: `f` may clear the bit of the body it is given.
template <class F>
void for_each_set(const std::uint32_t* words, std::uint32_t count, F&& f)
{
  const std::uint32_t n = bit_words(count);
  for (std::uint32_t k = 0; k < n; ++k)
    for (std::uint32_t bits = words[k]; bits != 0; bits &= bits - 1) f(k * 32 + lowest_bit(bits));
}

inline void set_bit(std::uint32_t* words, std::uint32_t i)
{
  words[i / 32] |= std::uint32_t(1) << (i % 32);
}
inline bool bit_set(const std::uint32_t* words, std::uint32_t i) { return (words[i / 32] >> (i % 32)) & 1u; }
inline void clear_bit(std::uint32_t* words, std::uint32_t i)
{
  words[i / 32] &= ~(std::uint32_t(1) << (i % 32));
}

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
  /// contact passes leave their slope contacts alone. Scratch of the step, not part of the state.
  std::uint32_t* rolled;
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

/// What one step counts as its phases run; the passes reset the counter they test.
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

/// True when the plane of unit normal `n` is tilted: it carries weight (n.g < 0) and gravity
/// `g` pulls along it (a part that is not exactly zero). Writes g.n to `gn`.
template <class Vec>
bool is_tilted_plane(const Vec& g, const Vec& n, Scalar& gn)
{
  gn = g.dot(n);
  return gn < 0 && (g - n * gn).squaredNorm() > 0;
}

/// True when some plane is tilted (`WorldData::tilted_planes`, set as planes are added).
template <int D>
bool any_tilted_plane(const WorldData<D>& w)
{
  Scalar gn;
  for (std::uint32_t p = 0; p < w.plane_count; ++p)
    if (is_tilted_plane(w.def.gravity, w.planes[p].normal, gn)) return true;
  return false;
}

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

/// How far beyond its collision sphere, as a fraction of its radius, the broad phase looks for a
/// body's contacts. The step's passes move bodies after the broad phase (out of the ground, out of
/// one another), and a pair they bring into touch is met in that step only if it is a candidate.
constexpr Scalar pair_margin = Scalar(0.1);

/// The radius within which the broad phase looks for a body's contacts, m: its bounding radius
/// where it may touch at its hull (`BodyContacts::hulls`), else its collision sphere's with
/// `pair_margin`, at most its bounding radius. A bunny's collision sphere is about 0.6 of its
/// bounding radius: the grid's cells shrink to 0.66 of the bounding diameter, and their volume
/// to 0.3; a pile's candidate pairs, and the pair buffer it needs, to a fifth.
template <int D>
Scalar pair_radius(const WorldData<D>& w, const Body<D>& b)
{
  const Shape<D>& s = w.shapes[b.shape];
  if (w.def.body_contacts == BodyContacts::hulls && has_hull(s)) return s.bounding_radius;
  const Scalar r = b.radius * (1 + pair_margin);
  return r < s.bounding_radius ? r : s.bounding_radius;
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

/// True when the sleep test measures the body's centre from where its slow time began
/// (`update_motion_states`): with hull contacts, for a shape whose table has body-body data (an
/// older table steps exactly as with collision spheres).
template <int D>
bool sleeps_from_anchor(const WorldData<D>& w, const Body<D>& b)
{
  const Shape<D>& s = w.shapes[b.shape];
  return w.def.body_contacts == BodyContacts::hulls && s.statistical && s.signature.contact.present();
}

/// Semi-implicit Euler for awake bodies: gravity and damping change the velocity, which then
/// moves the body; orientation without trigonometry (`detail::integrate`). `own(i)` may move
/// body i through the step itself (`roll_on_slopes`) and return true. Returns the number of
/// bodies integrated.
template <int D, class Own>
std::uint32_t integrate(WorldData<D>& w, Scalar dt, Own&& own)
{
  using Vec = typename Space<D>::Vec;
  const Vec dv = w.def.gravity * dt;
  const Scalar lin_damp = Scalar(1) / (1 + dt * w.def.linear_damping);
  const Scalar ang_damp = Scalar(1) / (1 + dt * w.def.angular_damping);
  const bool hulls = w.def.body_contacts == BodyContacts::hulls;
  std::uint32_t count = 0;
  for_each_set(w.awake, w.body_count, [&](std::uint32_t i) {
    Body<D>& b = w.bodies[i];
    // The sleep test may measure from where the body's slow time began (`sleeps_from_anchor`):
    // the centre is kept there while the clock runs.
    if (b.slow_time == 0 || !hulls || !sleeps_from_anchor(w, b)) b.step_start = b.position;
    ++count;
    if (own(i)) return;
    b.linear_velocity = (b.linear_velocity + dv) * lin_damp;
    b.angular_velocity = b.angular_velocity * ang_damp;
    b.position += b.linear_velocity * dt;
    b.orientation = integrate(b.orientation, b.angular_velocity, dt);
  });
  return count;
}

/// Adds every parameter of a world to a hash. A new `WorldDef` field belongs here too, but for
/// `WorldDef::workers`, which does not change results.
template <int D>
void hash_def(Fnv1a& h, const WorldDef<D>& d)
{
  h.add_vec(d.gravity);
  h.add_all(d.seed, d.restitution_threshold, d.settle_speed, d.sleep_speed, d.sleep_time, d.wake_speed,
            d.linear_damping, d.angular_damping, std::int32_t(d.support_iterations),
            std::uint8_t(d.shock_propagation), std::int32_t(d.position_iterations), d.allowed_overlap,
            d.overlap_correction, d.spin_ratio_speed_floor, std::uint8_t(d.nearest_radius),
            std::uint8_t(d.pair_response), std::uint8_t(d.rest_conditions), std::uint8_t(d.pile_rest),
            d.rest_blend_time, d.rest_turn_time, d.rest_snap_cosine, d.ground_cosine, std::uint8_t(d.broad_phase),
            d.grid_above_bodies, std::int32_t(d.sweep_axis), std::uint8_t(d.table_restitution_threshold));
  // Added only when not the default, so that worlds from before the option keep their hashes.
  if (d.body_contacts != BodyContacts::collision_spheres) h.add(std::uint8_t(d.body_contacts));
  if (d.impact_threshold != WorldDef<D>{}.impact_threshold) h.add(d.impact_threshold);
}

/// Adds a table's numbers as the runtime reads them (16-bit ones as their values).
inline void hash_values(Fnv1a& h, const ValuesView& v, std::uint32_t n)
{
  for (std::uint32_t i = 0; i < n; ++i) h.add(v[i]);
}
inline void hash_axis(Fnv1a& h, const AxisView& a)
{
  h.add(a.size);
  for (std::uint32_t i = 0; i < a.size; ++i) h.add(a.values[i]);
}

/// FNV-1a hash of everything of a signature that a step reads: its scalars, axes, tables and
/// rest poses. Computed once, by `add_shape`; the signature must have passed `check_signature`.
template <int D>
std::uint64_t signature_hash(const SignatureView<D>& sig)
{
  Fnv1a h;
  h.add_all(sig.length, sig.bounding_radius, sig.mass, sig.unit_inertia[0], sig.unit_inertia[1],
            sig.unit_inertia[2], sig.material.restitution, sig.material.friction, sig.material.rolling_resistance,
            sig.restitution_threshold, std::uint8_t(sig.layout));
  hash_axis(h, sig.height.spin_ratio);
  hash_values(h, sig.height.mean, sig.height.spin_ratio.size);
  hash_values(h, sig.height.stddev, sig.height.spin_ratio.size);
  const ResponseTableView& r = sig.response;
  h.add_all(r.axis_count, r.components, std::uint8_t(r.model), r.spread_per_cell);
  std::uint32_t cells = 1;
  for (std::uint32_t a = 0; a < r.axis_count; ++a) {
    hash_axis(h, r.axes[a]);
    cells *= r.axes[a].size;
  }
  hash_values(h, r.mean, cells * r.components);
  hash_values(h, r.spread, cells * r.spread_per_cell);
  h.add(sig.rest.count);
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    h.add_vec(sig.rest.normal(i));
    h.add(sig.rest.heights[i]);
    h.add(sig.rest.frequencies[i]);
  }
  // Body-body data, when the table has it (a table without it hashes as before).
  const ContactView<D>& c = sig.contact;
  if (!c.present()) return h.value;
  h.add_all(c.support_size, c.face_count);
  hash_values(h, c.support, c.support_count());
  for (std::uint32_t i = 0; i < c.face_count * face_values(D); ++i) h.add(c.faces[i]);
  if (c.offset_scale != 1) h.add(c.offset_scale);  // a shape of another size (a table's own hashes as before)
  for (std::size_t k = 0; k < 3; ++k) h.add_all(c.packing_mean[k], c.packing_stddev[k]);
  if (c.pair_mean != nullptr)
    for (std::uint32_t i = 0; i < sig.height.spin_ratio.size; ++i) h.add_all(c.pair_mean[i], c.pair_stddev[i]);
  return h.value;
}

/// FNV-1a hash of the world's state (see `WorldCore::state_hash`).
template <int D>
std::uint64_t state_hash(const WorldData<D>& w)
{
  Fnv1a h;
  h.add_all(w.body_count, w.plane_count, w.shape_count, w.step_count);
  hash_def(h, w.def);
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    const Body<D>& b = w.bodies[i];
    h.add_vec(b.position);
    h.add_rot(b.orientation);
    h.add_vec(b.linear_velocity);
    h.add_spin(b.angular_velocity);
    h.add_all(b.radius, w.shapes[b.shape].bounding_radius, b.inv_mass, b.slow_time, std::uint64_t(b.rng_state),
              b.rest_blend, b.shape,
              std::uint8_t(b.state), std::uint8_t(b.touching), std::uint8_t(b.on_ground), b.rest_pose,
              std::uint8_t(b.pile_rest));
  }
  for (std::uint32_t i = 0; i < w.plane_count; ++i) {
    h.add_vec(w.planes[i].normal);
    h.add(w.planes[i].offset);
  }
  for (std::uint32_t i = 0; i < w.shape_count; ++i) {
    const Shape<D>& s = w.shapes[i];
    h.add_all(s.radius, s.bounding_radius, s.material.restitution, s.material.friction,
              s.material.rolling_resistance, std::uint8_t(s.statistical));
    if (!s.statistical) continue;
    h.add(s.signature_hash);
    h.add(s.mean_rest_height);
    for (std::uint32_t k = 0; k < s.signature.rest.count; ++k) h.add(s.rest_bias[k]);
  }
  // Slot generations decide the ids and random streams of reused slots; a world that never
  // removed a body has none and hashes as before removal existed.
  std::uint32_t removals = 0;
  for (std::uint32_t i = 0; i < w.body_count; ++i) removals += w.slots.generation[i];
  if (removals > 0)
    for (std::uint32_t i = 0; i < w.body_count; ++i) h.add(w.slots.generation[i]);
  // The sweep-and-prune order breaks ties between equal interval starts, so it decides the order
  // of pairs, and with it of contacts.
  h.add(w.entry_count);
  for (std::uint32_t i = 0; i < w.entry_count; ++i) h.add(w.grid_layout ? w.order[i] : w.entries[i].body);
  return h.value;
}

}  // namespace detail
}  // namespace statsim
