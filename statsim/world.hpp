#pragma once
/// @file
/// The world: fixed-capacity arrays of bodies and planes, and `step()`.
///
/// `World<D, MaxBodies, ...>` owns the storage; everything it does is implemented once in the
/// capacity-erased `WorldCore<D>`, so helpers can take a `WorldCore<3>&` whatever the capacity and
/// the code is compiled once per dimension, not once per capacity.
///
/// A step, in order (each phase is a function of `detail`, in the file of statsim/detail/ named):
///  1. integrate awake bodies (semi-implicit Euler; orientation without trigonometry;
///     integrate.hpp; a body rolling on a slope in substeps with its slope contacts,
///     slope_contact.hpp) and set the statistical bodies' collision radii (sleep.hpp);
///  2. broad phase: pairs within `detail::pair_radius` of each other, from a hashed grid or from
///     sweep-and-prune (intervals on the bounding radius; broad_phase.hpp); then the
///     impacts of the step are recorded (events.hpp);
///  3. impact pass: body-plane then body-body contacts get the bodies' response (the statistical
///     response for statistical bodies, the particle response for plain spheres); planes push
///     bodies out of them (contact_passes.hpp, as are 4 and 5);
///  4. support passes (`WorldDef::support_iterations`): inelastic, removing approach velocity
///     left at resting contacts, planes last;
///  5. shock pass: contacts from the bottom up, the lower body immovable; overlaps between bodies
///     are corrected here, softly (`allowed_overlap`, `overlap_correction`), then again in
///     `position_iterations` passes that only move bodies;
///  6. motion state (sleep.hpp): moving, settling (slow and touching), asleep (slow for
///     `sleep_time`).
/// Sleeping bodies are not integrated and act as static supports until hit harder than
/// `wake_speed` (or, with hull contacts, pressed deep: `detail::hull_wake_overlap`).

#include "statsim/detail/body_ops.hpp"
#include "statsim/detail/broad_phase.hpp"
#include "statsim/detail/checks.hpp"
#include "statsim/detail/contact_passes.hpp"
#include "statsim/detail/events.hpp"
#include "statsim/detail/feature_checks.hpp"
#include "statsim/detail/integrate.hpp"
#include "statsim/detail/shape_setup.hpp"
#include "statsim/detail/sleep.hpp"
#include "statsim/detail/slope.hpp"
#include "statsim/detail/state_hash.hpp"
#include "statsim/detail/world_data.hpp"
#include "statsim/detail/world_storage.hpp"
#include "statsim/features.hpp"
#include "statsim/signature_scale.hpp"
#include "statsim/world_def.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace statsim {
namespace detail {
struct SnapshotAccess;  // statsim/snapshot.hpp: `load` writes a world's arrays
struct CoreAccess;      // below: the runtime's own read access to a world's arrays
}  // namespace detail

/// Capacity-erased world: all the logic, working on storage that `World<>` provides.
template <int D>
class WorldCore {
 public:
  using Vec = typename Space<D>::Vec;
  using Rot = typename Space<D>::Rot;
  using Spin = typename Space<D>::Spin;

  WorldCore(const WorldCore&) = delete;
  WorldCore& operator=(const WorldCore&) = delete;

  /// Replaces the world's parameters. Rejected with `invalid_parameter` (or `non_finite`) if any
  /// is out of range, or if it asks for `BroadPhase::grid` in a world that keeps storage for
  /// sweep-and-prune only; with `not_compiled` if it asks for hull contacts in a world without
  /// `Features::hull_contacts`, or for a gravity that tilts a plane of a world without
  /// `Features::slopes`; the world then keeps the parameters it had.
  Status configure(const WorldDef<D>& def)
  {
    Status s = detail::check_world_def(def);
    // A world without the grid's storage (`World`'s `Storage` parameter) cannot run it.
    if (s == Status::ok && def.broad_phase == BroadPhase::grid && !w_.grid_storage) s = Status::invalid_parameter;
    if (s == Status::ok) s = detail::check_features(w_, def);
    if (s == Status::ok) {
      w_.def = def;
      w_.sweep_current = false;  // the sweep axis may have changed
    }
    return s;
  }
  const WorldDef<D>& def() const { return w_.def; }
  /// Status of the construction. `ok`; or why the parameters given were refused (the world then
  /// uses the defaults); or, with valid parameters, `float_contraction`: this build fuses
  /// floating-point operations (see `detail::float_contraction`), so the world works but its
  /// results differ in the last bits from builds with `-ffp-contract=off` (the CMake targets).
  Status construction_status() const { return construction_status_; }
  /// This world's tag, carried by the shape ids it issues (`ShapeId::world`), 1 to 65535.
  std::uint16_t tag() const { return tag_; }

