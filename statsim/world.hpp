#pragma once
/// @file
/// The world: fixed-capacity arrays of bodies and planes, and `step()`.
///
/// `World<D, MaxBodies, ...>` owns the storage; everything it does is implemented once in the
/// capacity-erased `WorldCore<D>`, so helpers can take a `WorldCore<3>&` whatever the capacity and
/// the code is compiled once per dimension, not once per capacity.
///
/// A step, in order:
///  1. integrate awake bodies (semi-implicit Euler; orientation without trigonometry);
///  2. broad phase (hashed grid or sweep-and-prune) on the bounding radius;
///  3. impact pass: body-plane then body-body contacts get the response (particle response for
///     now); planes push bodies out of them;
///  4. support passes (`WorldDef::support_iterations`): inelastic, removing approach velocity
///     left at resting contacts, planes last;
///  5. shock pass: contacts from the bottom up, the lower body immovable; overlaps between bodies
///     are corrected here, softly (`allowed_overlap`, `overlap_correction`), then again in
///     `position_iterations` passes that only move bodies;
///  6. motion state: moving, settling (slow and touching), asleep (slow for `sleep_time`).
/// Sleeping bodies are not integrated and act as static supports until hit harder than
/// `wake_speed`.

#include "statsim/broadphase.hpp"
#include "statsim/contact.hpp"
#include "statsim/random.hpp"
#include "statsim/response.hpp"
#include "statsim/statistical.hpp"
#include "statsim/status.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

