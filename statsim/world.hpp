#pragma once
/// @file
/// The world: fixed-capacity arrays of bodies and planes, and `step()`.
///
/// `World<D, MaxBodies, ...>` owns the storage; everything it does is implemented once in the
/// capacity-erased `WorldCore<D>`, so helpers can take a `WorldCore<3>&` whatever the capacity and
/// the code is compiled once per dimension, not once per capacity.
///
/// A step, in order (each phase is a function of `detail`, in the file named):
///  1. integrate awake bodies (semi-implicit Euler; orientation without trigonometry;
///     world_data.hpp) and set the statistical bodies' collision radii (rest_and_sleep.hpp);
///  2. broad phase (hashed grid or sweep-and-prune) on the bounding radius (find_pairs.hpp);
///  3. impact pass: body-plane then body-body contacts get the bodies' response (the statistical
///     response for statistical bodies, the particle response for plain spheres); planes push
///     bodies out of them (contact_solver.hpp, as are 4 and 5);
///  4. support passes (`WorldDef::support_iterations`): inelastic, removing approach velocity
///     left at resting contacts, planes last;
///  5. shock pass: contacts from the bottom up, the lower body immovable; overlaps between bodies
///     are corrected here, softly (`allowed_overlap`, `overlap_correction`), then again in
///     `position_iterations` passes that only move bodies;
///  6. motion state: moving, settling (slow and touching), asleep (slow for `sleep_time`)
///     (rest_and_sleep.hpp).
/// Sleeping bodies are not integrated and act as static supports until hit harder than
/// `wake_speed`.

#include "statsim/contact_solver.hpp"
#include "statsim/find_pairs.hpp"
#include "statsim/rest_and_sleep.hpp"
#include "statsim/signature_scale.hpp"
#include "statsim/world_checks.hpp"
#include "statsim/world_data.hpp"
#include "statsim/world_def.hpp"

#include <array>
#include <atomic>
#include <cstdint>