  /// Registers a plain sphere shape. Rejected with `non_finite`, `invalid_radius`,
  /// `invalid_mass`, `invalid_material` or `out_of_range` on bad input, with
  /// `capacity_exceeded` when the shape pool is full.
  Added<ShapeId> add_shape(const ShapeDef& def)
  {
    const Scalar bound = def.bounding_radius == 0 ? def.radius : def.bounding_radius;
    const Status s = detail::check_shape_def(def, bound);
    if (s != Status::ok) return {s, ShapeId{}};
    if (w_.shape_count == w_.max_shapes) return {Status::capacity_exceeded, ShapeId{}};
    w_.shapes[w_.shape_count] = Shape<D>{def.radius, bound, def.material, false, SignatureView<D>{}, {},
                                         def.radius, 0, def.radius, 1, def.mass};
    detail::note_bound(w_, bound);
    return {Status::ok, ShapeId(std::uint16_t(w_.shape_count++), tag_)};
  }

  /// Registers a statistical shape from its signature (`tables::NAME.view()`). The view is
  /// copied; the tables it points to must outlive the world (generated tables are static).
  /// Rejected with `invalid_shape` if the signature is malformed (a pointer missing for a count
  /// above 0, a number out of its range) or has more than `max_rest_poses` rest poses, and with
  /// `out_of_range` if its mass (the default mass of its bodies) is beyond `limits`. Computes
  /// the rest-pose basins (`rest_basin_biases`), which takes a while for a shape with many rest
  /// poses: add shapes while setting up, not during steps.
  Added<ShapeId> add_shape(const SignatureView<D>& sig)
  {
    if (!includes(w_.features, Features::statistical)) return {Status::not_compiled, ShapeId{}};
    const Status s = detail::check_signature(sig);
    if (s != Status::ok) return {s, ShapeId{}};
    if (w_.shape_count == w_.max_shapes) return {Status::capacity_exceeded, ShapeId{}};
    Shape<D>& shape = w_.shapes[w_.shape_count];
    detail::statistical_shape(sig, shape);
    rest_basin_biases<D>(sig, shape.rest_bias.data());
    detail::note_bound(w_, shape.bounding_radius);
    return {Status::ok, ShapeId(std::uint16_t(w_.shape_count++), tag_)};
  }

  /// A statistical shape `scale` times its table's size (`scaled_view`; 1: `add_shape(sig)` bit for bit).
  /// Rejected with `non_finite`, `out_of_range` (outside [`min_shape_scale`, `max_shape_scale`]), or as above.
  Added<ShapeId> add_shape(const SignatureView<D>& sig, Scalar scale)
  {
    if (!std::isfinite(scale)) return {Status::non_finite, ShapeId{}};
    if (!(scale >= min_shape_scale && scale <= max_shape_scale)) return {Status::out_of_range, ShapeId{}};
    return add_shape(scaled_view(sig, scale));
  }

  /// Adds a static plane with the given normal (any length > 0; it is normalised) through the
  /// point normal_unit * offset. Fails with `capacity_exceeded` when the plane pool is full, and
  /// with `not_compiled` for a tilted plane (`detail::is_tilted_plane`) in a world without
  /// `Features::slopes`.
  Added<PlaneId> add_plane(const Vec& normal, Scalar offset)
  {
    if (!detail::finite(normal) || !detail::finite(offset)) return {Status::invalid_plane, 0};
    if (!detail::within(offset, limits::coordinate)) return {Status::out_of_range, 0};
    const Scalar len = normal.norm();
    if (!(len > Scalar(1e-12)) || !detail::finite(len)) return {Status::invalid_plane, 0};
    if (w_.plane_count == w_.max_planes) return {Status::capacity_exceeded, 0};
    if (detail::check_plane_features(w_.features, w_.def.gravity, Vec(normal / len)) != Status::ok)
      return {Status::not_compiled, 0};
    w_.planes[w_.plane_count] = Plane<D>{normal / len, offset};
    ++w_.plane_count;
    w_.tilted_planes = detail::any_tilted_plane(w_);
    return {Status::ok, PlaneId(w_.plane_count - 1)};
  }

