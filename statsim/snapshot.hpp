#pragma once
/// @file
/// World snapshots: `save` writes a world's whole state into a caller's buffer and `load` puts
/// it back, so that the world then steps on bit for bit as the saved one would have, also on
/// another platform (a Cortex-M build's snapshot loads on a host). No heap, no exceptions.
///
/// The format (version `detail::snapshot_version`), every value little-endian whatever the
/// machine, scalars as their IEEE bits (`Scalar`'s width), never as memory images of structs:
///  - header, 32 bytes: magic "STSN", u16 version, u8 dimension, u8 bytes per scalar, u32 size
///    of the whole snapshot, u32 flags (1: the world keeps the grid's storage, 2: the broad
///    phase's block holds the grid, 4: the sweep order is current), u32 body slots, planes,
///    shapes and sweep entries;
///  - u64 step count, energy clamps and statistical responses; the widest bounding diameter;
///  - the `WorldDef`, field by field;
///  - a u64 fingerprint per shape (`detail::shape_fingerprint`): tables are not saved, so the
///    world loaded into must have the same shapes added in the same order;
///  - each plane: its unit normal and offset;
///  - each body slot: u8 flags (1 touching, 2 on ground, 4 pile rest, 8 removed, 16 step start
///    follows), u16 generation, u16 shape, u8 motion state, u8 rest pose, u64 random state, then
///    orientation, position, velocities, collision radius, 1/mass, slow time, rest blend and,
///    only where the sleep test still reads it, the step start;
///  - the sweep order: a u32 body slot per entry;
///  - the u64 FNV-1a (`detail::fnv1a64`) of every byte before it.
/// Not saved, because the next step rewrites them before it reads them: the pair buffer (a
/// loaded world's `pairs()` and `impacts()` are empty until it steps), the grid, `Body::supports`,
/// and the contact flags' bookkeeping (a body whose flags are set and that is not awake is
/// marked for the next step to clear, as the last step's touching pairs would have).

#include "statsim/detail/feature_checks.hpp"
#include "statsim/detail/slope.hpp"
#include "statsim/detail/snapshot_format.hpp"
#include "statsim/world.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>  // placement new into the broad phase's block, as find_pairs.hpp does