namespace statsim {

namespace detail {
/// A tag for a new world, 1 to 65535 (0 is the bare-index tag of `ShapeId`). Worlds made one after
/// another get different tags until 65535 have been made; the tag never enters a simulation.
inline std::uint16_t next_world_tag()
{
  static std::atomic<std::uint32_t> made{0};
  return std::uint16_t(made.fetch_add(1, std::memory_order_relaxed) % 65535u + 1u);
}
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
  /// is out of range; the world then keeps the parameters it had.
  Status configure(const WorldDef<D>& def)
  {
    const Status s = detail::check_world_def(def);
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
    const Status s = detail::check_signature(sig);
    if (s != Status::ok) return {s, ShapeId{}};
    if (w_.shape_count == w_.max_shapes) return {Status::capacity_exceeded, ShapeId{}};
    // The broad phase must hold every radius a body can take: the largest h_coll and h_rest.
    Scalar largest = sig.bounding_radius, rest_max = 0;
    for (std::uint32_t i = 0; i < sig.height.spin_ratio.size; ++i)
      largest = sig.height.mean[i] > largest ? sig.height.mean[i] : largest;
    for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
      largest = sig.rest.heights[i] > largest ? sig.rest.heights[i] : largest;
      rest_max = sig.rest.heights[i] > rest_max ? sig.rest.heights[i] : rest_max;
    }
    // The radius of a body at rest on other bodies: the rest heights weighted by how often the
    // reference came to rest in each pose; without frequencies, the largest rest height (h_coll
    // at spin 0 without rest poses).
    Scalar weighted = 0, weight = 0;
    for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
      weighted += sig.rest.frequencies[i] * sig.rest.heights[i];
      weight += sig.rest.frequencies[i];
    }
    const Scalar mean_rest = weight > 0 ? weighted / weight : (rest_max > 0 ? rest_max : sig.height.mean[0]);
    // With body-body data a body also touches others as far out as its support map reaches,
    // times the largest packing ratio.
    Scalar floor = 0, packing = 1;
    Shape<D>& shape = w_.shapes[w_.shape_count];
    shape = Shape<D>{0,         largest, sig.material, true, sig, {}, mean_rest, detail::signature_hash(sig),
                     floor,     packing, sig.mass};
    if (sig.contact.present()) {
      const detail::SupportBounds sb = detail::support_bounds(sig.contact);
      packing = detail::largest_packing(shape);
      const Scalar reach = sb.ceiling * (packing > 1 ? packing : Scalar(1));
      shape.bounding_radius = reach > largest ? reach : largest;
      shape.support_floor = sb.floor;
      shape.largest_packing = packing;
    }
    rest_basin_biases<D>(sig, shape.rest_bias.data());
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
  /// point normal_unit * offset. Fails with `capacity_exceeded` when the plane pool is full.
  Added<PlaneId> add_plane(const Vec& normal, Scalar offset)
  {
    if (!detail::finite(normal) || !detail::finite(offset)) return {Status::invalid_plane, 0};
    if (!detail::within(offset, limits::coordinate)) return {Status::out_of_range, 0};
    const Scalar len = normal.norm();
    if (!(len > Scalar(1e-12)) || !detail::finite(len)) return {Status::invalid_plane, 0};
    if (w_.plane_count == w_.max_planes) return {Status::capacity_exceeded, 0};
    w_.planes[w_.plane_count] = Plane<D>{normal / len, offset};
    return {Status::ok, PlaneId(w_.plane_count++)};
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
    const Shape<D>& shape = w_.shapes[def.shape.index];
    const Scalar mass = def.mass == 0 ? shape.mass : def.mass;
    if (!detail::finite(mass)) return {Status::non_finite, 0};
    if (!(mass > 0)) return {Status::invalid_mass, 0};
    if (mass < limits::min_mass || mass > limits::max_mass) return {Status::out_of_range, 0};
    if (w_.body_count == w_.max_bodies) return {Status::capacity_exceeded, 0};

    const BodyId id = w_.body_count;
    Body<D>& b = w_.bodies[id];
    b.position = def.position;
    b.orientation = detail::normalized(def.orientation);
    b.linear_velocity = def.asleep ? Vec::Zero() : def.linear_velocity;
    b.angular_velocity = def.asleep ? Space<D>::zero_spin() : def.angular_velocity;
    b.radius = shape.statistical
                   ? collision_radius<D>(shape.signature, b.linear_velocity, b.angular_velocity)
                   : shape.radius;
    b.bounding_radius = shape.bounding_radius;
    w_.widest = 2 * b.bounding_radius > w_.widest ? 2 * b.bounding_radius : w_.widest;
    b.inv_mass = Scalar(1) / mass;
    b.slow_time = 0;
    b.step_start = b.position;
    b.rng_state = Pcg32(w_.def.seed, body_stream(w_.def.seed, id)).state();
    b.shape = def.shape.index;
    b.state = def.asleep ? MotionState::asleep : MotionState::moving;
    b.touching = false;
    b.on_ground = false;
    b.rest_pose = no_rest_pose;
    b.pile_rest = false;
    b.rest_blend = 0;
    if (!def.asleep) {
      detail::set_bit(w_.awake, id);
      ++w_.awake_count;
    }
    ++w_.body_count;
    return {Status::ok, id};
  }

  /// Sets a body's velocities and wakes it.
  Status set_velocity(BodyId id, const Vec& linear, const Spin& angular)
  {
    if (id >= w_.body_count) return Status::invalid_body;
    if (!detail::finite(linear) || !detail::finite(angular)) return Status::non_finite;
    if (!detail::within(linear, limits::speed) || !detail::within(angular, limits::spin)) return Status::out_of_range;
    Body<D>& b = w_.bodies[id];
    b.linear_velocity = linear;
    b.angular_velocity = angular;
    detail::wake(w_, b);
    return Status::ok;
  }

  /// Moves a body and wakes it.
  Status set_transform(BodyId id, const Vec& position, const Rot& orientation)
  {
    if (id >= w_.body_count) return Status::invalid_body;
    const Status s = detail::check_state<D>(position, orientation, Vec::Zero(), Space<D>::zero_spin());
    if (s != Status::ok) return s;
    Body<D>& b = w_.bodies[id];
    b.position = position;
    b.orientation = detail::normalized(orientation);
    detail::wake(w_, b);
    return Status::ok;
  }