  /// Adds a body. Fails, adding nothing, on bad input (`non_finite`, `zero_quaternion`,
  /// `non_unit_quaternion`, `out_of_range`; `invalid_shape` for a shape id of another world or
  /// past the last shape; `invalid_mass` for a mass that is not positive, or 0 with a shape that
  /// has no mass) or with `capacity_exceeded` when the body pool is full.
  Added<BodyId> add_body(const BodyDef<D>& def)
  {
    const Status s = detail::check_state<D>(def.position, def.orientation, def.linear_velocity, def.angular_velocity);
    if (s != Status::ok) return {s, 0};
    if (!owns(def.shape)) return {Status::invalid_shape, 0};
    return detail::add_body(w_, def);
  }

  /// Sets a body's velocities (m/s, rad/s) and wakes it. `invalid_body`, `non_finite`,
  /// `out_of_range` (beyond `limits::speed`, `limits::spin`).
  Status set_velocity(BodyId id, const Vec& linear, const Spin& angular)
  {
    const std::uint32_t slot = detail::find_slot(w_, id);
    return slot == detail::no_slot ? Status::invalid_body : detail::set_velocities(w_, slot, linear, angular);
  }
  /// Moves a body (m; a unit orientation) and wakes it. `invalid_body`, or as `add_body`.
  Status set_transform(BodyId id, const Vec& position, const Rot& orientation)
  {
    return detail::set_transform(w_, id, position, orientation);
  }
  /// Adds `impulse` (N s, world frame) at `point` (m, world): the body's velocity changes by
  /// impulse / m and its angular velocity by I^-1 ((point - centre) x impulse), I its inertia
  /// (a table's `unit_inertia` times m, or 2/5 m r^2 for a sphere, 1/2 m r^2 for a 2D disc).
  /// Wakes the body. `invalid_body`, `non_finite`, `out_of_range` (a point beyond
  /// `limits::coordinate`, or velocities beyond `limits::speed` / `limits::spin` after it).
  Status apply_impulse(BodyId id, const Vec& impulse, const Vec& point)
  {
    return detail::apply_impulse(w_, id, impulse, point);
  }
  /// Adds an angular impulse (N m s, world frame; 2D: counter-clockwise): the angular velocity
  /// changes by I^-1 impulse. Wakes the body. Statuses as `apply_impulse`.
  Status apply_angular_impulse(BodyId id, const Spin& impulse)
  {
    return detail::apply_angular_impulse(w_, id, impulse);
  }
  /// Removes a body. Its slot is reused by a later `add_body`, under a new id: this one is
  /// refused with `invalid_body` from now on. Sleepers it reached (bounding spheres) wake.
  /// `invalid_body` for an id that names no body.
  Status remove_body(BodyId id) { return detail::remove_body(w_, id); }
  /// Wakes a body (an awake one starts its `sleep_time` again). `invalid_body`.
  Status wake(BodyId id) { return detail::wake_body(w_, id); }
  /// Puts a body to sleep where it is: its velocities become 0 and it is a static support until
  /// hit faster than `wake_speed`, woken or moved. `ok` also for a sleeping body; `invalid_body`.
  Status sleep(BodyId id) { return detail::sleep_body(w_, id); }

  /// Advances the world by `dt` seconds (typical 1/60). Rejected with `invalid_time_step` (not
  /// `out_of_range`), changing nothing, if dt is not finite and positive or above `limits::time_step`.
  /// Overflow of the pair buffer is reported in the result, never silent.
  StepResult step(Scalar dt) { return step_(*this, dt); }

  /// What the world's step is compiled with (`World`'s `Features`).
  Features features() const { return w_.features; }