namespace statsim {

/// Limits on finite inputs. Beyond them single-precision arithmetic can overflow (a speed of
/// 1e30 m/s squared is infinite) or lose all meaning, so calls with such values are rejected with
/// `Status::out_of_range` (or `invalid_parameter` for `WorldDef`) and change nothing.
namespace limits {
constexpr Scalar coordinate = Scalar(1e6);   ///< |position component|, |plane offset|, m
constexpr Scalar speed = Scalar(1e5);        ///< |linear velocity component|, m/s
constexpr Scalar spin = Scalar(1e7);         ///< |angular velocity component|, rad/s
constexpr Scalar time_step = 1;              ///< largest dt of `step`, s
constexpr Scalar min_mass = Scalar(1e-9);    ///< kg
constexpr Scalar max_mass = Scalar(1e9);     ///< kg
constexpr Scalar min_radius = Scalar(1e-6);  ///< collision and bounding radius, m
constexpr Scalar max_radius = Scalar(1e4);   ///< m
constexpr Scalar gravity = Scalar(1e4);      ///< |gravity component|, m/s^2
}  // namespace limits

namespace detail {
template <class V>
bool within(const V& v, Scalar bound)
{
  return (v.array().abs() <= bound).all();
}
inline bool within(Scalar x, Scalar bound) { return std::fabs(x) <= bound; }
}  // namespace detail

/// Index of a body in its world, in order of creation.
using BodyId = std::uint32_t;
/// Index of a shape in its world, in order of creation.
using ShapeId = std::uint16_t;
/// Index of a plane in its world, in order of creation.
using PlaneId = std::uint16_t;

/// What a body is doing.
enum class MotionState : std::uint8_t {
  moving,    ///< free flight or fast contact
  settling,  ///< touching something and slower than `WorldDef::settle_speed`
  asleep,    ///< not integrated; acts as a static support until hit hard enough
};

/// A shape: what all bodies made from it share. Built like Box2D's defs: start from the defaults
/// and set what differs.
struct ShapeDef {
  /// Radius of the collision sphere, m. Typical: 0.05 to 1.
  Scalar radius = Scalar(0.1);
  /// Radius of a sphere about the centre of mass that holds the whole shape, m; the broad phase
  /// uses it. 0 means "same as radius". Must be >= radius.
  Scalar bounding_radius = 0;
  /// Restitution and friction of the shape's surface.
  Material material{};
};

/// Initial state of a body.
template <int D>
struct BodyDef {
  using Vec = typename Space<D>::Vec;
  Vec position = Vec::Zero();                                 ///< centre of mass, m
  typename Space<D>::Rot orientation = Space<D>::identity();  ///< body to world; unit length
  Vec linear_velocity = Vec::Zero();                          ///< m/s
  typename Space<D>::Spin angular_velocity = Space<D>::zero_spin();  ///< rad/s, world frame
  ShapeId shape = 0;                                          ///< from `add_shape`
  Scalar mass = 1;                                            ///< kg, > 0
  bool asleep = false;                                        ///< start asleep (e.g. a pre-built pile)
};

/// How a body-body impact with a statistical body is resolved (see `WorldCore::respond_pair`).
enum class PairResponse : std::uint8_t {
  independent,  ///< paper 3.3.2: each body as against a fixed plane; energy can grow in piles
  momentum,     ///< the same samples, combined into one momentum-conserving impulse
};

/// Parameters of a world. Defaults suit bodies of 5 cm to 1 m at 30 to 240 Hz.
template <int D>
struct WorldDef {
  using Vec = typename Space<D>::Vec;
  /// Gravity, m/s^2, each component within +-`limits::gravity` (1e4). Default: 9.81 down the up
  /// axis (-z in 3D, -y in 2D).
  Vec gravity = -Scalar(9.81) * Vec::Unit(Space<D>::up_axis);
  /// Seed of every random stream; body i draws from stream `body_stream(seed, i)`.
  std::uint64_t seed = 0x5eed5eedull;
  /// Approach speed below which contacts do not bounce, m/s. Keep it above |g| dt (0.16 at
  /// 60 Hz) so that resting bodies do not jitter.
  Scalar restitution_threshold = Scalar(0.5);
  /// A touching body slower than this is settling, m/s (speed = max(|v|, |w| R_bound)).
  Scalar settle_speed = Scalar(0.5);
  /// A touching body slower than this for `sleep_time` falls asleep, m/s. Its linear speed
  /// counts as the lesser of |v| and the distance its centre moved in the step over dt: a body
  /// wedged between resting ones can keep a velocity that the overlap correction undoes every
  /// step, and it is still all the same.
  Scalar sleep_speed = Scalar(0.05);
  /// Seconds a touching body must stay below `sleep_speed` before it sleeps, >= 0.
  Scalar sleep_time = Scalar(0.5);
  /// An awake body hitting a sleeping one faster than this (normal approach, m/s) wakes it;
  /// slower, the sleeper acts as a static support.
  Scalar wake_speed = Scalar(0.5);
  /// Velocity damping, 1/s: v *= 1 / (1 + dt c). 0 = none.
  Scalar linear_damping = 0;
  /// Spin damping, 1/s. 0 = none.
  Scalar angular_damping = 0;
  /// Contact passes after the impact pass, >= 1 (paper: 1). Each takes out approach velocity
  /// left at resting contacts; a stack of k layers needs about k passes to hold still in one step.
  int support_iterations = 4;
  /// After the support passes, one bottom-up pass that settles stacks exactly (see `step`).
  bool shock_propagation = true;
  /// Passes after the shock pass that only push overlapping bodies apart, in its order and with
  /// its frozen bodies, in [0, 64]; they need `shock_propagation`. A body wedged between several
  /// others needs a few to come out of all of them. Typical: 0 to 4.
  int position_iterations = 2;
  /// Overlap of two bodies left uncorrected, as a fraction of the sum of their radii, in [0, 0.5).
  /// Typical: 0.005 to 0.05. Resting contacts keep about this much overlap.
  Scalar allowed_overlap = Scalar(0.01);
  /// Fraction of the remaining overlap of two bodies removed per step, in (0, 1]. Overlaps are
  /// corrected in the shock pass only, bottom-up with the lower body fixed, where removing them in
  /// full lifts nothing that was not sinking; lower values leave piles more compressed.
  Scalar overlap_correction = Scalar(1);
  /// In the spin ratio that sets the collision radius, speeds below this count as this, m/s, so
  /// a body resting or bouncing in place keeps a steady radius. Typical: the settle speed.
  Scalar spin_ratio_speed_floor = Scalar(0.5);
  /// Collision radius from the nearest height sample instead of interpolating (paper 3.3.1:
  /// both work).
  bool nearest_radius = false;
  /// Body-body impacts of statistical bodies: the paper's independent responses, or the same
  /// samples made to conserve momentum (the default: in piles the independent responses add
  /// energy, see README).
  PairResponse pair_response = PairResponse::momentum;
  /// Resting conditions of paper 3.4 for statistical bodies settling on a near-horizontal plane.
  bool rest_conditions = true;
  /// Bodies settling on other bodies (not on the ground) blend their radius to the shape's
  /// frequency-weighted mean rest height, without choosing a pose or turning. Off (the paper's
  /// method): they rest on their h_coll spheres, and piles stand too tall (100 squares: 10.7 m
  /// against Box2D's 7.2 m; on: 7.0 m, but about 15% more steps until all sleep; README,
  /// "2D signatures and the 2D demo").
  bool pile_rest = false;
  /// Seconds over which a settling body's radius blends from h_coll to h_rest (and back).
  Scalar rest_blend_time = Scalar(0.15);
  /// Settling bodies are turned toward their rest pose at each ground contact with an angular
  /// velocity of (sine of the remaining angle) / rest_turn_time, rad/s, capped so that the
  /// farthest point moves at most at `settle_speed`. Seconds, >= 1e-4.
  Scalar rest_turn_time = Scalar(0.1);
  /// A body turning into its rest pose may fall asleep (and snap into the pose) once the pose's
  /// normal is within this cosine of up (0.996: about 5 degrees).
  Scalar rest_snap_cosine = Scalar(0.996);
  /// A plane counts as ground for resting conditions when its normal's up component is at least
  /// this (0.9: within about 25 degrees of horizontal).
  Scalar ground_cosine = Scalar(0.9);
  /// The broad phase: sweep-and-prune for small worlds and the hashed grid for large ones
  /// (default, `automatic`), or either one always.
  BroadPhase broad_phase = BroadPhase::automatic;
  /// With `BroadPhase::automatic`, worlds of more bodies than this use the grid, fewer
  /// sweep-and-prune. The measured crossover of the two is near 2,000 bodies.
  std::uint32_t grid_above_bodies = 2048;
  /// Axis the sweep-and-prune broad phase sweeps along: 0 = x, 1 = y (2 = z in 3D). Pick one the scene spreads
  /// along, not the up axis of a pile.
  int sweep_axis = 0;
};

/// Full state of a body. Read it through `WorldCore::body()`; change it only through the world.
template <int D>
struct Body {
  using Vec = typename Space<D>::Vec;
  Vec position;                           ///< centre of mass, m
  typename Space<D>::Rot orientation;     ///< body to world, unit
  Vec linear_velocity;                    ///< m/s
  typename Space<D>::Spin angular_velocity;  ///< rad/s
  Scalar radius;                          ///< current collision radius, m
  Scalar bounding_radius;                 ///< m
  Scalar inv_mass;                        ///< 1/kg
  Scalar slow_time;                       ///< s spent slow and touching
  Vec step_start;                         ///< m, centre at the start of the last step (for the sleep test)
  std::uint64_t rng_state;                ///< state of the body's PCG32 stream
  Scalar rest_blend;                      ///< 0: radius is h_coll; 1: radius is h_rest of rest_pose
  ShapeId shape;
  MotionState state;
  bool touching;                          ///< touched a plane or body in the last step
  bool on_ground;                         ///< touched a near-horizontal plane in the last step
  std::uint8_t rest_pose;                 ///< chosen rest pose, or `no_rest_pose`
  bool pile_rest;                         ///< settling on other bodies, blending to the mean h_rest (`WorldDef::pile_rest`)
};

/// `Body::rest_pose` when no rest pose is chosen.
constexpr std::uint8_t no_rest_pose = 0xff;

/// Result of an `add_*` call: a status and, when ok, the new id.
template <class Id>
struct Added {
  Status status;
  Id id;
  constexpr bool ok() const { return status == Status::ok; }
};

/// Shape data a world keeps. A shape with a signature is statistical: its bodies take their
/// collision radius, response and rest poses from it; without one, bodies are plain spheres with
/// the particle response.
template <int D>
struct Shape {
  Scalar radius;            ///< m; for statistical shapes the radius at rest (largest h_rest)
  Scalar bounding_radius;   ///< m
  Material material;
  bool statistical;
  SignatureView<D> signature;  ///< meaningful when `statistical`
  /// Biases of the rest-pose basins (`rest_basin_biases`), one per rest pose.
  std::array<Scalar, max_rest_poses> rest_bias;
  /// Frequency-weighted mean of the rest heights, m: the radius a body blends to while it
  /// settles on other bodies (`WorldDef::pile_rest`).
  Scalar mean_rest_height;
};

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
    const Status s = validate(def);
    if (s == Status::ok) def_ = def;
    return s;
  }
  const WorldDef<D>& def() const { return def_; }
  /// Status of the parameters given at construction: if not ok, the world uses the defaults.
  Status construction_status() const { return construction_status_; }

  /// Registers a shape. Fails with `capacity_exceeded` when the shape pool is full.
  Added<ShapeId> add_shape(const ShapeDef& def)
  {
    const Scalar bound = def.bounding_radius == 0 ? def.radius : def.bounding_radius;
    if (!detail::finite(def.radius) || !detail::finite(bound) || !detail::finite(def.material.restitution) ||
        !detail::finite(def.material.friction))
      return {Status::non_finite, 0};
    if (!(def.radius > 0) || bound < def.radius) return {Status::invalid_radius, 0};
    if (def.radius < limits::min_radius || bound > limits::max_radius) return {Status::out_of_range, 0};
    if (!detail::finite(def.material.rolling_resistance)) return {Status::non_finite, 0};
    if (def.material.restitution < 0 || def.material.restitution > 1 || def.material.friction < 0 ||
        def.material.rolling_resistance < 0)
      return {Status::invalid_material, 0};
    if (shape_count_ == max_shapes_) return {Status::capacity_exceeded, 0};
    shapes_[shape_count_] = Shape<D>{def.radius, bound, def.material, false, SignatureView<D>{}, {}, def.radius};
    return {Status::ok, ShapeId(shape_count_++)};
  }

  /// Registers a statistical shape from its signature (`tables::NAME.view()`). The view is
  /// copied; the tables it points to must outlive the world (generated tables are static).
  /// Rejected with `invalid_shape` if the signature is malformed or has more than `max_rest_poses`
  /// rest poses. Computes the rest-pose basins (`rest_basin_biases`): up to 10 ms.
  Added<ShapeId> add_shape(const SignatureView<D>& sig)
  {
    const Status s = check_signature(sig);
    if (s != Status::ok) return {s, 0};
    if (shape_count_ == max_shapes_) return {Status::capacity_exceeded, 0};
    // The broad phase must hold every radius a body can take: the largest h_coll and h_rest.
    Scalar largest = sig.bounding_radius, rest_max = 0;
    for (std::uint32_t i = 0; i < sig.height.spin_ratio.size; ++i)
      largest = sig.height.mean[i] > largest ? sig.height.mean[i] : largest;
    for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
      largest = sig.rest.heights[i] > largest ? sig.rest.heights[i] : largest;
      rest_max = sig.rest.heights[i] > rest_max ? sig.rest.heights[i] : rest_max;
    }
    const Scalar radius = rest_max > 0 ? rest_max : sig.height.mean[0];
    // The radius of a body at rest on other bodies: the rest heights weighted by how often the
    // reference came to rest in each pose.
    Scalar weighted = 0, weight = 0;
    for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
      weighted += sig.rest.frequencies[i] * sig.rest.heights[i];
      weight += sig.rest.frequencies[i];
    }
    const Scalar mean_rest = weight > 0 ? weighted / weight : radius;
    shapes_[shape_count_] = Shape<D>{radius, largest, sig.material, true, sig, {}, mean_rest};
    rest_basin_biases<D>(sig, shapes_[shape_count_].rest_bias.data());
    return {Status::ok, ShapeId(shape_count_++)};
  }

  /// Adds a static plane with the given normal (any length > 0; it is normalised) through the
  /// point normal_unit * offset. Fails with `capacity_exceeded` when the plane pool is full.
  Added<PlaneId> add_plane(const Vec& normal, Scalar offset)
  {
    if (!detail::finite(normal) || !detail::finite(offset)) return {Status::invalid_plane, 0};
    if (!detail::within(offset, limits::coordinate)) return {Status::out_of_range, 0};
    const Scalar len = normal.norm();
    if (!(len > Scalar(1e-12)) || !detail::finite(len)) return {Status::invalid_plane, 0};
    if (plane_count_ == max_planes_) return {Status::capacity_exceeded, 0};
    planes_[plane_count_] = Plane<D>{normal / len, offset};
    return {Status::ok, PlaneId(plane_count_++)};
  }

  /// Adds a body. Fails, adding nothing, on bad input or when the body pool is full.
  Added<BodyId> add_body(const BodyDef<D>& def)
  {
    const Status s = check_state(def.position, def.orientation, def.linear_velocity, def.angular_velocity);
    if (s != Status::ok) return {s, 0};
    if (def.shape >= shape_count_) return {Status::invalid_shape, 0};
    if (!detail::finite(def.mass)) return {Status::non_finite, 0};
    if (!(def.mass > 0)) return {Status::invalid_mass, 0};
    if (def.mass < limits::min_mass || def.mass > limits::max_mass) return {Status::out_of_range, 0};
    if (body_count_ == max_bodies_) return {Status::capacity_exceeded, 0};

    const BodyId id = body_count_;
    const Shape<D>& shape = shapes_[def.shape];
    Body<D>& b = bodies_[id];
    b.position = def.position;
    b.orientation = detail::normalized(def.orientation);
    b.linear_velocity = def.asleep ? Vec::Zero() : def.linear_velocity;
    b.angular_velocity = def.asleep ? Space<D>::zero_spin() : def.angular_velocity;
    b.radius = shape.statistical
                   ? collision_radius<D>(shape.signature, b.linear_velocity, b.angular_velocity)
                   : shape.radius;
    b.bounding_radius = shape.bounding_radius;
    b.inv_mass = Scalar(1) / def.mass;
    b.slow_time = 0;
    b.step_start = b.position;
    b.rng_state = Pcg32(def_.seed, body_stream(def_.seed, id)).state();
    b.shape = def.shape;
    b.state = def.asleep ? MotionState::asleep : MotionState::moving;
    b.touching = false;
    b.on_ground = false;
    b.rest_pose = no_rest_pose;
    b.pile_rest = false;
    b.rest_blend = 0;
    entries_[id] = SweepEntry{0, 0, id, 1};
    ++body_count_;
    return {Status::ok, id};
  }

  /// Sets a body's velocities and wakes it.
  Status set_velocity(BodyId id, const Vec& linear, const Spin& angular)
  {
    if (id >= body_count_) return Status::invalid_body;
    if (!detail::finite(linear) || !detail::finite(angular)) return Status::non_finite;
    if (!detail::within(linear, limits::speed) || !detail::within(angular, limits::spin)) return Status::out_of_range;
    Body<D>& b = bodies_[id];
    b.linear_velocity = linear;
    b.angular_velocity = angular;
    wake(b);
    return Status::ok;
  }

  /// Moves a body and wakes it.
  Status set_transform(BodyId id, const Vec& position, const Rot& orientation)
  {
    if (id >= body_count_) return Status::invalid_body;
    const Status s = check_state(position, orientation, Vec::Zero(), Space<D>::zero_spin());
    if (s != Status::ok) return s;
    Body<D>& b = bodies_[id];
    b.position = position;
    b.orientation = detail::normalized(orientation);
    wake(b);
    return Status::ok;
  }

  /// Advances the world by `dt` seconds (typical 1/60). Rejected with `invalid_time_step` if dt
  /// is not finite and positive or exceeds `limits::time_step` (1 s); then nothing changes. Overflow of the pair buffer is reported in
  /// the result, never silent.
  StepResult step(Scalar dt)
  {
    StepResult result;
    if (!detail::finite(dt) || !(dt > 0) || dt > limits::time_step) {
      result.status = Status::invalid_time_step;
      return result;
    }
    integrate(dt);
    update_radii();
    find_pairs(result);
    for (std::uint32_t i = 0; i < body_count_; ++i) {
      bodies_[i].touching = false;
      bodies_[i].on_ground = false;
    }
    energy_clamps_step_ = 0;
    result.contacts += resolve_planes(Pass::impact);
    const std::uint32_t touching = resolve_pairs(pair_count_, Pass::impact);
    result.contacts += touching;
    // Planes come last in every support pass: a pair push can drive a body into the ground, and
    // the ground has the last word on position and velocity. A support pass that changed no
    // velocity and moved nothing would be repeated exactly by the next one: stop there (a
    // resting pile needs one pass, not `support_iterations`; the result is bit for bit the same).
    for (int i = 0; i < def_.support_iterations; ++i) {
      changes_ = 0;
      resolve_pairs(touching, Pass::support);
      resolve_planes(Pass::support);
      if (changes_ == 0) break;
    }
    if (def_.shock_propagation) {
      sort_bottom_up(touching);
      moves_ = 0;
      resolve_pairs(touching, Pass::shock);
      resolve_planes(Pass::support);
      // A pass after one that moved nothing would find every contact as that one did: skip it
      // (in a resting pile, all of them).
      for (int i = 0; i < def_.position_iterations && moves_ > 0; ++i) {
        moves_ = 0;
        resolve_pairs(touching, Pass::position);
        resolve_planes(Pass::position);
      }
    }
    update_motion_states(dt);
    result.energy_clamps = energy_clamps_step_;
    energy_clamps_ += energy_clamps_step_;
    ++step_count_;
    return result;
  }

  std::uint32_t body_count() const { return body_count_; }
  std::uint32_t plane_count() const { return plane_count_; }
  std::uint32_t shape_count() const { return shape_count_; }
  std::uint32_t body_capacity() const { return max_bodies_; }
  std::uint32_t plane_capacity() const { return max_planes_; }
  std::uint32_t pair_capacity() const { return max_pairs_; }
  std::uint32_t shape_capacity() const { return max_shapes_; }
  std::uint64_t step_count() const { return step_count_; }
  /// Sampled responses scaled down by the energy guard, over the world's life.
  std::uint64_t energy_clamp_count() const { return energy_clamps_; }

  /// A body's state. `id` must be < body_count() (checked by STATSIM_ASSERT).
  const Body<D>& body(BodyId id) const
  {
    STATSIM_ASSERT(id < body_count_);
    return bodies_[id];
  }
  const Plane<D>& plane(PlaneId id) const
  {
    STATSIM_ASSERT(id < plane_count_);
    return planes_[id];
  }
  const Shape<D>& shape(ShapeId id) const
  {
    STATSIM_ASSERT(id < shape_count_);
    return shapes_[id];
  }
  /// Candidate pairs of the last step (the broad phase's output, up to the pair capacity).
  const Pair* pairs() const { return pairs_; }
  std::uint32_t pair_count() const { return pair_count_; }

  /// Number of bodies in each motion state.
  std::uint32_t count(MotionState s) const
  {
    std::uint32_t n = 0;
    for (std::uint32_t i = 0; i < body_count_; ++i) n += bodies_[i].state == s;
    return n;
  }

  /// FNV-1a hash of everything that determines the future: body states, planes, shapes, counts.
  /// Equal hashes after equal calls show bit-identical worlds.
  std::uint64_t state_hash() const
  {
    detail::Fnv1a h;
    h.add(body_count_);
    h.add(plane_count_);
    h.add(shape_count_);
    h.add(step_count_);
    for (std::uint32_t i = 0; i < body_count_; ++i) {
      const Body<D>& b = bodies_[i];
      h.add_vec(b.position);
      h.add_rot(b.orientation);
      h.add_vec(b.linear_velocity);
      h.add_spin(b.angular_velocity);
      h.add(b.radius);
      h.add(b.bounding_radius);
      h.add(b.inv_mass);
      h.add(b.slow_time);
      h.add(b.rng_state);
      h.add(b.rest_blend);
      h.add(b.shape);
      h.add(std::uint8_t(b.state));
      h.add(std::uint8_t(b.touching));
      h.add(std::uint8_t(b.on_ground));
      h.add(b.rest_pose);
      h.add(std::uint8_t(b.pile_rest));
    }
    for (std::uint32_t i = 0; i < plane_count_; ++i) {
      h.add_vec(planes_[i].normal);
      h.add(planes_[i].offset);
    }
    for (std::uint32_t i = 0; i < shape_count_; ++i) {
      h.add(shapes_[i].radius);
      h.add(shapes_[i].bounding_radius);
      h.add(shapes_[i].material.restitution);
      h.add(shapes_[i].material.friction);
    }
    return h.value;
  }

 protected:
  /// Storage a `World<>` hands to its core.
  struct Storage {
    Body<D>* bodies;
    SweepEntry* entries;
    Pair* pairs;
    Plane<D>* planes;
    Shape<D>* shapes;
    std::uint32_t* grid_start;
    detail::GridItem<D>* grid_items;
    std::uint32_t max_bodies, max_pairs, max_planes, max_shapes;
  };

  WorldCore(const Storage& s, const WorldDef<D>& def)
      : bodies_(s.bodies),
        entries_(s.entries),
        pairs_(s.pairs),
        planes_(s.planes),
        shapes_(s.shapes),
        grid_{s.grid_start, s.grid_items, detail::grid_buckets(s.max_bodies)},
        max_bodies_(s.max_bodies),
        max_pairs_(s.max_pairs),
        max_planes_(s.max_planes),
        max_shapes_(s.max_shapes)
  {
    construction_status_ = configure(def);
  }
  ~WorldCore() = default;

 private:
  static Status validate(const WorldDef<D>& d)
  {
    if (!detail::finite(d.gravity) || !detail::finite(d.restitution_threshold) || !detail::finite(d.settle_speed) ||
        !detail::finite(d.sleep_speed) || !detail::finite(d.sleep_time) || !detail::finite(d.wake_speed) ||
        !detail::finite(d.linear_damping) || !detail::finite(d.angular_damping) ||
        !detail::finite(d.allowed_overlap) || !detail::finite(d.overlap_correction) ||
        !detail::finite(d.rest_blend_time) || !detail::finite(d.rest_turn_time) || !detail::finite(d.ground_cosine) ||
        !detail::finite(d.rest_snap_cosine) || !detail::finite(d.spin_ratio_speed_floor))
      return Status::non_finite;
    if (d.restitution_threshold < 0 || d.settle_speed < 0 || d.sleep_speed < 0 || d.sleep_time < 0 ||
        d.wake_speed < 0 || d.linear_damping < 0 || d.angular_damping < 0 || d.support_iterations < 1 ||
        d.support_iterations > 64 || d.position_iterations < 0 || d.position_iterations > 64 ||
        (d.broad_phase != BroadPhase::grid && d.broad_phase != BroadPhase::sweep_and_prune &&
         d.broad_phase != BroadPhase::automatic) || d.allowed_overlap < 0 || d.allowed_overlap >= Scalar(0.5) ||
        !(d.overlap_correction > 0) || d.overlap_correction > 1 || !(d.rest_blend_time > 0) ||
        !(d.rest_turn_time > 0) || d.ground_cosine < 0 || d.ground_cosine > 1 ||
        d.rest_snap_cosine < 0 || d.rest_snap_cosine > 1 || d.spin_ratio_speed_floor < 0 || d.sweep_axis < 0 ||
        d.sweep_axis >= D || !detail::within(d.gravity, limits::gravity) || d.rest_turn_time < Scalar(1e-4))
      return Status::invalid_parameter;
    return Status::ok;
  }

  static Status check_state(const Vec& x, const Rot& q, const Vec& v, const Spin& w)
  {
    if (!detail::finite(x) || !detail::finite(q) || !detail::finite(v) || !detail::finite(w))
      return Status::non_finite;
    const Scalar n2 = detail::squared_norm(q);
    if (!(n2 > Scalar(1e-12))) return Status::zero_quaternion;
    // |q|^2 - 1 ~ 2 (|q| - 1): a tolerance of 1e-3 on the length.
    if (!(n2 > Scalar(1 - 2e-3) && n2 < Scalar(1 + 2e-3))) return Status::non_unit_quaternion;
    if (!detail::within(x, limits::coordinate) || !detail::within(v, limits::speed) ||
        !detail::within(w, limits::spin))
      return Status::out_of_range;
    return Status::ok;
  }

  static Status check_signature(const SignatureView<D>& sig)
  {
    if (!detail::finite(sig.length) || !detail::finite(sig.bounding_radius)) return Status::non_finite;
    if (!(sig.length > 0) || !(sig.bounding_radius > 0)) return Status::invalid_radius;
    if (sig.material.restitution < 0 || sig.material.restitution > 1 || sig.material.friction < 0)
      return Status::invalid_material;
    const ResponseTableView& r = sig.response;
    const std::uint32_t expected_axes =
        (D == 3 ? 3u : 2u) + (sig.layout == ResponseLayout::with_speed ? 1u : 0u);
    if (!sig.height.spin_ratio.values || sig.height.spin_ratio.size < 1 || r.axis_count != expected_axes ||
        r.components != (D == 3 ? 6u : 3u) || (!r.mean.f32 && !r.mean.i16) || (!r.stddev.f32 && !r.stddev.i16) ||
        (sig.rest.count > 0 && (!sig.rest.normals || !sig.rest.heights)) || sig.rest.count > max_rest_poses)
      return Status::invalid_shape;
    for (std::uint32_t a = 0; a < r.axis_count; ++a)
      if (!r.axes[a].values || r.axes[a].size < 1) return Status::invalid_shape;
    if ((!sig.height.mean.f32 && !sig.height.mean.i16) || (!sig.height.stddev.f32 && !sig.height.stddev.i16))
      return Status::invalid_shape;
    return check_signature_values(sig);
  }

  /// The numbers of a signature: every one finite, axes strictly increasing, heights positive,
  /// rest normals unit. Table values are bounded (|x| <= 1e6: normalised responses are O(1)) so
  /// that scaling them by a speed cannot overflow. One pass over the tables, at add_shape only.
  static Status check_signature_values(const SignatureView<D>& sig)
  {
    constexpr Scalar bound = Scalar(1e6);
    const auto bad = [bound](Scalar x) { return !(x >= -bound && x <= bound); };  // NaN is bad
    const auto bad_axis = [&bad](const AxisView& a) {
      for (std::uint32_t i = 0; i < a.size; ++i)
        if (bad(a.values[i]) || (i > 0 && !(a.values[i] > a.values[i - 1]))) return true;
      return false;
    };
    const Material& m = sig.material;
    if (bad(m.restitution) || bad(m.friction) || bad(m.rolling_resistance) || bad(sig.restitution_threshold) ||
        bad(sig.mass) || bad(sig.unit_inertia[0]) || bad(sig.unit_inertia[1]) || bad(sig.unit_inertia[2]))
      return Status::non_finite;
    if (m.rolling_resistance < 0 || sig.restitution_threshold < 0) return Status::invalid_material;
    if (sig.unit_inertia[0] < 0 || sig.unit_inertia[1] < 0 || sig.unit_inertia[2] < 0) return Status::invalid_shape;
    const HeightTableView& h = sig.height;
    if (bad_axis(h.spin_ratio)) return Status::invalid_shape;
    for (std::uint32_t i = 0; i < h.spin_ratio.size; ++i)
      if (bad(h.mean[i]) || !(h.mean[i] > 0) || bad(h.stddev[i])) return Status::invalid_shape;
    const ResponseTableView& r = sig.response;
    std::uint32_t values = r.components;
    for (std::uint32_t a = 0; a < r.axis_count; ++a) {
      if (bad_axis(r.axes[a])) return Status::invalid_shape;
      values *= r.axes[a].size;
    }
    if (bad(r.mean.scale) || bad(r.mean.offset) || bad(r.stddev.scale) || bad(r.stddev.offset))
      return Status::invalid_shape;
    for (std::uint32_t i = 0; i < values; ++i)
      if (bad(r.mean[i]) || bad(r.stddev[i])) return Status::invalid_shape;
    for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
      const typename Space<D>::Vec n = sig.rest.normal(i);
      if (!detail::finite(n) || !(std::fabs(n.squaredNorm() - 1) < Scalar(2e-3))) return Status::invalid_shape;
      if (bad(sig.rest.heights[i]) || !(sig.rest.heights[i] > 0)) return Status::invalid_shape;
    }
    return Status::ok;
  }

  /// Lever arm of a body in the particle response: its radius for a sphere; 0 for a statistical
  /// body, whose sphere is not its shape, so friction on the sphere must not spin it (a spin it
  /// does not have would come back as speed).
  Scalar contact_radius(const Body<D>& b) const { return shapes_[b.shape].statistical ? Scalar(0) : b.radius; }

  Pcg32 rng_of(const Body<D>& b) const
  {
    return Pcg32::resume(b.rng_state, body_stream(def_.seed, std::uint32_t(&b - bodies_)));
  }

  /// Collision radius of statistical bodies (paper 3.3.1), blended toward the rest height of a
  /// chosen rest pose (paper 3.4).
  void update_radii()
  {
    for (std::uint32_t i = 0; i < body_count_; ++i) {
      Body<D>& b = bodies_[i];
      const Shape<D>& shape = shapes_[b.shape];
      if (!shape.statistical || b.state == MotionState::asleep) continue;
      const SignatureView<D>& sig = shape.signature;
      // Spin ratio with the speed floored: a body bouncing in place has |v| near 0 one step and
      // g dt the next, and |w| L / |v| would swing its radius between the table's ends.
      const Scalar speed = b.linear_velocity.norm();
      const Scalar floor = def_.spin_ratio_speed_floor;
      const Vec v_ref = speed < floor ? Vec(Vec::Unit(0) * floor) : Vec(b.linear_velocity);
      const Scalar r = collision_radius<D>(sig, v_ref, b.angular_velocity, def_.nearest_radius);
      if (b.rest_pose == no_rest_pose && !b.pile_rest) {
        b.radius = r;
        continue;
      }
      const Scalar h = b.rest_pose != no_rest_pose ? sig.rest.heights[b.rest_pose] : shape.mean_rest_height;
      const Scalar blended = r + (h - r) * b.rest_blend;
      // A settling body's sphere changes size about its lowest point, so a body blending to its
      // rest height settles smoothly instead of dropping (paper 3.4).
      if (b.on_ground || b.pile_rest) b.position[Space<D>::up_axis] += blended - b.radius;
      b.radius = blended;
    }
  }

  /// The response of one body alone against a plane with normal `n` (towards the body), with
  /// its velocity taken relative to `other_velocity`: the statistical response for statistical
  /// shapes (paper 3.3.2; for body-body contacts each body responds on its own, as in the
  /// paper), the rest turn for bodies settling on the ground (paper 3.4), else (plain spheres,
  /// and resting contacts of statistical bodies) the particle response against a static plane.
  void respond_alone(Body<D>& b, const Vec& n, const Vec& other_velocity, bool ground_contact)
  {
    const Shape<D>& shape = shapes_[b.shape];
    Vec v = b.linear_velocity - other_velocity;
    // A contact approaching slower than the restitution threshold is resting, not a collision:
    // the tables describe collisions, and sampling a fresh spin at every resting step would
    // keep a body from ever settling. It gets the inelastic particle response instead.
    const bool resting = -v.dot(n) <= def_.restitution_threshold;
    if (!shape.statistical || (resting && !(ground_contact && b.rest_pose != no_rest_pose))) {
      particle_plane_response<D>(v, b.angular_velocity, contact_radius(b), n, shape.material,
                                 def_.restitution_threshold);
    } else if (ground_contact && b.rest_pose != no_rest_pose) {
      if (!(v.dot(n) < 0)) return;
      v = point_particle_velocity<D>(v, n, shape.material, def_.restitution_threshold);
      b.angular_velocity = rest_turn(b.orientation, shape.signature.rest.normal(b.rest_pose), n, def_.rest_turn_time);
      // A small turn (paper 3.4): its farthest point moves at most at the settle speed, so a
      // slow body is not spun up (sin(angle) / rest_turn_time alone reaches 10 rad/s).
      const Scalar cap = def_.settle_speed / b.bounding_radius;
      const Scalar spin2 = detail::squared_norm(b.angular_velocity);
      if (spin2 > cap * cap) b.angular_velocity = b.angular_velocity * (cap / std::sqrt(spin2));
    } else {
      Pcg32 rng = rng_of(b);
      const ResponseOutcome o = statistical_response<D>(shape.signature, b.orientation, n, v, b.angular_velocity, rng);
      b.rng_state = rng.state();
      energy_clamps_step_ += o.energy_clamped;
    }
    b.linear_velocity = v + other_velocity;
  }

  /// Body-body impact with at least one statistical body. Each body first responds on its own
  /// to the separating plane with its velocity relative to the other's (paper 3.3.2), from the
  /// velocities before either response; a sleeper (inverse mass 0) keeps still.
  /// `PairResponse::independent` keeps those velocities, as the paper does. With
  /// `PairResponse::momentum` the two changes of relative velocity are averaged into one impulse
  /// that each body takes in proportion to its inverse mass, so momentum is conserved and the
  /// pair's kinetic energy in its centre-of-mass frame cannot grow; spins stay as sampled.
  void respond_pair(Body<D>& a, Body<D>& b, const Vec& n, Scalar ima, Scalar imb)
  {
    const Vec va = a.linear_velocity, vb = b.linear_velocity;
    if (ima > 0) respond_alone(a, -n, vb, false);
    if (imb > 0) respond_alone(b, n, va, false);
    if (def_.pair_response != PairResponse::momentum) return;
    // Change of (vb - va) as each body saw it; a static side saw none, so the other counts alone.
    const Vec from_b = (b.linear_velocity - va) - (vb - va);
    const Vec from_a = (vb - a.linear_velocity) - (vb - va);
    const Vec change = ima > 0 && imb > 0 ? Vec((from_a + from_b) * Scalar(0.5)) : (ima > 0 ? from_a : from_b);
    const Scalar ims = ima + imb;
    a.linear_velocity = va - change * (ima / ims);
    b.linear_velocity = vb + change * (imb / ims);
  }

  void wake(Body<D>& b)
  {
    b.state = MotionState::moving;
    b.slow_time = 0;
    b.step_start = b.position;  // a sleeper is not integrated: this is where it started the step
  }

  void integrate(Scalar dt)
  {
    const Vec dv = def_.gravity * dt;
    const Scalar lin_damp = Scalar(1) / (1 + dt * def_.linear_damping);
    const Scalar ang_damp = Scalar(1) / (1 + dt * def_.angular_damping);
    for (std::uint32_t i = 0; i < body_count_; ++i) {
      Body<D>& b = bodies_[i];
      if (b.state == MotionState::asleep) continue;
      b.step_start = b.position;
      b.linear_velocity = (b.linear_velocity + dv) * lin_damp;
      b.angular_velocity = b.angular_velocity * ang_damp;
      b.position += b.linear_velocity * dt;
      b.orientation = detail::integrate(b.orientation, b.angular_velocity, dt);
    }
  }

  void find_pairs(StepResult& result)
  {
    const bool grid = def_.broad_phase == BroadPhase::grid ||
                      (def_.broad_phase == BroadPhase::automatic && body_count_ > def_.grid_above_bodies);
    if (grid) find_pairs_grid(result);
    else find_pairs_sweep(result);
    const std::uint32_t found = result.pairs_found;
    if (found > max_pairs_) {
      result.pairs_dropped = found - max_pairs_;
      result.overflow |= overflow_pairs;
    }
    pair_count_ = found < max_pairs_ ? found : max_pairs_;
  }

  /// Records a candidate pair if the bounding spheres overlap; counts it either way it fits.
  void candidate(std::uint32_t a, std::uint32_t b, std::uint32_t& found)
  {
    const Body<D>& ba = bodies_[a];
    const Body<D>& bb = bodies_[b];
    const Scalar reach = ba.bounding_radius + bb.bounding_radius;
    if ((bb.position - ba.position).squaredNorm() > reach * reach) return;
    if (found < max_pairs_) pairs_[found] = a < b ? Pair{a, b} : Pair{b, a};
    ++found;
  }

  void find_pairs_grid(StepResult& result)
  {
    Scalar widest = 0;
    for (std::uint32_t i = 0; i < body_count_; ++i)
      widest = 2 * bodies_[i].bounding_radius > widest ? 2 * bodies_[i].bounding_radius : widest;
    grid_.inv_cell = Scalar(1) / widest;
    const auto cell = [this](std::uint32_t i, std::int32_t* c) {
      for (int k = 0; k < 3; ++k) c[k] = k < D ? grid_.cell_of(bodies_[i].position[k], grid_.inv_cell) : 0;
    };
    const auto item = [this](std::uint32_t i) {
      const Body<D>& b = bodies_[i];
      return detail::GridItem<D>{b.position, b.bounding_radius, i, b.state != MotionState::asleep ? 1u : 0u};
    };
    grid_.build(body_count_, cell, item);
    std::uint32_t found = 0;
    constexpr int neighbours = D == 3 ? 27 : 9;
    for (std::uint32_t i = 0; i < body_count_; ++i) {
      const Body<D>& bi = bodies_[i];
      if (bi.state == MotionState::asleep) continue;
      std::int32_t c[3];
      cell(i, c);
      std::uint32_t seen[neighbours];
      int seen_count = 0;
      // Buckets seen so far, by their low 6 bits: a clear bit proves a bucket new without
      // comparing it with every one before (neighbouring cells rarely share a bucket).
      std::uint64_t seen_bits = 0;
      for (int n = 0; n < neighbours; ++n) {
        const std::int32_t dx = n % 3 - 1, dy = (n / 3) % 3 - 1, dz = D == 3 ? n / 9 - 1 : 0;
        const std::uint32_t b = grid_.bucket(c[0] + dx, c[1] + dy, c[2] + dz);
        // Two neighbouring cells can share a bucket: visit each bucket once.
        const std::uint64_t bit = std::uint64_t(1) << (b & 63u);
        if (seen_bits & bit) {
          bool repeat = false;
          for (int k = 0; k < seen_count; ++k) repeat = repeat || seen[k] == b;
          if (repeat) continue;
        }
        seen_bits |= bit;
        seen[seen_count++] = b;
        const detail::GridItem<D>* it = grid_.items + grid_.start[b];
        const detail::GridItem<D>* const end = grid_.items + grid_.start[b + 1];
        for (; it != end; ++it) {
          const std::uint32_t j = it->body;
          // An awake pair is found once, from its lower index; a sleeper never looks itself.
          if (j == i || (j < i && it->awake)) continue;
          // As `candidate`, from the grid's copy of body j.
          const Scalar reach = bi.bounding_radius + it->reach;
          if ((it->position - bi.position).squaredNorm() > reach * reach) continue;
          if (found < max_pairs_) pairs_[found] = Pair{i < j ? i : j, i < j ? j : i};
          ++found;
        }
      }
    }
    result.pairs_found = found;
  }

  void find_pairs_sweep(StepResult& result)
  {
    const int axis = def_.sweep_axis;
    Scalar widest = 0;
    for (std::uint32_t i = 0; i < body_count_; ++i) {
      SweepEntry& e = entries_[i];
      const Body<D>& b = bodies_[e.body];
      e.lo = b.position[axis] - b.bounding_radius;
      e.hi = b.position[axis] + b.bounding_radius;
      e.active = b.state != MotionState::asleep ? 1u : 0u;
      widest = 2 * b.bounding_radius > widest ? 2 * b.bounding_radius : widest;
    }
    detail::insertion_sort(entries_, body_count_);
    std::uint32_t found = 0;
    detail::sweep_active(entries_, body_count_, widest,
                         [&](std::uint32_t a, std::uint32_t b) { candidate(a, b, found); });
    result.pairs_found = found;
  }

  /// The first contact pass resolves impacts with the bodies' response; support passes only take
  /// out what approach velocity is left (inelastic, with friction), so that a stack passes its
  /// weight down to the ground within one step instead of one layer per step.
  ///
  /// The shock pass (Guendelman, Bridson and Fedkiw 2003) then visits contacts from the bottom up
  /// and treats the lower body of each as immovable: whatever approach velocity and overlap are
  /// left go to the upper body alone, so a pile is consistent from the ground up after one pass,
  /// where Gauss-Seidel passes over k layers leave residuals that pump the pile.
  ///
  /// Position passes repeat only the shock pass's overlap correction. One pass leaves a body
  /// wedged between several others (or between a sleeper and the ground) where the last push put
  /// it, which may be back inside the first; a few repetitions let it find the gap, without
  /// touching velocities.
  enum class Pass : std::uint8_t { impact, support, shock, position };

  /// Plane contacts of every awake body: approaching bodies get the particle response, and a body
  /// inside a plane is moved out along its normal.
  std::uint32_t resolve_planes(Pass pass)
  {
    const Scalar threshold = pass == Pass::impact ? def_.restitution_threshold : no_bounce;
    std::uint32_t contacts = 0;
    for (std::uint32_t i = 0; i < body_count_; ++i) {
      Body<D>& b = bodies_[i];
      if (b.state == MotionState::asleep) continue;
      for (std::uint32_t p = 0; p < plane_count_; ++p) {
        Contact<D> c;
        // A support pass also sees a body that the last pass left exactly touching the plane.
        const Scalar slop = pass == Pass::impact ? 0 : b.radius * contact_slop;
        if (!sphere_plane_contact<D>(b.position, b.radius + slop, planes_[p], c)) continue;
        if (c.depth > slop) {
          b.position += c.normal * (c.depth - slop);
          ++moves_;
          ++changes_;
        }
        b.touching = true;
        const bool ground = c.normal[Space<D>::up_axis] >= def_.ground_cosine;
        b.on_ground = b.on_ground || ground;
        ++contacts;
        if (pass == Pass::position) continue;
        if (pass == Pass::impact && shapes_[b.shape].statistical)
          respond_alone(b, c.normal, Vec::Zero(), ground);
        else if (particle_plane_response<D>(b.linear_velocity, b.angular_velocity, contact_radius(b), c.normal,
                                            shapes_[b.shape].material, threshold))
          ++changes_;
      }
    }
    return contacts;
  }

  /// Body-body contacts among the first `count` candidate pairs. The impact pass moves the pairs
  /// that touch to the front of the buffer and returns how many; support passes run over those.
  std::uint32_t resolve_pairs(std::uint32_t count, Pass pass)
  {
    const Scalar threshold = pass == Pass::impact ? def_.restitution_threshold : no_bounce;
    const int up = Space<D>::up_axis;
    std::uint32_t touching = 0;
    for (std::uint32_t k = 0; k < count; ++k) {
      Body<D>& a = bodies_[pairs_[k].a];
      Body<D>& b = bodies_[pairs_[k].b];
      Contact<D> c;
      const Scalar slop = pass == Pass::impact ? 0 : (a.radius + b.radius) * contact_slop;
      if (!sphere_sphere_contact<D>(a.position, a.radius + slop, b.position, b.radius, c)) continue;
      if (pass == Pass::impact) {
        const Pair p = pairs_[touching];
        pairs_[touching] = pairs_[k];
        pairs_[k] = p;
      }
      ++touching;
      const Vec& n = c.normal;
      const bool a_asleep = a.state == MotionState::asleep;
      const bool b_asleep = b.state == MotionState::asleep;
      if (pass == Pass::impact && (a_asleep || b_asleep)) {
        // An awake body hitting a sleeper fast enough wakes it; otherwise the sleeper is static.
        const Scalar approach = (a.linear_velocity - b.linear_velocity).dot(n);
        if (approach > def_.wake_speed) {
          if (a_asleep) wake(a);
          if (b_asleep) wake(b);
        }
      }
      Scalar ima = a.state == MotionState::asleep ? 0 : a.inv_mass;
      Scalar imb = b.state == MotionState::asleep ? 0 : b.inv_mass;
      // Shock pass: a contact that mostly supports (normal within 60 degrees of up) freezes its
      // lower body; the normal points from a to b, so n_up > 0 means a is below.
      const bool bottom_up = pass == Pass::shock || pass == Pass::position;
      if (bottom_up && n[up] >= Scalar(0.5) && imb > 0) ima = 0;
      if (bottom_up && n[up] <= Scalar(-0.5) && ima > 0) imb = 0;
      const Scalar ims = ima + imb;
      if (ims <= 0) continue;
      if (pass == Pass::position) {
        // Velocities were settled by the passes before; this pass only moves.
      } else if (pass == Pass::impact && (shapes_[a.shape].statistical || shapes_[b.shape].statistical)) {
        respond_pair(a, b, n, ima, imb);
      } else {
        const Scalar ra = contact_radius(a), rb = contact_radius(b);
        // Bodies of one shape need no mixed material: sqrt(f * f) == f in IEEE arithmetic.
        const Material m = a.shape == b.shape ? shapes_[a.shape].material
                                              : mix(shapes_[a.shape].material, shapes_[b.shape].material);
        const ContactSide<D> sa{a.linear_velocity, a.angular_velocity, ima, ra};
        const ContactSide<D> sb{b.linear_velocity, b.angular_velocity, imb, rb};
        const bool changed = ra == 0 && rb == 0 ? particle_point_response<D>(sa, sb, n, m, threshold)
                                                : particle_response<D>(sa, sb, n, m, threshold);
        if (changed) ++changes_;
      }
      // Positions are corrected once per step: in the shock pass, or in the impact pass without
      // one. Pushing overlaps apart in every pass, split between both bodies, squeezes bodies
      // sideways and upward out of a packed pile each step, and the lift comes back as kinetic
      // energy, so the pile never sleeps. Split in proportion to inverse mass (in the shock pass
      // the lower body's is 0), so a sleeper does not move. The position passes after the shock
      // pass repeat only this correction, with the same order and the same frozen bodies.
      const bool correct = pass == (def_.shock_propagation ? Pass::shock : Pass::impact) || pass == Pass::position;
      const Scalar depth = (c.depth - slop - def_.allowed_overlap * (a.radius + b.radius)) * def_.overlap_correction;
      if (correct && depth > 0) {
        a.position -= n * (depth * ima / ims);
        b.position += n * (depth * imb / ims);
        ++moves_;
      }
      a.touching = true;
      b.touching = true;
    }
    return touching;
  }

  /// Orders the first `count` pairs by the height of their lower centre, ties by body index, so
  /// the order is a total one and the same on every platform.
  void sort_bottom_up(std::uint32_t count)
  {
    const int up = Space<D>::up_axis;
    const Body<D>* bodies = bodies_;
    std::sort(pairs_, pairs_ + count, [bodies, up](const Pair& x, const Pair& y) {
      const Scalar xa = bodies[x.a].position[up], xb = bodies[x.b].position[up];
      const Scalar ya = bodies[y.a].position[up], yb = bodies[y.b].position[up];
      const Scalar kx = xa < xb ? xa : xb, ky = ya < yb ? ya : yb;
      if (kx != ky) return kx < ky;
      if (x.a != y.a) return x.a < y.a;
      return x.b < y.b;
    });
  }

  /// Resting conditions (paper 3.4): a statistical body settling on the ground picks the rest
  /// pose nearest to its orientation and blends its radius toward that pose's height; a body
  /// that speeds up again blends back and forgets the pose; a body briefly off the ground keeps
  /// it.
  void update_rest_pose(Body<D>& b, bool settling_on_ground, bool settling_on_bodies, bool fast, Scalar dt)
  {
    const Shape<D>& shape = shapes_[b.shape];
    if (!shape.statistical || !def_.rest_conditions || shape.signature.rest.count == 0) return;
    const Scalar step = dt / def_.rest_blend_time;
    if (settling_on_ground) {
      if (b.rest_pose == no_rest_pose) {
        const std::uint32_t pose =
            nearest_rest_pose<D>(shape.signature, b.orientation, Vec::Unit(Space<D>::up_axis), shape.rest_bias.data());
        if (pose >= shape.signature.rest.count) return;  // only with a non-finite orientation
        b.rest_pose = std::uint8_t(pose);
      }
      b.pile_rest = false;
      b.rest_blend = b.rest_blend + step < 1 ? b.rest_blend + step : Scalar(1);
    } else if (def_.pile_rest && settling_on_bodies && (b.pile_rest || b.rest_pose == no_rest_pose)) {
      b.pile_rest = true;
      b.rest_blend = b.rest_blend + step < 1 ? b.rest_blend + step : Scalar(1);
    } else if (fast && (b.rest_pose != no_rest_pose || b.pile_rest)) {
      b.rest_blend = b.rest_blend - step > 0 ? b.rest_blend - step : Scalar(0);
      if (b.rest_blend == 0) {
        b.rest_pose = no_rest_pose;
        b.pile_rest = false;
      }
    }
  }

  /// True when the chosen rest pose's normal is within `rest_snap_cosine` of up.
  bool in_rest_pose(const Body<D>& b) const
  {
    const SignatureView<D>& sig = shapes_[b.shape].signature;
    const Vec u = b.orientation * sig.rest.normal(b.rest_pose);
    return u[Space<D>::up_axis] >= def_.rest_snap_cosine;
  }

  void update_motion_states(Scalar dt)
  {
    const Scalar settle2 = def_.settle_speed * def_.settle_speed;
    const Scalar sleep2 = def_.sleep_speed * def_.sleep_speed;
    for (std::uint32_t i = 0; i < body_count_; ++i) {
      Body<D>& b = bodies_[i];
      if (b.state == MotionState::asleep) continue;
      const Scalar r2 = b.bounding_radius * b.bounding_radius;
      const Scalar v2 = b.linear_velocity.squaredNorm();
      // A body turning into its rest pose spins because the resting conditions make it: its
      // spin does not count against settling, and it sleeps once the pose is (nearly) reached.
      const bool turning = b.rest_pose != no_rest_pose;
      const Scalar w2 = turning ? Scalar(0) : detail::squared_norm(b.angular_velocity) * r2;
      const Scalar speed2 = v2 > w2 ? v2 : w2;
      const bool settling = b.touching && speed2 < settle2;
      update_rest_pose(b, settling && b.on_ground, settling && !b.on_ground, speed2 >= settle2, dt);
      if (!settling) {
        b.state = MotionState::moving;
        b.slow_time = 0;
        continue;
      }
      b.state = MotionState::settling;
      // Stillness by displacement as well as velocity: with three or more contacts the passes
      // can leave a velocity that separates from some while sliding along another; the next
      // step moves the body into them and the shock pass moves it back, a cycle in which it
      // never moves and never sleeps (2 of 1,000 squares in compare2d, 27 of 1,000 spheres).
      const Scalar moved2 = (b.position - b.step_start).squaredNorm();
      const Scalar lin2 = moved2 < v2 * dt * dt ? moved2 / (dt * dt) : v2;
      // It turns at ground contacts only: one that keeps its pose while held up by other bodies
      // cannot reach it there, and may sleep where it is.
      const bool still = (lin2 > w2 ? lin2 : w2) < sleep2 && (!turning || !b.on_ground || in_rest_pose(b));
      b.slow_time = still ? b.slow_time + dt : 0;
      if (still && b.slow_time >= def_.sleep_time) {
        b.state = MotionState::asleep;
        b.linear_velocity = Vec::Zero();
        b.angular_velocity = Space<D>::zero_spin();
        if (b.rest_pose != no_rest_pose && b.on_ground) {
          // Fall asleep exactly in the pose, at its height: the last few degrees and the rest of
          // the radius blend are below what a slow body would show.
          const SignatureView<D>& sig = shapes_[b.shape].signature;
          const Vec up = Vec::Unit(Space<D>::up_axis);
          b.orientation = snap_to_rest(b.orientation, sig.rest.normal(b.rest_pose), up);
          const Scalar h = sig.rest.heights[b.rest_pose];
          b.position[Space<D>::up_axis] += h - b.radius;
          b.radius = h;
          b.rest_blend = 1;
        }
      }
    }
  }

  /// Approach speed used as restitution threshold in support passes: nothing bounces there.
  static constexpr Scalar no_bounce = std::numeric_limits<Scalar>::infinity();
  /// Support passes count spheres within this fraction of their radius as touching: the impact
  /// pass leaves resting contacts exactly touching, not overlapping.
  static constexpr Scalar contact_slop = Scalar(1e-3);

  Body<D>* bodies_;
  SweepEntry* entries_;
  Pair* pairs_;
  Plane<D>* planes_;
  Shape<D>* shapes_;
  detail::SpatialHash<D> grid_;
  std::uint32_t max_bodies_, max_pairs_, max_planes_, max_shapes_;
  std::uint32_t body_count_ = 0, pair_count_ = 0, plane_count_ = 0, shape_count_ = 0;
  std::uint64_t step_count_ = 0;
  std::uint64_t energy_clamps_ = 0;
  std::uint32_t energy_clamps_step_ = 0;
  std::uint32_t moves_ = 0;  ///< position corrections in the current pass (step-local)
  std::uint32_t changes_ = 0;  ///< impulses and position corrections in the current support pass
  WorldDef<D> def_{};
  Status construction_status_ = Status::ok;
};