  /// Advances the world by `dt` seconds (typical 1/60). Rejected with `invalid_time_step` (not
  /// `out_of_range`) if dt is not finite and positive or exceeds `limits::time_step` (1 s); then
  /// nothing changes.
  /// Overflow of the pair buffer is reported in the result, never silent.
  StepResult step(Scalar dt)
  {
    StepResult result;
    if (!detail::finite(dt) || !(dt > 0) || dt > limits::time_step) {
      result.status = Status::invalid_time_step;
      return result;
    }
    detail::StepContext ctx;
    ctx.dt = dt;
    ctx.tilted_planes = detail::any_tilted_plane(w_);
    result.bodies_integrated = detail::integrate(w_, dt);
    detail::update_radii(w_);
    // Before the broad phase, which replaces last step's pairs (it does not read the flags).
    detail::forget_contacts(w_);
    detail::find_pairs(w_, result);
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
    detail::update_motion_states(w_, dt);
    w_.touching_pairs = ctx.touching;
    result.energy_clamps = ctx.energy_clamps;
    result.statistical_responses = ctx.statistical_responses;
    w_.energy_clamps += ctx.energy_clamps;
    w_.statistical_responses += ctx.statistical_responses;
    ++w_.step_count;
    return result;
  }

  std::uint32_t body_count() const { return w_.body_count; }
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

  /// A body's state. `id` must be < body_count(): a caller's bug otherwise, reported by
  /// STATSIM_ASSERT where assertions are on; where they are off the call reads the first slot
  /// of the body storage instead of memory past it (meaningless, but memory-safe). For an id
  /// that may be bad, use `find_body`.
  const Body<D>& body(BodyId id) const
  {
    STATSIM_ASSERT(id < w_.body_count);
    return w_.bodies[id < w_.body_count ? id : 0];
  }
  /// A body's state, or nullptr if `id` is not < body_count().
  [[nodiscard]] const Body<D>* find_body(BodyId id) const { return id < w_.body_count ? &w_.bodies[id] : nullptr; }
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

  /// Number of bodies in each motion state.
  std::uint32_t count(MotionState s) const
  {
    std::uint32_t n = 0;
    for (std::uint32_t i = 0; i < w_.body_count; ++i) n += w_.bodies[i].state == s;
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
    unsigned char* broad_phase;  ///< `detail::BroadPhaseLayout<D>::bytes(max_bodies)`, aligned for 16-byte records
    Pair* pairs;
    Plane<D>* planes;
    Shape<D>* shapes;
    std::uint32_t* awake;
    std::uint32_t* flagged;
    std::uint32_t max_bodies, max_pairs, max_planes, max_shapes;
  };

  WorldCore(const Storage& s, const WorldDef<D>& def)
      : w_{s.bodies,
           reinterpret_cast<SweepEntry*>(s.broad_phase + detail::BroadPhaseLayout<D>::order(s.max_bodies)),
           reinterpret_cast<std::uint32_t*>(s.broad_phase + detail::BroadPhaseLayout<D>::order(s.max_bodies)),
           s.pairs,
           s.planes,
           s.shapes,
           detail::SpatialHash<D>{
               reinterpret_cast<std::uint32_t*>(s.broad_phase + detail::BroadPhaseLayout<D>::start(s.max_bodies)),
               reinterpret_cast<detail::GridItem<D>*>(s.broad_phase + detail::BroadPhaseLayout<D>::items(s.max_bodies)),
               detail::grid_buckets(s.max_bodies)},
           s.awake,
           s.flagged,
           s.max_bodies,
           s.max_pairs,
           s.max_planes,
           s.max_shapes}
  {
    construction_status_ = configure(def);
    if (construction_status_ == Status::ok && detail::float_contraction()) construction_status_ = Status::float_contraction;
  }
  ~WorldCore() = default;