  /// Slots in use, removed bodies' included: ids of live bodies have an index below it (`id_of`).
  std::uint32_t body_count() const { return w_.body_count; }
  /// Bodies in the world: body_count() less the removed ones.
  std::uint32_t live_body_count() const { return w_.body_count - w_.slots.removed; }
  std::uint32_t plane_count() const { return w_.plane_count; }
  std::uint32_t shape_count() const { return w_.shape_count; }
  std::uint32_t body_capacity() const { return w_.max_bodies; }
  std::uint32_t plane_capacity() const { return w_.max_planes; }
  std::uint32_t pair_capacity() const { return w_.max_pairs; }
  std::uint32_t shape_capacity() const { return w_.max_shapes; }
  std::uint64_t step_count() const { return w_.step_count; }
  /// Sampled responses scaled down by the energy guard, over the world's life.
  std::uint64_t energy_clamp_count() const { return w_.energy_clamps; }
  /// Sampled (statistical) responses applied, over the world's life: the energy guard's clamp
  /// rate is energy_clamp_count() / statistical_response_count().
  std::uint64_t statistical_response_count() const { return w_.statistical_responses; }

  /// A body's state. `id` must name a body of the world (`alive`): a caller's bug otherwise,
  /// reported by STATSIM_ASSERT where assertions are on; where they are off the call reads the
  /// first slot of the body storage instead of memory past it (meaningless, but memory-safe).
  /// For an id that may be bad, use `find_body`.
  const Body<D>& body(BodyId id) const
  {
    STATSIM_ASSERT(alive(id));
    return w_.bodies[alive(id) ? body_index(id) : 0];
  }
  /// A body's state, or nullptr if `id` names no body (never added, or removed).
  [[nodiscard]] const Body<D>* find_body(BodyId id) const
  {
    return alive(id) ? &w_.bodies[body_index(id)] : nullptr;
  }
  /// True when `id` names a body of the world: added and not removed.
  bool alive(BodyId id) const { return w_.slots.find(id, w_.body_count) != detail::no_slot; }
  /// A plane. `id` must be < plane_count(), as for `body()`.
  const Plane<D>& plane(PlaneId id) const
  {
    STATSIM_ASSERT(id < w_.plane_count);
    return w_.planes[id < w_.plane_count ? id : 0];
  }
  /// A shape. `id` must name a shape of this world (`owns`), as for `body()`.
  const Shape<D>& shape(ShapeId id) const
  {
    STATSIM_ASSERT(owns(id));
    return w_.shapes[owns(id) ? id.index : 0];
  }
  /// The shape of a body (`Body::shape`, an index), as for `body()`.
  const Shape<D>& shape_of(const Body<D>& b) const { return shape(ShapeId(b.shape)); }
  /// True when `id` names a shape of this world: below shape_count(), with this world's tag or
  /// none (a bare index).
  bool owns(ShapeId id) const { return id.index < w_.shape_count && (id.world == 0 || id.world == tag_); }
  /// Candidate pairs of the last step: the broad phase's pairs, up to the pair capacity, in the
  /// order the contact solver left them (the pairs that touched first; with shock propagation
  /// those sorted from the bottom up).
  const Pair* pairs() const { return w_.pairs; }
  std::uint32_t pair_count() const { return w_.pair_count; }

  /// The impacts of the last step above `WorldDef::impact_threshold` (see `Impact`), bodies
  /// against planes first, up to `MaxImpacts`; `StepResult::impacts_dropped` counts the rest.
  const Impact<D>* impacts() const { return impacts_.items; }
  std::uint32_t impact_count() const { return impacts_.count; }
  std::uint32_t impact_capacity() const { return impacts_.capacity; }

  /// The id of the body in slot `slot` (< body_count()), or `no_body` for a free slot.
  BodyId id_of(std::uint32_t slot) const { return w_.slots.id(slot, w_.body_count); }

  /// Number of bodies in each motion state.
  std::uint32_t count(MotionState s) const
  {
    std::uint32_t n = 0;
    for (std::uint32_t i = 0; i < w_.body_count; ++i) n += w_.bodies[i].state == s && w_.slots.live(i);
    return n;
  }

  /// FNV-1a hash of everything that determines the future: the parameters (`def()`), body
  /// states, planes, shapes (materials and signatures), the sweep-and-prune order and the
  /// counts. Equal hashes show bit-identical worlds that will step alike; worlds that differ in
  /// anything a step reads hash differently (but for hash collisions).
  std::uint64_t state_hash() const { return detail::state_hash(w_); }

