#pragma once
/// @file
/// What a world is made of: the limits on inputs, the ids, the definitions users fill in
/// (`ShapeDef`, `BodyDef`, `WorldDef` and its options), the state the world keeps (`Body`,
/// `Shape`, `Plane`) and what a step leaves to read (`Pair`, `Impact`).

#include "statsim/statistical.hpp"
#include "statsim/status.hpp"

#include <array>
#include <cmath>
#include <cstdint>

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
constexpr std::uint32_t max_workers = 64;    ///< `Workers::count`
}  // namespace limits

namespace detail {
template <class V>
bool within(const V& v, Scalar bound)
{
  return (v.array().abs() <= bound).all();
}
inline bool within(Scalar x, Scalar bound) { return std::fabs(x) <= bound; }
}  // namespace detail

/// Names a body of one world: its slot (the low `body_index_bits` bits) and the slot's
/// generation (the high 12 bits), which `remove_body` advances. A world refuses an id of a body
/// removed since with `Status::invalid_body`, also once its slot holds another body. In a world
/// that removes nothing, ids are the indices 0, 1, 2, ... in order of creation.
using BodyId = std::uint32_t;
constexpr std::uint32_t body_index_bits = 20;
/// The id of no body (`Impact::b` of a plane impact, `QueryHit::body` of a plane); never issued.
constexpr BodyId no_body = 0xffffffffu;
constexpr std::uint32_t body_index(BodyId id) { return id & ((1u << body_index_bits) - 1u); }
constexpr std::uint32_t body_generation(BodyId id) { return id >> body_index_bits; }
constexpr BodyId make_body_id(std::uint32_t index, std::uint32_t generation)
{
  return generation << body_index_bits | index;
}
namespace detail {
/// A slot index that names no slot.
constexpr std::uint32_t no_slot = 0xffffffffu;
}  // namespace detail
/// Names a shape of one world: its index in order of creation and the tag of the world that
/// made it. `add_shape` returns tagged ids, and a world rejects a tagged id of another world with
/// `Status::invalid_shape`, so an id cannot silently mean another world's shape. `ShapeId{}` and
/// `ShapeId(index)` are bare indices (tag 0), valid in any world that has that many shapes.
struct ShapeId {
  std::uint16_t index = 0;  ///< position in the world's shapes, in order of creation
  std::uint16_t world = 0;  ///< tag of the world that issued it (`WorldCore::tag()`); 0: any world
  constexpr ShapeId() = default;
  constexpr explicit ShapeId(std::uint16_t i, std::uint16_t tag = 0) : index(i), world(tag) {}
  constexpr bool operator==(const ShapeId& o) const { return index == o.index && world == o.world; }
  constexpr bool operator!=(const ShapeId& o) const { return !(*this == o); }
};
/// Bits of a shape's index in a body (`Body::shape`): a world holds at most 2,048 shapes.
constexpr std::uint32_t shape_index_bits = 11;
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
  /// Radius of a sphere about the centre of mass that holds the whole shape, m; sweep-and-prune
  /// uses it, and the grid with hull contacts. 0 means "same as radius". Must be >= radius.
  Scalar bounding_radius = 0;
  /// Restitution and friction of the shape's surface.
  Material material{};
  /// Mass a body of this shape gets when its `BodyDef::mass` is 0, kg, in
  /// [`limits::min_mass`, `limits::max_mass`].
  Scalar mass = 1;
};

/// Initial state of a body.
template <int D>
struct BodyDef {
  using Vec = typename Space<D>::Vec;
  Vec position = Vec::Zero();                                 ///< centre of mass, m
  typename Space<D>::Rot orientation = Space<D>::identity();  ///< body to world; unit length
  Vec linear_velocity = Vec::Zero();                          ///< m/s
  typename Space<D>::Spin angular_velocity = Space<D>::zero_spin();  ///< rad/s, world frame
  ShapeId shape{};                                            ///< from `add_shape`
  /// kg. 0 (the default): the shape's mass, the table's `Signature::mass` for a statistical
  /// shape (the reference body's, set by the mesh and the gathering's density) or
  /// `ShapeDef::mass` for a sphere. Otherwise > 0, in [`limits::min_mass`, `limits::max_mass`].
  Scalar mass = 0;
  bool asleep = false;                                        ///< start asleep (e.g. a pre-built pile)
};