 private:
  detail::WorldData<D> w_;
  Status construction_status_ = Status::ok;
  std::uint16_t tag_ = detail::next_world_tag();
};

namespace detail {
/// Storage of a World, a base class so that it is constructed before the core that points into it.
template <int D, std::uint32_t MaxBodies, std::uint32_t MaxPlanes, std::uint32_t MaxPairs, std::uint32_t MaxShapes>
struct WorldStorage {
  std::array<Body<D>, MaxBodies> body_store;
  alignas(16) std::array<unsigned char, detail::BroadPhaseLayout<D>::bytes(MaxBodies)> broad_phase_store;
  std::array<Pair, MaxPairs> pair_store;
  std::array<Plane<D>, MaxPlanes> plane_store;
  std::array<Shape<D>, MaxShapes> shape_store;
  std::array<std::uint32_t, detail::bit_words(MaxBodies)> awake_store;
  std::array<std::uint32_t, detail::bit_words(MaxBodies)> flagged_store;
};
}  // namespace detail

/// A world of at most `MaxBodies` bodies, `MaxPlanes` planes, `MaxPairs` candidate pairs per step
/// (a settling pile of equal spheres needs about 6 per body; raise it if `step()` reports
/// `overflow_pairs`) and `MaxShapes` shapes. All storage is inside the object: a large world
/// belongs in static storage, not on the stack (10,000 bodies take about 2 MB with the default
/// pair buffer).
template <int D, std::uint32_t MaxBodies, std::uint32_t MaxPlanes = 8, std::uint32_t MaxPairs = 6 * MaxBodies,
          std::uint32_t MaxShapes = 8>
class World : private detail::WorldStorage<D, MaxBodies, MaxPlanes, MaxPairs, MaxShapes>, public WorldCore<D> {
  using StorageBase = detail::WorldStorage<D, MaxBodies, MaxPlanes, MaxPairs, MaxShapes>;

 public:
  static constexpr std::uint32_t max_bodies = MaxBodies;
  static constexpr std::uint32_t max_planes = MaxPlanes;
  static constexpr std::uint32_t max_pairs = MaxPairs;
  static constexpr std::uint32_t max_shapes = MaxShapes;
  static_assert(MaxBodies > 0 && MaxPlanes > 0 && MaxPairs > 0 && MaxShapes > 0, "capacities must be positive");
  static_assert(MaxShapes <= 65535 && MaxPlanes <= 65535, "shape and plane ids are 16-bit");

  /// A world with the given parameters; if they are invalid it uses the defaults and
  /// `construction_status()` says why.
  explicit World(const WorldDef<D>& def = {})
      : StorageBase(),
        WorldCore<D>(typename WorldCore<D>::Storage{StorageBase::body_store.data(),
                                                     StorageBase::broad_phase_store.data(),
                                                     StorageBase::pair_store.data(), StorageBase::plane_store.data(),
                                                     StorageBase::shape_store.data(),
                                                     StorageBase::awake_store.data(),
                                                     StorageBase::flagged_store.data(), MaxBodies, MaxPairs, MaxPlanes,
                                                     MaxShapes},
                     def)
  {
  }
};

/// The 2D world: bodies with a position in the plane, an orientation `Rot2` and a scalar angular
/// velocity (counter-clockwise positive). Up is +y; planes are lines. The 3D world: bodies with a
/// position, a quaternion orientation and angular velocity vectors. Up is +z. See `World` for the
/// capacities.
template <std::uint32_t MaxBodies, std::uint32_t MaxPlanes = 8, std::uint32_t MaxPairs = 6 * MaxBodies,
          std::uint32_t MaxShapes = 8>
using World2 = World<2, MaxBodies, MaxPlanes, MaxPairs, MaxShapes>;
template <std::uint32_t MaxBodies, std::uint32_t MaxPlanes = 8, std::uint32_t MaxPairs = 6 * MaxBodies,
          std::uint32_t MaxShapes = 8>
using World3 = World<3, MaxBodies, MaxPlanes, MaxPairs, MaxShapes>;
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