 protected:
  /// Storage a `World<>` hands to its core.
  struct Storage {
    Body<D>* bodies;
    /// `detail::BroadPhaseLayout<D>::bytes(max_bodies)`, aligned for 16-byte records; or, without
    /// `grid_storage`, room for `max_bodies` sweep-and-prune entries only.
    unsigned char* broad_phase;
    Pair* pairs;
    Plane<D>* planes;
    Shape<D>* shapes;
    std::uint32_t* awake;
    std::uint32_t* flagged;
    std::uint32_t* rolled;
    std::uint32_t* hull_ground;
    std::uint32_t* paired;
    std::uint32_t max_bodies, max_pairs, max_planes, max_shapes;
    Impact<D>* impacts;
    std::uint32_t max_impacts;
    std::uint16_t* generations;
    std::uint32_t* free_slots;
    bool grid_storage;  ///< `broad_phase` holds the grid too
    detail::PairHull<D>* pair_hulls;  ///< `max_pair_hulls` of them (`STATSIM_HULL_CACHE`)
    std::uint32_t max_pair_hulls;
    Features features;  ///< what `step` is compiled with
    StepResult (*step)(WorldCore&, Scalar);  ///< `step_as<FS>` for those features
  };

  /// The step of a world compiled with the parts `FS` (`detail::FeatureSet`); `World` hands
  /// the core the one its features name, so no other is compiled.
  template <class FS>
  static StepResult step_as(WorldCore& core, Scalar dt)
  {
    return core.template step_with<FS>(dt);
  }

 private:
  template <class FS>
  StepResult step_with(Scalar dt)
  {
    StepResult result;
    if (!detail::finite(dt) || !(dt > 0) || dt > limits::time_step) {
      result.status = Status::invalid_time_step;
      return result;
    }
    detail::StepContext<FS> ctx;
    ctx.dt = dt;
    ctx.tilted_planes = w_.tilted_planes;
    const auto id = [this](std::uint32_t slot) { return id_of(slot); };
    impacts_.count = 0;
    impacts_.found = 0;
    // `rolled` every step that may roll: the passes read it (`respond_alone`), and it holds the
    // islands' marks of the last step.
    const bool hull_planes = detail::hull_planes<FS>(w_), ground_hulls = FS::slopes && w_.def.ground_hulls;
    if (hull_planes)
      for (std::uint32_t k = 0; k < detail::bit_words(w_.body_count); ++k) {
        w_.rolled[k] = 0;
        if (ground_hulls) w_.hull_ground[k] = 0;
      }
    result.bodies_integrated = detail::integrate<FS>(w_, dt, [&](std::uint32_t i) {
      if constexpr (FS::slopes) {
        // `on_ground` is still last step's: `forget_contacts` clears it below. A body that the
        // table's response sent off (`leaves_ground`) flies.
        const Body<D>& b = w_.bodies[i];
        if (ground_hulls && ((b.on_ground && !detail::leaves_ground(w_, b)) || detail::slow_landing(w_, b)))
          detail::set_bit(w_.hull_ground, i);
        return hull_planes && detail::roll_on_slopes<FS>(w_, i, dt, impacts_, id);
      } else {
        (void)i;
        return false;
      }
    });
    detail::update_radii<FS>(w_);
    // Before the broad phase, which replaces last step's pairs (it does not read the flags).
    detail::forget_contacts(w_);
    detail::find_pairs<FS>(w_, result);
    if constexpr (FS::statistical) detail::mark_paired(w_);
    detail::record_impacts<FS>(w_, impacts_, id);
    result.impacts_found = impacts_.found;
    if (impacts_.found > impacts_.count) {
      result.impacts_dropped = impacts_.found - impacts_.count;
      result.overflow |= overflow_impacts;
    }
    result.contacts += detail::impact_pass(w_, ctx);
    // A support pass that changed no velocity and moved nothing would be repeated exactly by
    // the next one: stop there (a resting pile needs one pass, not `support_iterations`; the
    // result is bit for bit the same).
    for (int i = 0; i < w_.def.support_iterations; ++i)
      if (detail::support_pass(w_, ctx) == 0) break;
    if (w_.def.shock_propagation) {
      // A position pass after a pass that moved nothing would find every contact as that one
      // did: skip it (in a resting pile, all of them).
      std::uint32_t moves = detail::shock_pass(w_, ctx);
      for (int i = 0; i < w_.def.position_iterations && moves > 0; ++i) moves = detail::position_pass(w_, ctx);
    }
    detail::update_motion_states<FS>(w_, dt, ctx.touching);
    if constexpr (FS::queries) detail::measure_drift(w_);
    w_.touching_pairs = ctx.touching;
    result.energy_clamps = ctx.energy_clamps;
    result.statistical_responses = ctx.statistical_responses;
    w_.energy_clamps += ctx.energy_clamps;
    w_.statistical_responses += ctx.statistical_responses;
    ++w_.step_count;
    return result;
  }