/// How a body-body impact with a statistical body is resolved (see `detail::respond_pair`).
enum class PairResponse : std::uint8_t {
  independent,  ///< paper 3.3.2: each body as against a fixed plane; energy can grow in piles
  momentum,     ///< the same samples, combined into one momentum-conserving impulse
};

/// A piece of a step that a world hands to the user's workers: `task(begin, end, task_context)`
/// does the items [begin, end) of the task. Ranges of one task may run at the same time on
/// different threads; each item must run exactly once.
using TaskCallback = void(std::uint32_t begin, std::uint32_t end, void* task_context);
/// Runs `task` over the items [0, count), in ranges of at least `min_range` items, on the user's
/// workers (in the manner of Box2D v3's `b2EnqueueTaskCallback`). Returns a handle that the world
/// passes to `FinishTaskCallback`, or nullptr when every item has run before it returns.
/// `user_context` is `Workers::context`.
using EnqueueTaskCallback = void*(TaskCallback* task, std::uint32_t count, std::uint32_t min_range,
                                  void* task_context, void* user_context);
/// Returns once every item of the task behind `user_task` (from `EnqueueTaskCallback`) has run.
using FinishTaskCallback = void(void* user_task, void* user_context);

/// Optional worker threads of a host program, reached through callbacks the user provides: the
/// world starts no thread, allocates nothing and holds no lock. The hashed grid's pair search
/// (`BroadPhase::grid`) is split into `count` parts by body index, and each part writes its pairs
/// to its own share of the pair buffer; the parts are then joined in index order, so a world
/// steps to the same bits with any `count` (a part that would overflow its share makes the step
/// search again on one thread). Not part of the world's state: not hashed, not saved in
/// snapshots, and a world that loads a snapshot keeps its own.
struct Workers {
  /// Parts the work is split into, in [1, `limits::max_workers`]; 1 (default): all of it on the
  /// calling thread, and the callbacks are not used. Typical: the number of threads of the pool.
  std::uint32_t count = 1;
  EnqueueTaskCallback* enqueue = nullptr;  ///< required when `count` > 1
  FinishTaskCallback* finish = nullptr;    ///< required when `count` > 1
  void* context = nullptr;                 ///< passed to both callbacks as `user_context`
};

/// Which broad phase a world uses.
enum class BroadPhase : std::uint8_t {
  /// Uniform grid of cells as wide as the widest reach of two bodies (`detail::pair_radius`: the
  /// bounding radius with hull contacts, else about the collision sphere), hashed into a fixed
  /// table: each awake body looks at the 3^D cells around it. Cost grows with awake bodies times
  /// their neighbours.
  grid,
  /// Sweep-and-prune along one axis (paper 4.1). Cost grows with the bodies whose intervals
  /// overlap on that axis, which in a wide pile is many more than the true neighbours.
  sweep_and_prune,
  /// Sweep-and-prune up to `WorldDef::grid_above_bodies` bodies, the grid above: sweep-and-prune
  /// is the faster in small worlds, the grid in large ones (`statsim bench`, tools/bench/README.md).
  automatic,
};

/// A candidate pair of bodies, by index, a < b: 8 bytes, as a pair buffer holds several per body.
/// (`b` and `witness` are bit-fields: copy them into an integer before binding a reference.)
struct Pair {
  std::uint32_t a;
  std::uint32_t b : 24;  ///< body indices have `body_index_bits` (20) bits
  /// With hull contacts, the candidate normal the impact pass found for a touching pair
  /// (`detail::find_hull_witness`), which the later passes of the step reuse; 0 in a new pair.
  std::uint32_t witness : 8;
};

/// A static plane (a line in 2D): the points x with normal . x = offset, solid on the side
/// normal . x < offset.
template <int D>
struct Plane {
  typename Space<D>::Vec normal;  ///< unit, pointing out of the solid side
  Scalar offset;                  ///< m
};