namespace detail {
/// Storage of a World, a base class so that it is constructed before the core that points into it.
template <int D, std::uint32_t MaxBodies, std::uint32_t MaxPlanes, std::uint32_t MaxPairs, std::uint32_t MaxShapes>
struct WorldStorage {
  std::array<Body<D>, MaxBodies> body_store;
  std::array<SweepEntry, MaxBodies> entry_store;
  std::array<Pair, MaxPairs> pair_store;
  std::array<Plane<D>, MaxPlanes> plane_store;
  std::array<Shape<D>, MaxShapes> shape_store;
  std::array<std::uint32_t, detail::grid_buckets(MaxBodies) + 1> grid_start_store;
  std::array<detail::GridItem<D>, MaxBodies> grid_item_store;
};
}  // namespace detail

/// A world of at most `MaxBodies` bodies, `MaxPlanes` planes, `MaxPairs` candidate pairs per step
/// (a settling pile of equal spheres needs about 6 per body; raise it if `step()` reports
/// `overflow_pairs`)
/// and `MaxShapes` shapes. All storage is inside the object: a large world belongs in static
/// storage, not on the stack (10,000 bodies take about 2 MB with the default pair buffer).
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
        WorldCore<D>(typename WorldCore<D>::Storage{StorageBase::body_store.data(), StorageBase::entry_store.data(),
                                                     StorageBase::pair_store.data(), StorageBase::plane_store.data(),
                                                     StorageBase::shape_store.data(),
                                                     StorageBase::grid_start_store.data(),
                                                     StorageBase::grid_item_store.data(), MaxBodies, MaxPairs, MaxPlanes,
                                                     MaxShapes},
                     def)
  {
  }
};

}  // namespace statsim