 protected:
  WorldCore(const Storage& s, const WorldDef<D>& def)
      : w_{s.bodies,
           reinterpret_cast<SweepEntry*>(s.broad_phase + detail::BroadPhaseLayout<D>::order(s.max_bodies)),
           reinterpret_cast<std::uint32_t*>(s.broad_phase + detail::BroadPhaseLayout<D>::order(s.max_bodies)),
           s.pairs,
           s.planes,
           s.shapes,
           s.grid_storage ? detail::SpatialHash<D>{reinterpret_cast<std::uint32_t*>(
                                                       s.broad_phase + detail::BroadPhaseLayout<D>::start(s.max_bodies)),
                                                   reinterpret_cast<detail::GridItem<D>*>(
                                                       s.broad_phase + detail::BroadPhaseLayout<D>::items(s.max_bodies)),
                                                   detail::grid_buckets(s.max_bodies)}
                          : detail::SpatialHash<D>{nullptr, nullptr, 1},
           s.awake,
           s.flagged,
           s.rolled,
           s.hull_ground,
           s.paired,
           s.max_bodies,
           s.max_pairs,
           s.max_planes,
           s.max_shapes},
        impacts_{s.impacts, s.max_impacts},
        step_(s.step)
  {
    w_.features = s.features;
    w_.slots.generation = s.generations;
    w_.slots.free = s.free_slots;
    w_.grid_storage = s.grid_storage;
    w_.pair_hulls = s.max_pair_hulls > 0 ? s.pair_hulls : nullptr;  // std::array<T, 0>::data() may be anything
    w_.max_pair_hulls = s.max_pair_hulls;
    construction_status_ = configure(def);
    if (construction_status_ == Status::ok && detail::float_contraction()) construction_status_ = Status::float_contraction;
  }
  ~WorldCore() = default;

 private:
  friend struct detail::SnapshotAccess;
  friend struct detail::CoreAccess;
  detail::WorldData<D> w_;
  detail::ImpactLog<D> impacts_;
  StepResult (*step_)(WorldCore&, Scalar);
  Status construction_status_ = Status::ok;
  std::uint16_t tag_ = detail::next_world_tag();
};

namespace detail {
/// A world's arrays, read by the runtime's own code outside the world (queries, snapshots) and by
/// tests and tools that check internals: not part of the public API, their layout may change.
struct CoreAccess {
  template <int D>
  static const WorldData<D>& data(const WorldCore<D>& world)
  {
    return world.w_;
  }
};
}  // namespace detail

/// A world of at most `MaxBodies` bodies, `MaxPlanes` planes, `MaxPairs` candidate pairs per step
/// (a settling pile of equal spheres needs about 6 per body; raise it if `step()` reports
/// `overflow_pairs`), `MaxShapes` shapes (at most 2,048) and `MaxImpacts` impact events per step
/// (0: none recorded, none reported). All storage is inside the object: a large world belongs in
/// static storage, not on the stack (10,000 bodies take about 2 MB with the default pair
/// buffer). `Phases`: the broad phases the world keeps storage for, `automatic` (both) or
/// `sweep_and_prune` (its entries only, for small worlds short of memory: `automatic` then
/// always sweeps, and `WorldDef::broad_phase = grid` is refused; the grid's code is not
/// compiled). `F`: the features its scene uses (statsim/features.hpp); the step of a world
/// without a feature is compiled without its code, and calls that need it are refused with
/// `Status::not_compiled`. Impact events are compiled only with `MaxImpacts` above 0.
template <int D, std::uint32_t MaxBodies, std::uint32_t MaxPlanes = 8, std::uint32_t MaxPairs = 6 * MaxBodies,
          std::uint32_t MaxShapes = 8, std::uint32_t MaxImpacts = 0, BroadPhase Phases = BroadPhase::automatic,
          Features F = Features::all>