/// One impact of the last step, as the impact pass met it: before any response of the step.
template <int D>
struct Impact {
  using Vec = typename Space<D>::Vec;
  BodyId a;       ///< the (first) body
  BodyId b;       ///< the other body, or `no_body` for an impact with plane `plane`
  PlaneId plane;  ///< meaningful when b == no_body
  /// Contact point, m: the foot of a's centre on the plane; between two bodies, on the line of
  /// their centres, dividing it in the ratio of their collision radii.
  Vec point;
  /// Unit normal: from a towards b; with a plane, the plane's normal (out of it, towards a).
  Vec normal;
  /// Speed at which the bodies approach along the normal, m/s (> `WorldDef::impact_threshold`).
  Scalar approach_speed;
};

/// Where two bodies touch (see statsim/detail/hull.hpp).
enum class BodyContacts : std::uint8_t {
  /// Paper 3.3.1: at the sum of their collision radii, whatever their orientations.
  collision_spheres,
  /// At the distance their hulls allow at their current orientations (the signature's support
  /// map and largest faces) times the shape's packing ratio from reference piles, along the
  /// candidate contact normal that allows the least; for pairs whose tables both have
  /// body-body data (a plain sphere counts as having it), else as `collision_spheres`.
  /// Settling bodies also keep their hull out of planes. Refused by a world compiled without
  /// `Features::hull_contacts`.
  hulls,
  /// `hulls` in a world compiled with `Features::hull_contacts`, else `collision_spheres`: the
  /// model a scene's feature set declares (the default).
  automatic,
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
  /// 60 Hz) so that resting bodies do not jitter. Statistical bodies use it only while settling
  /// (see `table_restitution_threshold`).
  Scalar restitution_threshold = Scalar(0.5);
  /// Statistical bodies that were not settling at the end of the last step take the statistical
  /// response at contacts approaching faster than their table's restitution threshold
  /// (`Signature::restitution_threshold`, m/s; 0.02 in the committed 3D tables, Box2D's 1 in the
  /// 2D ones), the threshold the reference bounced with when the table was gathered, instead of
  /// `restitution_threshold`.
  /// Settling bodies (touching and slower than `settle_speed`) keep `restitution_threshold`: a
  /// body resting on the ground or on other bodies approaches at |g| dt every step, and a sampled
  /// response there would keep it from ever settling. The table's threshold is never taken below
  /// 2 |g.n| dt (0.33 m/s on level ground at 60 Hz) either: a body sliding or rolling on a plane
  /// meets it at |g.n| dt every step, which is not an impact. Off: every contact uses
  /// `restitution_threshold`.
  bool table_restitution_threshold = true;
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
  /// Bodies fall asleep by islands (bodies connected through touching pairs), as rigid-body
  /// engines put them to sleep: a body still for `sleep_time` waits until every awake body it
  /// touches, directly or through others, is too, and they fall asleep in the same step; at the
  /// end of a step an awake body that was not still in it joins a sleeper it touches to its
  /// island, at any approach speed (the default). Off: each body falls asleep on its own, and a sleeper is a static support unless
  /// hit faster than `wake_speed`; a pile then freezes layer by layer as it forms, where a pile
  /// of rigid bodies slumps under the bodies still landing on it (tools/fidelity/README.md, "A
  /// pile model").
  bool sleep_islands = true;
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
  /// energy, see statsim/README.md, "Statistical bodies").
  PairResponse pair_response = PairResponse::momentum;
  /// Where bodies touch each other: at their hulls for tables with body-body data wherever the
  /// world compiles hull contacts (`automatic`, the default), always at their collision spheres
  /// (the paper's rule), or at their hulls (refused without `Features::hull_contacts`). Hulls
  /// hold stacks at their true height and keep bodies out of the ground; collision spheres take
  /// a third of their time per step in piles and stand piles too tall (statsim/README.md,
  /// "Statistical bodies"; tools/fidelity/README.md, "One default").
  BodyContacts body_contacts = BodyContacts::automatic;
  /// Resting conditions of paper 3.4 for statistical bodies settling on a near-horizontal plane.
  bool rest_conditions = true;
  /// Statistical bodies whose table has a support map meet level ground with their hull
  /// (`detail::ground_hull`, statsim/README.md, "Hull contacts on level ground"): the impact from
  /// flight is the table's response, taken where the hull touches; the tumbles and hops after it
  /// are the hull's, in 1 ms substeps, until the body chooses a rest pose; a landing as slow as a
  /// hop's (from a fall of the centre of L / 2 or less) is the hull's too
  /// (`detail::slow_landing`), and a body the response sends off flies (`detail::leaves_ground`).
  /// Single drops nearer the reference on some shapes, at more time per step in piles
  /// (tools/fidelity/README.md, "Hull contacts on level ground"). Needs `rest_conditions`;
  /// refused with `not_compiled` in a world without `Features::slopes`, whose contact it takes.
  bool ground_hulls = false;
  /// Bodies settling on other bodies (not on the ground) blend their radius to the shape's
  /// frequency-weighted mean rest height, without choosing a pose or turning. Off (the paper's
  /// method): they rest on their h_coll spheres, which are larger than the shape's rest heights,
  /// so piles stand taller than the reference's; on, piles stand nearer the reference's height
  /// but take longer to fall asleep (figures: tools/ref2d/README.md, the 2D comparison).
  bool pile_rest = false;
  /// Seconds over which a settling body's radius blends from h_coll to h_rest (and back).
  Scalar rest_blend_time = Scalar(0.15);
  /// Settling bodies are turned toward their rest pose at each ground contact with an angular
  /// velocity of (sine of the remaining angle) / rest_turn_time, rad/s, capped so that the
  /// farthest point moves at most at `settle_speed`. Seconds, >= 1e-4.
  Scalar rest_turn_time = Scalar(0.1);
  /// A body turning into its rest pose may fall asleep (and snap into the pose) once the pose's
  /// normal is within this cosine of the ground plane's normal (0.996: about 5 degrees).
  Scalar rest_snap_cosine = Scalar(0.996);
  /// A plane counts as ground for resting conditions when its normal's up component is at least
  /// this (0.9: within about 25 degrees of horizontal).
  Scalar ground_cosine = Scalar(0.9);
  /// The broad phase: sweep-and-prune for small worlds and the hashed grid for large ones
  /// (default, `automatic`), or either one always.
  BroadPhase broad_phase = BroadPhase::automatic;
  /// With `BroadPhase::automatic`, worlds of more bodies than this use the grid, fewer
  /// sweep-and-prune: near where the two cost the same (measured by `statsim bench`,
  /// tools/bench/README.md).
  std::uint32_t grid_above_bodies = 2048;
  /// Axis the sweep-and-prune broad phase sweeps along: 0 = x, 1 = y (2 = z in 3D). Pick one the scene spreads
  /// along, not the up axis of a pile.
  int sweep_axis = 0;
  /// Contacts approaching faster than this are reported as impact events, m/s, >= 0 (see
  /// `WorldCore::impacts`; only in worlds with a `MaxImpacts` above 0). Typical: 1 (Box2D's
  /// hit-event default); a body resting on the ground approaches at |g| dt each step.
  Scalar impact_threshold = 1;
  /// Worker threads for the step (see `Workers`); none by default.
  Workers workers;
};