namespace statsim {
namespace detail {

/// What `load` needs of a world beyond its public interface.
struct SnapshotAccess {
  template <int D>
  static WorldData<D>& data(WorldCore<D>& w)
  {
    return w.w_;
  }
  template <int D>
  static ImpactLog<D>& impacts(WorldCore<D>& w)
  {
    return w.impacts_;
  }
};

constexpr std::size_t snapshot_header_bytes = 32;
/// Bits of the header's flags.
constexpr std::uint32_t snap_grid_storage = 1, snap_grid_layout = 2, snap_sweep_current = 4;
/// Bits of a body slot's flags.
constexpr std::uint32_t snap_touching = 1, snap_on_ground = 2, snap_pile_rest = 4, snap_removed = 8,
                        snap_step_start = 16;

/// The body in `slot` has no body: removed, waiting for reuse or retired.
inline bool removed_slot(const BodySlots& s, std::uint32_t slot) { return !s.live(slot); }

/// True when the next step reads the body's step start as it is: an awake body measured from
/// where its slow time began (`integrate` keeps it there). Any other body's is set to its
/// position before it is read (`integrate`, `wake`), and `load` sets it so.
template <int D>
bool keeps_step_start(const WorldData<D>& w, const Body<D>& b)
{
  return b.state != MotionState::asleep && b.slow_time > 0 && hull_contacts_on(w) &&
         sleeps_from_anchor(w, b);
}

template <int D>
void write_def(SnapshotWriter& out, const WorldDef<D>& d)
{
  out.vec(d.gravity);
  out.u64(d.seed);
  for (Scalar x : {d.restitution_threshold, d.settle_speed, d.sleep_speed, d.sleep_time, d.wake_speed,
                   d.linear_damping, d.angular_damping, d.allowed_overlap, d.overlap_correction,
                   d.spin_ratio_speed_floor, d.rest_blend_time, d.rest_turn_time, d.rest_snap_cosine, d.ground_cosine,
                   d.impact_threshold})
    out.scalar(x);
  out.u32(std::uint32_t(d.support_iterations));
  out.u32(std::uint32_t(d.position_iterations));
  out.u32(std::uint32_t(d.sweep_axis));
  out.u32(d.grid_above_bodies);
  for (std::uint32_t b : {std::uint32_t(d.table_restitution_threshold), std::uint32_t(d.shock_propagation),
                          std::uint32_t(d.nearest_radius), std::uint32_t(d.pair_response),
                          std::uint32_t(d.body_contacts), std::uint32_t(d.rest_conditions) | (d.ground_hulls ? 2u : 0u),
                          std::uint32_t(d.pile_rest), std::uint32_t(d.broad_phase), std::uint32_t(d.sleep_islands)})
    out.u8(b);
}

/// Reads a `WorldDef` as `write_def` wrote it; false when a bool or an enum holds a value it
/// cannot have (they are read as bytes and checked before they are converted).
template <int D>
bool read_def(SnapshotReader& in, WorldDef<D>& d)
{
  in.vec(d.gravity);
  d.seed = in.u64();
  for (Scalar* x : {&d.restitution_threshold, &d.settle_speed, &d.sleep_speed, &d.sleep_time, &d.wake_speed,
                    &d.linear_damping, &d.angular_damping, &d.allowed_overlap, &d.overlap_correction,
                    &d.spin_ratio_speed_floor, &d.rest_blend_time, &d.rest_turn_time, &d.rest_snap_cosine,
                    &d.ground_cosine, &d.impact_threshold})
    *x = in.scalar();
  d.support_iterations = int(std::int32_t(in.u32()));
  d.position_iterations = int(std::int32_t(in.u32()));
  d.sweep_axis = int(std::int32_t(in.u32()));
  d.grid_above_bodies = in.u32();
  std::uint8_t b[9];
  for (std::uint8_t& x : b) x = in.u8();
  // b[4]: BodyContacts, up to `automatic`; b[5]: rest conditions (bit 0) and ground hulls (bit 1),
  // which snapshots from before the option hold 0.
  for (int i = 0; i < 7; ++i)
    if (b[i] > (i == 4 ? 2 : i == 5 ? 3 : 1)) return false;
  if (b[7] > 2 || b[8] > 1) return false;
  d.table_restitution_threshold = b[0] != 0;
  d.shock_propagation = b[1] != 0;
  d.nearest_radius = b[2] != 0;
  d.pair_response = PairResponse(b[3]);
  d.body_contacts = BodyContacts(b[4]);
  d.rest_conditions = (b[5] & 1u) != 0;
  d.ground_hulls = (b[5] & 2u) != 0;
  d.pile_rest = b[6] != 0;
  d.broad_phase = BroadPhase(b[7]);
  d.sleep_islands = b[8] != 0;
  return true;
}

/// Writes the whole snapshot of `w` (or, with a null buffer, counts its bytes).
template <int D>
std::size_t write_snapshot(const WorldData<D>& w, unsigned char* buf)
{
  SnapshotWriter out(buf);
  out.u32(snapshot_magic);
  out.u16(snapshot_version);
  out.u8(D);
  out.u8(sizeof(Scalar));
  out.u32(0);  // the size, filled in below
  out.u32((w.grid_storage ? snap_grid_storage : 0u) | (w.grid_layout ? snap_grid_layout : 0u) |
          (w.sweep_current ? snap_sweep_current : 0u));
  for (std::uint32_t n : {w.body_count, w.plane_count, w.shape_count, w.entry_count}) out.u32(n);
  out.u64(w.step_count);
  out.u64(w.energy_clamps);
  out.u64(w.statistical_responses);
  out.scalar(w.widest);
  write_def(out, w.def);
  for (std::uint32_t i = 0; i < w.shape_count; ++i) out.u64(shape_fingerprint(w.shapes[i]));
  for (std::uint32_t i = 0; i < w.plane_count; ++i) {
    out.vec(w.planes[i].normal);
    out.scalar(w.planes[i].offset);
  }
  for (std::uint32_t i = 0; i < w.body_count; ++i) {
    const Body<D>& b = w.bodies[i];
    const bool anchor = keeps_step_start(w, b);
    out.u8((b.touching ? snap_touching : 0u) | (b.on_ground ? snap_on_ground : 0u) |
           (b.pile_rest ? snap_pile_rest : 0u) | (removed_slot(w.slots, i) ? snap_removed : 0u) |
           (anchor ? snap_step_start : 0u));
    out.u16(w.slots.generation[i]);
    out.u16(b.shape);
    out.u8(std::uint32_t(b.state));
    out.u8(b.rest_pose);
    out.u64(b.rng_state);
    out.rot(b.orientation);
    out.vec(b.position);
    out.vec(b.linear_velocity);
    out.vec(b.angular_velocity);
    for (Scalar x : {b.radius, b.inv_mass, b.slow_time, b.rest_blend}) out.scalar(x);
    if (anchor) out.vec(b.step_start);
  }
  for (std::uint32_t k = 0; k < w.entry_count; ++k) out.u32(w.grid_layout ? w.order[k] : w.entries[k].body);
  const std::size_t size = out.size() + 8;
  if (buf != nullptr) {
    SnapshotWriter at(buf + 8);
    at.u32(std::uint32_t(size));
    SnapshotWriter end(buf + out.size());
    end.u64(fnv1a64(buf, out.size()));
  }
  return size;
}

/// A scratch word per body slot for `read_snapshot`'s check of the sweep order: words of the
/// broad phase's block that the next step writes before it reads them. In the sweep layout the
/// entries' `active` (`find_pairs_sweep` sets every one before it sorts, or returns before it
/// reads any); in the grid layout the grid's records (built from scratch every step).
template <int D>
bool order_mark(const WorldData<D>& w, std::uint32_t slot)
{
  return (w.grid_layout ? w.grid.items[slot].key : std::uint32_t(w.entries[slot].active)) != 0;
}
template <int D>
void set_order_mark(WorldData<D>& w, std::uint32_t slot, bool on)
{
  if (w.grid_layout) w.grid.items[slot].key = on ? 1u : 0u;
  else w.entries[slot].active = on ? 1u : 0u;
}

/// One body slot's state as it was read, before it is checked.
template <int D>
struct SnapshotBody {
  Body<D> body;
  std::uint8_t flags, state;
  std::uint16_t generation, shape;  // shape: as read, before `Body::shape` keeps its low bits
};

/// Checks a body slot as `add_body` and the setters check their input: the status of the first
/// problem, or ok.
template <int D>
Status check_snapshot_body(const WorldData<D>& w, const SnapshotBody<D>& r, const WorldDef<D>& def,
                           std::uint32_t shape_count)
{
  using Vec = typename Space<D>::Vec;
  const Body<D>& b = r.body;
  if (r.flags >= 32 || r.state > std::uint8_t(MotionState::asleep)) return Status::invalid_snapshot;
  if (r.shape >= shape_count) return Status::invalid_shape;
  const Shape<D>& shape = w.shapes[r.shape];
  const bool removed = (r.flags & snap_removed) != 0;
  if (r.generation > retired_generation || (r.generation == retired_generation && !removed))
    return Status::invalid_snapshot;
  const Vec x = removed ? Vec(Vec::Zero()) : b.position;
  const Status s = check_state<D>(x, b.orientation, b.linear_velocity, b.angular_velocity);
  if (s != Status::ok) return s;
  if (!finite(b.radius) || !finite(b.inv_mass) || !finite(b.slow_time) || !finite(b.rest_blend))
    return Status::non_finite;
  // A plain sphere keeps its shape's radius; a statistical body's comes from its table, whose
  // shapes the world's limits bound. A smaller one (a tiny positive float) would overflow the
  // contact arithmetic to infinity.
  if (!(b.radius >= limits::min_radius) || b.radius > limits::max_radius) return Status::invalid_radius;
  if (!shape.statistical && b.radius != shape.radius) return Status::invalid_radius;
  if (b.inv_mass < Scalar(1) / limits::max_mass || b.inv_mass > Scalar(1) / limits::min_mass) return Status::invalid_mass;
  // A negative slow time is a settling time still to run (`SettleView`), for a body in a pose.
  if (b.slow_time < -max_settle_time || b.rest_blend < 0 || b.rest_blend > 1) return Status::out_of_range;
  if (b.slow_time < 0 && b.rest_pose == no_rest_pose) return Status::invalid_snapshot;
  if (b.rest_pose != no_rest_pose && (!shape.statistical || b.rest_pose >= shape.signature.rest.count))
    return Status::invalid_snapshot;
  if (removed) {
    // As `remove_body` leaves a slot: at infinity, still, asleep, without contacts.
    const Scalar inf = std::numeric_limits<Scalar>::infinity();
    const bool left = (b.position.array() == inf).all() && (b.linear_velocity.array() == 0).all() &&
                      squared_norm(b.angular_velocity) == 0 && r.state == std::uint8_t(MotionState::asleep) &&
                      (r.flags & ~snap_removed) == 0 && b.rest_pose == no_rest_pose &&
                      b.rest_blend == 0 && b.slow_time == 0;
    return left ? Status::ok : Status::invalid_snapshot;
  }
  if (!finite(b.step_start)) return Status::non_finite;
  if (!within(b.step_start, limits::coordinate)) return Status::out_of_range;
  // Saved exactly for the bodies whose sleep test reads it (`keeps_step_start`), so that a
  // snapshot has one encoding and a loaded world saves the bytes it was loaded from.
  WorldData<D> probe_world = w;
  probe_world.def = def;
  Body<D> probe = b;
  probe.state = MotionState(r.state);
  if (keeps_step_start(probe_world, probe) != ((r.flags & snap_step_start) != 0)) return Status::invalid_snapshot;
  return Status::ok;
}

/// Parses a snapshot whose header, size and checksum `load` has checked: with `commit` false
/// it checks everything and writes only scratch (`order_mark`); with `commit` true, called only
/// after a check passed, it writes the state into `w`.
template <int D>
Status read_snapshot(WorldData<D>& w, const unsigned char* data, std::size_t size, bool commit)
{
  SnapshotReader in(data, size - 8);
  for (int i = 0; i < 3; ++i) in.u32();  // magic, version, dimension, width and size: checked
  const std::uint32_t flags = in.u32();
  const std::uint32_t bodies = in.u32(), planes = in.u32(), shapes = in.u32(), entries = in.u32();
  if (flags >= 8 || ((flags & snap_grid_layout) && !(flags & snap_grid_storage))) return Status::invalid_snapshot;
  if (((flags & snap_grid_storage) != 0) != w.grid_storage) return Status::snapshot_incompatible;
  if (shapes != w.shape_count) return Status::shape_mismatch;
  if (bodies > w.max_bodies || planes > w.max_planes) return Status::capacity_exceeded;
  if (entries > bodies) return Status::invalid_snapshot;
  const std::uint64_t steps = in.u64(), clamps = in.u64(), responses = in.u64();
  const Scalar widest = in.scalar();
  WorldDef<D> def;
  if (!read_def(in, def)) return Status::invalid_snapshot;
  if (!in.ok()) return Status::invalid_snapshot;
  const Status def_status = check_world_def(def);
  if (def_status != Status::ok) return def_status;
  if (def.broad_phase == BroadPhase::grid && !w.grid_storage) return Status::invalid_parameter;
  if (check_def_features(w.features, def) != Status::ok) return Status::not_compiled;
  // The widest diameter is that of some shape added (`add_body`), or 0 before any body.
  bool widest_known = widest == 0 && bodies == 0;
  for (std::uint32_t i = 0; i < shapes; ++i) {
    if (in.u64() != shape_fingerprint(w.shapes[i])) return Status::shape_mismatch;
    widest_known = widest_known || widest == 2 * w.shapes[i].bounding_radius;
  }
  if (!widest_known) return Status::invalid_snapshot;
  if (commit) {
    def.workers = w.def.workers;  // the loading world's threads, not the saving one's
    w.def = def;
    w.step_count = steps;
    w.energy_clamps = clamps;
    w.statistical_responses = responses;
    w.widest = widest;
    w.sweep_current = (flags & snap_sweep_current) != 0;
    w.plane_count = planes;
    w.body_count = bodies;
    w.entry_count = entries;
    w.pair_count = 0;
    w.touching_pairs = 0;
    for (std::uint32_t k = 0; k < bit_words(w.max_bodies); ++k) w.awake[k] = w.flagged[k] = w.slots.free[k] = 0;
    w.awake_count = w.slots.free_count = w.slots.removed = 0;
  }
  for (std::uint32_t i = 0; i < planes; ++i) {
    Plane<D> p;
    in.vec(p.normal);
    p.offset = in.scalar();
    if (!finite(p.normal) || !finite(p.offset) || !(std::fabs(p.normal.squaredNorm() - 1) < Scalar(2e-3)))
      return Status::invalid_plane;
    if (!within(p.offset, limits::coordinate)) return Status::out_of_range;
    if (check_plane_features(w.features, def.gravity, p.normal) != Status::ok) return Status::not_compiled;
    if (commit) w.planes[i] = p;
  }
  if (commit) w.tilted_planes = any_tilted_plane(w);
  for (std::uint32_t i = 0; i < bodies; ++i) {
    SnapshotBody<D> r{};
    Body<D>& b = r.body;
    r.flags = in.u8();
    r.generation = in.u16();
    r.shape = in.u16();
    b.shape = std::uint16_t(r.shape & ((1u << shape_index_bits) - 1u));  // checked below shape_count
    r.state = in.u8();
    b.rest_pose = in.u8();
    b.rng_state = in.u64();
    in.rot(b.orientation);
    in.vec(b.position);
    in.vec(b.linear_velocity);
    in.vec(b.angular_velocity);
    for (Scalar* x : {&b.radius, &b.inv_mass, &b.slow_time, &b.rest_blend}) *x = in.scalar();
    b.step_start = b.position;
    if (r.flags & snap_step_start) in.vec(b.step_start);
    if (!in.ok()) return Status::invalid_snapshot;
    const Status s = check_snapshot_body(w, r, def, shapes);
    if (s != Status::ok) return s;
    // Every body of a shape was added with the shape's bounding diameter taken into `widest`.
    if (2 * w.shapes[r.shape].bounding_radius > widest) return Status::invalid_snapshot;
    if (!commit) continue;
    b.state = MotionState(r.state);
    b.touching = (r.flags & snap_touching) != 0;
    b.on_ground = (r.flags & snap_on_ground) != 0;
    b.pile_rest = (r.flags & snap_pile_rest) != 0;
    w.bodies[i] = b;  // its `supports` 0, as `r` was value-initialised
    w.slots.generation[i] = r.generation;
    if (r.flags & snap_removed) {
      ++w.slots.removed;
      if (r.generation != retired_generation) {
        set_bit(w.slots.free, i);
        ++w.slots.free_count;
      }
    } else if (b.state != MotionState::asleep) {
      set_bit(w.awake, i);
      ++w.awake_count;
    } else if (b.touching || b.on_ground) {
      // Its flags came from the last step's passes: the next step must clear them, as it would
      // have through the touching pairs or `flagged` (`forget_contacts`).
      set_bit(w.flagged, i);
    }
  }
  // The sweep order: each slot below `entries` exactly once.
  if (!commit)
    for (std::uint32_t k = 0; k < entries; ++k) {
      // Records never made yet are begun first, as the broad phase begins them.
      if (w.grid_layout)
        new (&w.grid.items[k]) GridItem<D>{typename Space<D>::Vec(Space<D>::Vec::Zero()), 0, 0};
      else if (k >= w.entry_count)
        new (&w.entries[k]) SweepEntry(sweep_entry(k, false));
      set_order_mark(w, k, false);
    }
  for (std::uint32_t k = 0; k < entries; ++k) {
    const std::uint32_t slot = in.u32();
    if (!in.ok() || slot >= entries) return Status::invalid_snapshot;
    if (!commit) {
      if (order_mark(w, slot)) return Status::invalid_snapshot;
      set_order_mark(w, slot, true);
    } else if (flags & snap_grid_layout) {
      new (&w.order[k]) std::uint32_t(slot);
    } else {
      new (&w.entries[k]) SweepEntry(sweep_entry(slot, true));
    }
  }
  if (in.offset() != size - 8) return Status::invalid_snapshot;  // bytes left over
  if (commit) w.grid_layout = (flags & snap_grid_layout) != 0;
  return Status::ok;
}

}  // namespace detail

/// The most bytes `save` writes for a world of these capacities (every slot holding a body
/// measured from a sleep anchor): the size of a static buffer that holds any of its snapshots.
template <int D>
constexpr std::size_t snapshot_capacity(std::uint32_t max_bodies, std::uint32_t max_planes, std::uint32_t max_shapes)
{
  constexpr std::size_t s = sizeof(Scalar);
  // Header, counters and widest; the `WorldDef` (gravity, seed, 15 scalars, 4 integers, 9 bytes);
  // shapes, planes, body slots with their step start and sweep entry; the checksum.
  return 32 + 24 + s + (D + 15) * s + 8 + 16 + 9 + 8 * std::size_t(max_shapes) + (D + 1) * s * max_planes +
         (15 + (D == 3 ? 20 : 13) * s + 4) * std::size_t(max_bodies) + 8;
}

/// Bytes `save` writes for this world now: 32 + 8 per shape + (D + 1) scalars per plane, per
/// body slot 15 bytes and 17 scalars in 3D (11 in 2D) plus a 4-byte sweep entry, a few hundred
/// bytes of parameters, and D more scalars for each awake body measured from a sleep anchor.
template <int D>
std::size_t snapshot_size(const WorldCore<D>& world)
{
  return detail::write_snapshot(detail::CoreAccess::data(world), nullptr);
}

/// Writes the world's state into `buf` (`cap` bytes) and its size into `*written` (when not
/// null). `capacity_exceeded` when it needs more than `cap` bytes (`snapshot_size`): then
/// nothing is written and `*written` is the size needed.
template <int D>
Status save(const WorldCore<D>& world, unsigned char* buf, std::size_t cap, std::size_t* written)
{
  const std::size_t n = snapshot_size(world);
  if (written != nullptr) *written = n;
  if (buf == nullptr || n > cap) return Status::capacity_exceeded;
  detail::write_snapshot(detail::CoreAccess::data(world), buf);
  return Status::ok;
}

/// Replaces the world's state with a snapshot's (`size` bytes from `save`), in which the world
/// must have the same shapes, added in the same order (the planes, bodies, parameters and step
/// count are the snapshot's). The world then steps on bit for bit as the saved one, as long as
/// neither overflows its pair buffer. Refused, changing no state, with `invalid_snapshot`
/// (not a snapshot, truncated, too long, checksum wrong, a value no world can hold),
/// `snapshot_incompatible` (another version, dimension or scalar width, or the other broad-phase
/// storage), `shape_mismatch`, `not_compiled` (hull contacts or a tilted plane in a world compiled
/// without them, statsim/features.hpp), `capacity_exceeded` (more bodies or planes than the world holds),
/// or the status a setter gives a value out of its range (`non_finite`, `out_of_range`,
/// `non_unit_quaternion`, `invalid_parameter`...). Bodies beyond `limits` (one that fell far)
/// are refused like such input: such a world saves but does not load.
template <int D>
Status load(WorldCore<D>& world, const unsigned char* data, std::size_t size)
{
  detail::WorldData<D>& w = detail::SnapshotAccess::data(world);
  if (data == nullptr || size < detail::snapshot_header_bytes + 8) return Status::invalid_snapshot;
  detail::SnapshotReader head(data, detail::snapshot_header_bytes);
  if (head.u32() != detail::snapshot_magic) return Status::invalid_snapshot;
  const std::uint16_t version = head.u16();
  const std::uint8_t dimension = head.u8(), width = head.u8();
  if (version != detail::snapshot_version || dimension != D || width != sizeof(Scalar))
    return Status::snapshot_incompatible;
  if (head.u32() != size) return Status::invalid_snapshot;
  detail::SnapshotReader tail(data + size - 8, 8);
  if (tail.u64() != detail::fnv1a64(data, size - 8)) return Status::invalid_snapshot;
  const Status s = detail::read_snapshot(w, data, size, false);
  // The check wrote scratch words of the broad phase's block (`order_mark`) that the queries'
  // index may read as records; queries test every body until the next step makes them again.
  w.index.valid = false;
  if (s != Status::ok) return s;
  detail::ImpactLog<D>& impacts = detail::SnapshotAccess::impacts(world);
  impacts.count = impacts.found = 0;
  return detail::read_snapshot(w, data, size, true);
}

}  // namespace statsim