class World : private detail::WorldStorage<D, MaxBodies, MaxPlanes, MaxPairs, MaxShapes, MaxImpacts, Phases>,
              public WorldCore<D> {
  using StorageBase = detail::WorldStorage<D, MaxBodies, MaxPlanes, MaxPairs, MaxShapes, MaxImpacts, Phases>;

 public:
  static constexpr std::uint32_t max_bodies = MaxBodies;
  static constexpr std::uint32_t max_planes = MaxPlanes;
  static constexpr std::uint32_t max_pairs = MaxPairs;
  static constexpr std::uint32_t max_shapes = MaxShapes;
  static_assert(MaxBodies > 0 && MaxPlanes > 0 && MaxPairs > 0 && MaxShapes > 0, "capacities must be positive");
  static_assert(MaxShapes <= 1u << shape_index_bits && MaxPlanes < 65535,
                "a body holds its shape's index in shape_index_bits bits; plane ids are 16-bit");
  static_assert(MaxBodies <= 1u << body_index_bits, "body ids hold the slot in body_index_bits bits");
  static_assert(Phases != BroadPhase::grid, "the grid's storage holds sweep-and-prune's too: use automatic");
  static_assert(includes(Features::all, F), "F: a combination of the bits of statsim::Features");
  using FeatureSet = detail::FeatureSet<F, Phases == BroadPhase::automatic, (MaxImpacts > 0)>;

  /// A world with the given parameters; if they are invalid it uses the defaults and
  /// `construction_status()` says why.
  explicit World(const WorldDef<D>& def = {})
      : StorageBase(),
        WorldCore<D>(typename WorldCore<D>::Storage{
                         StorageBase::body_store.data(), StorageBase::broad_phase_store.data(),
                         StorageBase::pair_store.data(), StorageBase::plane_store.data(),
                         StorageBase::shape_store.data(), StorageBase::awake_store.data(),
                         StorageBase::flagged_store.data(), StorageBase::rolled_store.data(),
                         StorageBase::hull_ground_store.data(), StorageBase::paired_store.data(), MaxBodies, MaxPairs,
                         MaxPlanes, MaxShapes, StorageBase::impact_store.data(), MaxImpacts,
                         StorageBase::generation_store.data(), StorageBase::free_store.data(), StorageBase::grid,
                         StorageBase::pair_hull_store.data(), std::uint32_t(StorageBase::pair_hull_store.size()), F,
                         &WorldCore<D>::template step_as<FeatureSet>},
                     def)
  {
  }
};

/// The 2D world: bodies with a position in the plane, an orientation `Rot2` and a scalar angular
/// velocity (counter-clockwise positive). Up is +y; planes are lines. The 3D world: bodies with a
/// position, a quaternion orientation and angular velocity vectors. Up is +z. See `World` for the
/// capacities.
template <std::uint32_t MaxBodies, std::uint32_t MaxPlanes = 8, std::uint32_t MaxPairs = 6 * MaxBodies,
          std::uint32_t MaxShapes = 8, std::uint32_t MaxImpacts = 0, BroadPhase Phases = BroadPhase::automatic,
          Features F = Features::all>
using World2 = World<2, MaxBodies, MaxPlanes, MaxPairs, MaxShapes, MaxImpacts, Phases, F>;
template <std::uint32_t MaxBodies, std::uint32_t MaxPlanes = 8, std::uint32_t MaxPairs = 6 * MaxBodies,
          std::uint32_t MaxShapes = 8, std::uint32_t MaxImpacts = 0, BroadPhase Phases = BroadPhase::automatic,
          Features F = Features::all>
using World3 = World<3, MaxBodies, MaxPlanes, MaxPairs, MaxShapes, MaxImpacts, Phases, F>;
using BodyDef2 = BodyDef<2>;
using BodyDef3 = BodyDef<3>;
using WorldDef2 = WorldDef<2>;
using WorldDef3 = WorldDef<3>;
using Body2 = Body<2>;
using Body3 = Body<3>;
using Plane2 = Plane<2>;
using Plane3 = Plane<3>;
using WorldCore2 = WorldCore<2>;
using WorldCore3 = WorldCore<3>;

}  // namespace statsim