/// A 64-bit word kept as two 32-bit halves, so that it needs only 4-byte alignment: a body's
/// random state then packs after its 4-byte fields without padding (a 2D body would otherwise
/// grow by 4 bytes to the next multiple of 8). Reads and writes as a `std::uint64_t`.
struct Word64 {
  std::uint32_t lo;
  std::uint32_t hi;
  constexpr operator std::uint64_t() const { return std::uint64_t(hi) << 32 | lo; }
  constexpr Word64& operator=(std::uint64_t x)
  {
    lo = std::uint32_t(x);
    hi = std::uint32_t(x >> 32);
    return *this;
  }
};

/// Full state of a body. Read it through `WorldCore::body()`; change it only through the world.
/// The orientation comes first: a quaternion is 16-byte aligned, and after it the fields pack
/// without padding. The bounding radius is the
/// shape's (`Shape::bounding_radius`, `WorldCore::shape_of`): it is the same for every body of a
/// shape, so a body does not keep a copy.
template <int D>
struct Body {
  using Vec = typename Space<D>::Vec;
  typename Space<D>::Rot orientation;     ///< body to world, unit
  Vec position;                           ///< centre of mass, m
  Vec linear_velocity;                    ///< m/s
  typename Space<D>::Spin angular_velocity;  ///< rad/s
  /// m, centre at the start of the last step, or with `BodyContacts::hulls` where the body's slow
  /// time began (for the sleep test)
  Vec step_start;
  Scalar radius;                          ///< current collision radius, m
  Scalar inv_mass;                        ///< 1/kg
  /// s spent slow and touching; below 0, minus the settling time a body in its rest pose has
  /// still to rock before it may be still (tables with settling data, `SettleView`)
  Scalar slow_time;
  Scalar rest_blend;                      ///< 0: radius is h_coll; 1: radius is h_rest of rest_pose
  Word64 rng_state;                       ///< state of the body's PCG32 stream
  // Bit-fields: they read and assign as plain fields, but cannot be bound to a reference. In 2D
  // the shape's index and the four flags share two bytes, which makes the body 64 bytes; a 3D
  // body is 96 bytes either way (its orientation's alignment), and whole bytes are read and
  // written without masks.
  std::uint16_t shape : D == 2 ? shape_index_bits : 16;  ///< index of the body's shape (`ShapeId::index`)
  MotionState state : D == 2 ? 2 : 8;
  bool touching : D == 2 ? 1 : 8;         ///< touched a plane or body in the last step
  bool on_ground : D == 2 ? 1 : 8;        ///< touched a near-horizontal plane in the last step
  bool pile_rest : D == 2 ? 1 : 8;        ///< settling on other bodies, blending to the mean h_rest (`WorldDef::pile_rest`)
  std::uint8_t rest_pose;                 ///< chosen rest pose, or `no_rest_pose`
  /// With hull contacts, the horizontal directions (eight sectors, one bit each) from which
  /// bodies and planes held the body in the step's shock pass, all bits when one held it under
  /// its centre of mass (`detail::mark_supports`); scratch of the step, not part of the state,
  /// valid only for bodies of its touching pairs.
  std::uint8_t supports;
};

/// `Body::rest_pose` when no rest pose is chosen.
constexpr std::uint8_t no_rest_pose = 0xff;

/// Result of an `add_*` call: a status and, when ok, the new id.
template <class Id>
struct [[nodiscard]] Added {
  Status status;
  Id id;
  constexpr bool ok() const { return status == Status::ok; }
};

/// Shape data a world keeps. A shape with a signature is statistical: its bodies take their
/// collision radius, response and rest poses from it; without one, bodies are plain spheres with
/// the particle response.
template <int D>
struct Shape {
  /// Collision radius of a plain sphere, m; 0 for a statistical shape, whose bodies take theirs
  /// from the signature.
  Scalar radius;
  Scalar bounding_radius;   ///< m
  Material material;
  bool statistical;
  SignatureView<D> signature;  ///< meaningful when `statistical`
  /// Biases of the rest-pose basins (`rest_basin_biases`), one per rest pose.
  std::array<Scalar, max_rest_poses> rest_bias;
  /// Frequency-weighted mean of the rest heights, m: the radius a body blends to while it
  /// settles on other bodies (`WorldDef::pile_rest`).
  Scalar mean_rest_height;
  /// FNV-1a hash of the signature's numbers (`detail::signature_hash`), for `state_hash`; 0 for
  /// a plain sphere.
  std::uint64_t signature_hash;
  /// The least support the table's support map can give (`detail::support_bounds`), m; 0
  /// without body-body data.
  Scalar support_floor;
  /// The largest packing ratio of the table's body-body data (`detail::largest_packing`); 1
  /// without it.
  Scalar largest_packing;
  /// Mass of a body whose `BodyDef::mass` is 0, kg: the signature's, or `ShapeDef::mass`.
  Scalar mass;
};

}  // namespace statsim
