#pragma once
/// @file
/// Collision radius, rest and sleep: the statistical bodies' radius at the start of a step
/// (paper 3.3.1), and at its end the resting conditions (paper 3.4) and the motion states
/// (moving, settling, asleep).

#include "statsim/detail/hull.hpp"
#include "statsim/detail/slope.hpp"
#include "statsim/detail/slope_contact.hpp"
#include "statsim/detail/tipping.hpp"
#include "statsim/detail/world_data.hpp"

#include <cstdint>
#include <limits>

namespace statsim {
namespace detail {

/// The normal of the ground plane (normal within `ground_cosine` of up) nearest to the body's
/// sphere, or up when there is none: rest poses, their turn and their height are taken against
/// the plane a body rests on, which on a slope is not level.
template <int D>
typename Space<D>::Vec ground_normal(const WorldData<D>& w, const Body<D>& b)
{
  using Vec = typename Space<D>::Vec;
  const int up = Space<D>::up_axis;
  Vec normal = Vec::Unit(up);
  Scalar nearest = std::numeric_limits<Scalar>::infinity();
  for (std::uint32_t p = 0; p < w.plane_count; ++p) {
    const Plane<D>& plane = w.planes[p];
    if (!(plane.normal[up] >= w.def.ground_cosine)) continue;
    const Scalar gap = plane.normal.dot(b.position) - plane.offset - b.radius;
    if (gap < nearest) {
      nearest = gap;
      normal = plane.normal;
    }
  }
  return normal;
}

/// Collision radius of statistical bodies (paper 3.3.1), blended toward the rest height of a
/// chosen rest pose (paper 3.4).
template <class FS, int D>
void update_radii(WorldData<D>& w)
{
  using Vec = typename Space<D>::Vec;
  if constexpr (!FS::statistical) {
    return;
  }
  for_each_set(w.awake, w.body_count, [&](std::uint32_t i) {
    Body<D>& b = w.bodies[i];
    const Shape<D>& shape = w.shapes[b.shape];
    if (!shape.statistical) return;
    const SignatureView<D>& sig = shape.signature;
    // Spin ratio with the speed floored: a body bouncing in place has |v| near 0 one step and
    // g dt the next, and |w| L / |v| would swing its radius between the table's ends.
    const Scalar speed = b.linear_velocity.norm();
    const Scalar floor = w.def.spin_ratio_speed_floor;
    const Vec v_ref = speed < floor ? Vec(Vec::Unit(0) * floor) : Vec(b.linear_velocity);
    const Scalar r = collision_radius<D>(sig, v_ref, b.angular_velocity, w.def.nearest_radius);
    if (b.rest_pose == no_rest_pose && !b.pile_rest) {
      b.radius = r;
      return;
    }
    const Scalar h = b.rest_pose != no_rest_pose ? sig.rest.heights[b.rest_pose] : shape.mean_rest_height;
    const Scalar blended = r + (h - r) * b.rest_blend;
    // A settling body's sphere changes size about its lowest point, so a body blending to its
    // rest height settles smoothly instead of dropping (paper 3.4); on the ground that point is
    // below the centre along the plane's normal.
    // (On a slope the body keeps its hull's support from the plane instead: `hull_radius`.)
    if (b.on_ground) {
      const Vec n = ground_normal(w, b);
      if (!slope_hull<FS>(w, b, n)) b.position += n * (blended - b.radius);
    } else if (b.pile_rest) {
      b.position[Space<D>::up_axis] += blended - b.radius;
    }
    b.radius = blended;
  });
}

/// Resting conditions (paper 3.4): a statistical body settling on the ground picks the rest
/// pose nearest to its orientation relative to the ground's normal `ground` and blends its
/// radius toward that pose's height; a body that speeds up again blends back and forgets the
/// pose; a body briefly off the ground keeps it. With settling data (`SettleView`) the body
/// draws, as it picks its pose, how long it settles there: `slow_time` counts up from minus that
/// time (`update_motion_states`), and while it is negative the body rocks about the pose
/// (`settle_rock`) and cannot be still. Times scale with the square root of the shape's scale,
/// as a period of rocking under gravity does.
template <class FS, int D>
void update_rest_pose(const WorldData<D>& w, Body<D>& b, bool settling_on_ground, bool settling_on_bodies, bool fast,
                      Scalar dt, const typename Space<D>::Vec& ground)
{
  if constexpr (!FS::statistical) {
    return;
  }
  const Shape<D>& shape = w.shapes[b.shape];
  const WorldDef<D>& def = w.def;
  if (!shape.statistical || !def.rest_conditions || shape.signature.rest.count == 0) return;
  const Scalar step = dt / def.rest_blend_time;
  if (settling_on_ground) {
    if (b.rest_pose == no_rest_pose) {
      const std::uint32_t pose = nearest_rest_pose<D>(shape.signature, b.orientation, ground, shape.rest_bias.data());
      if (pose >= shape.signature.rest.count) return;  // only with a non-finite orientation
      b.rest_pose = std::uint8_t(pose);
      const SettleView& settle = shape.signature.settle;
      if (settle.present()) {
        Pcg32 rng = rng_of(w, b);
        const Scalar time = settle.at(pose, rng.uniform()) * std::sqrt(shape.signature.scale);
        b.rng_state = rng.state();
        b.slow_time = -time;
      }
    }
    b.pile_rest = false;
    b.rest_blend = b.rest_blend + step < 1 ? b.rest_blend + step : Scalar(1);
  } else if (def.pile_rest && settling_on_bodies && (b.pile_rest || b.rest_pose == no_rest_pose)) {
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

/// True when the chosen rest pose's normal is within `rest_snap_cosine` of the ground's normal.
template <int D>
bool in_rest_pose(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& ground)
{
  const SignatureView<D>& sig = w.shapes[b.shape].signature;
  const typename Space<D>::Vec u = b.orientation * sig.rest.normal(b.rest_pose);
  return u.dot(ground) >= w.def.rest_snap_cosine;
}

/// Puts an awake body to sleep where the last step left it: still, off the awake set, and, if it
/// rests on the ground in its chosen pose (`posed`), exactly in that pose.
template <class FS, int D>
void fall_asleep(WorldData<D>& w, Body<D>& b, std::uint32_t i, bool posed, const typename Space<D>::Vec& ground)
{
  using Vec = typename Space<D>::Vec;
  // Where the centre stood above the ground: `held_radius` of the body as it was, settling (the
  // collision radius, or the hull's support where that is more); asleep it would be the radius.
  const Scalar above = b.rest_pose != no_rest_pose && b.on_ground && posed ? held_radius<FS>(w, b, ground) : Scalar(0);
  b.state = MotionState::asleep;
  clear_bit(w.awake, i);
  --w.awake_count;
  set_bit(w.flagged, i);  // its contact flags stay set until the next step clears them
  b.linear_velocity = Vec::Zero();
  b.angular_velocity = Space<D>::zero_spin();
  if (b.rest_pose != no_rest_pose && b.on_ground && posed) {
    // Fall asleep exactly in the pose, at its height: the last few degrees and the rest of
    // the radius blend are below what a slow body would show. The centre stood `above` the
    // ground: it ends at the pose's height above it. Not lower, though, for a body near others
    // whose blend has not run its course: it settled on them rather than on the ground (its
    // sphere, still larger than the pose's height, reached the ground beside them), and the
    // rest of the blend would put it into the body under it, where asleep nothing lifts it out.
    const SignatureView<D>& sig = w.shapes[b.shape].signature;
    b.orientation = snap_to_rest(b.orientation, sig.rest.normal(b.rest_pose), ground);
    const Scalar h = sig.rest.heights[b.rest_pose];
    const bool held = bit_set(w.paired, i) && b.rest_blend < 1;
    if (!(held && h < above)) b.position += ground * (h - above);
    b.radius = h;
    b.rest_blend = 1;
  }
}

/// `WorldDef::sleep_islands`: of the awake bodies marked ready in `ready` (still for their sleep
/// time), unmarks every one connected to an unmarked awake body through the first `touching`
/// pairs, then puts the ones left marked to sleep. A sleeper in a pair counts as ready: it woke in
/// the impact pass if its awake neighbour was not. The marks spread along the pairs, which the
/// shock pass left ordered from the bottom up, in sweeps up and down the buffer until one changes
/// nothing: a pile's island takes a few sweeps, not one per body.
template <class FS, int D>
void sleep_islands(WorldData<D>& w, std::uint32_t* ready, std::uint32_t touching)
{
  using Vec = typename Space<D>::Vec;
  const auto restless = [&](std::uint32_t i) {
    return w.bodies[i].state != MotionState::asleep && !bit_set(ready, i);
  };
  const auto spread = [&](std::uint32_t k) {
    const Pair& p = w.pairs[k];
    const bool ra = restless(p.a), rb = restless(p.b);
    if (ra == rb) return false;
    const std::uint32_t calm = ra ? p.b : p.a;
    if (w.bodies[calm].state == MotionState::asleep) return false;
    clear_bit(ready, calm);
    return true;
  };
  for (bool changed = true; changed;) {
    changed = false;
    for (std::uint32_t k = 0; k < touching; ++k) changed = spread(k) || changed;
    for (std::uint32_t k = touching; k-- > 0;) changed = spread(k) || changed;
  }
  for_each_set(w.awake, w.body_count, [&](std::uint32_t i) {
    if (!bit_set(ready, i)) return;
    Body<D>& b = w.bodies[i];
    // As `update_motion_states` found it: a ready body is settling, and one that chose its pose
    // in this step is not ready, so that the pose it turns toward is the one it had.
    const Vec ground = b.on_ground ? ground_normal(w, b) : Vec(Vec::Unit(Space<D>::up_axis));
    const bool posed = b.rest_pose == no_rest_pose || !b.on_ground || in_rest_pose(w, b, ground);
    fall_asleep<FS>(w, b, i, posed, ground);
  });
}

/// `WorldDef::sleep_islands`: after the step's sleep tests, each sleeper of the first `touching`
/// pairs whose neighbour is awake and was not still in the step joins that neighbour's island
/// (`joins_island`): it wakes for the next step, whose broad phase then finds its pairs with
/// other sleepers. Joined in the contact passes it would move in this step without them (the
/// broad phase skipped pairs of two sleepers), into whichever sleeper lies in its way; here it has
/// been a static support for one step.
template <int D>
void join_islands(WorldData<D>& w, std::uint32_t touching)
{
  for (std::uint32_t k = 0; k < touching; ++k) {
    Body<D>& a = w.bodies[w.pairs[k].a];
    Body<D>& b = w.bodies[w.pairs[k].b];
    if (joins_island(w, a, b)) join_island(w, b);
    else if (joins_island(w, b, a)) join_island(w, a);
  }
}

/// The last phase of a step: each awake body is moving, settling (touching and slower than
/// `settle_speed`) or, once still for `sleep_time`, asleep (with `WorldDef::sleep_islands`, once
/// its island is: `sleep_islands`); settling bodies follow the resting conditions. `touching`:
/// the step's touching pairs, at the front of the pair buffer.
template <class FS, int D>
void update_motion_states(WorldData<D>& w, Scalar dt, std::uint32_t touching)
{
  const bool tilted_planes = FS::slopes && w.tilted_planes;
  using Vec = typename Space<D>::Vec;
  const WorldDef<D>& def = w.def;
  const Scalar settle2 = def.settle_speed * def.settle_speed;
  const Scalar sleep2 = def.sleep_speed * def.sleep_speed;
  const Scalar common = w.common_bound;
  // The islands' marks go in the slope substeps' bit set, which nothing reads after the contact
  // passes and the next step clears before it writes (`WorldData::rolled`).
  std::uint32_t* const ready = def.sleep_islands ? w.rolled : nullptr;
  if (ready)
    for (std::uint32_t k = 0; k < bit_words(w.body_count); ++k) ready[k] = 0;
  for_each_set(w.awake, w.body_count, [&](std::uint32_t i) {
    Body<D>& b = w.bodies[i];
    const Scalar bound = common > 0 ? common : w.shapes[b.shape].bounding_radius;
    const Scalar r2 = bound * bound;
    const Scalar v2 = b.linear_velocity.squaredNorm();
    // A body turning into its rest pose spins because the resting conditions make it: its
    // spin does not count against settling, and it sleeps once the pose is (nearly) reached.
    const bool turning = b.rest_pose != no_rest_pose;
    const Scalar w2 = turning ? Scalar(0) : squared_norm(b.angular_velocity) * r2;
    const Scalar speed2 = v2 > w2 ? v2 : w2;
    const bool settling = b.touching && speed2 < settle2;
    const Vec ground = settling && b.on_ground ? ground_normal(w, b) : Vec(Vec::Unit(Space<D>::up_axis));
    // On a slope a pose steeper than its tipping angle is no rest pose (`settle_on_slope`).
    // A body rolling down a slope on its hull (statsim/detail/slope_contact.hpp) takes a pose only
    // once its contacts have all but stopped it there: the faces it rolls over are not poses it
    // rests in. On level ground nothing pulls a body on once it is slower than the settle speed:
    // with `WorldDef::ground_hulls` it takes its pose then, as without, and turns into it on its
    // hull (`hull_radius`); rocking on to the sleep speed in the hull's substeps cost time in
    // every step and brought the drops no nearer the reference (tools/fidelity/LOG.md).
    const bool rolling = tilted_planes && settling && b.on_ground && speed2 >= sleep2 &&
                         b.rest_pose == no_rest_pose && slope_hull<FS>(w, b, ground);
    const SlopeSettle slope = rolling                                   ? SlopeSettle::tipping
                              : tilted_planes && settling && b.on_ground ? settle_on_slope<FS>(w, b, ground)
                                                                         : SlopeSettle::pose;
    const bool tipping = slope == SlopeSettle::tipping;
    update_rest_pose<FS>(w, b, settling && b.on_ground && slope == SlopeSettle::pose, settling && !b.on_ground,
                     speed2 >= settle2, dt, ground);
    // Its settling time runs (a negative slow time, `update_rest_pose`): it rocks, and is not
    // still before the time is over. The time runs once the body is within the snap angle of its
    // pose: the turn toward it moves the farthest point at the settle speed, and the reference's
    // settling was timed from the last moment at that speed. A rock that lifts it off the ground
    // for a step keeps the clock; only speed stops it.
    if (b.slow_time < 0 && b.rest_pose == no_rest_pose) b.slow_time = 0;  // a slope took its pose away
    if (b.slow_time < 0 && speed2 < settle2) {
      b.state = settling ? MotionState::settling : MotionState::moving;
      // One that other bodies hold out of its pose (on its hull, `hull_radius`) cannot reach it:
      // its time runs too, or it would never sleep.
      const bool on_ground = settling && b.on_ground;
      if (!on_ground || in_rest_pose(w, b, ground) || hull_radius<FS>(w, b, ground) > b.radius)
        b.slow_time = b.slow_time + dt < 0 ? b.slow_time + dt : Scalar(0);
      if (b.slow_time < 0) return;
    }
    // Its time is over (settling data): it stops exactly in its pose once within the snap angle
    // (as it would on falling asleep), not a few degrees off it while it waits out its sleep time.
    if (settling && b.on_ground && slope == SlopeSettle::pose && b.rest_pose != no_rest_pose &&
        w.shapes[b.shape].signature.settle.present() && in_rest_pose(w, b, ground)) {
      b.orientation = snap_to_rest(b.orientation, w.shapes[b.shape].signature.rest.normal(b.rest_pose), ground);
      b.angular_velocity = Space<D>::zero_spin();
    }
    if (!settling) {
      b.state = MotionState::moving;
      b.slow_time = 0;
      return;
    }
    b.state = MotionState::settling;
    // Stillness by displacement as well as velocity: with three or more contacts the passes
    // can leave a velocity that separates from some while sliding along another; the next
    // step moves the body into them and the shock pass moves it back, a cycle in which it
    // never moves and never sleeps (tools/ref2d/README.md shows how often in a pile).
    const Scalar moved2 = (b.position - b.step_start).squaredNorm();
    Scalar lin2 = moved2 < v2 * dt * dt ? moved2 / (dt * dt) : v2;
    // With hull contacts a body held by several neighbours can also cycle over a few steps: it
    // slides down one neighbour's face into another, whose overlap correction lifts it back, at a
    // velocity above the sleep speed in every step and without going anywhere. Its centre is
    // measured from where its slow time began (`sleeps_from_anchor`; `integrate` keeps it there):
    // it is still while it stays within the distance a body at the sleep speed covers in the
    // sleep time, |x - x_0| < v_sleep t_sleep, as well as while it is slower than the sleep speed.
    if (sleeps_from_anchor<FS>(w, b)) {
      const Scalar reach = def.sleep_speed * def.sleep_time;
      if (moved2 < reach * reach) lin2 = 0;
    }
    // It turns at ground contacts: one that keeps its pose while held up by other bodies cannot
    // reach it there, and may sleep where it is.
    // (On a slope `settle_on_slope` may have taken the pose away in this step.)
    const bool posed = !turning || b.rest_pose == no_rest_pose || !b.on_ground || in_rest_pose(w, b, ground);
    // On its hull (`hull_radius`) a body propped by others may stay still out of its pose; it
    // sleeps where it is after three sleep times.
    const bool wedged = !posed && hull_radius<FS>(w, b, ground) > b.radius;
    const bool still = !tipping && (lin2 > w2 ? lin2 : w2) < sleep2 && (posed || wedged);
    b.slow_time = still ? b.slow_time + dt : 0;
    if (!still || b.slow_time < (posed ? def.sleep_time : 3 * def.sleep_time)) return;
    // With islands a body still for `island_wait` sleep times sleeps whatever its island does: one
    // body that never comes to rest would otherwise hold a whole pile awake.
    if (!ready || b.slow_time >= island_wait * def.sleep_time) fall_asleep<FS>(w, b, i, posed, ground);
    else if (turning || b.rest_pose == no_rest_pose) set_bit(ready, i);
  });
  if (ready) {
    sleep_islands<FS>(w, ready, touching);
    join_islands(w, touching);
  }
}

}  // namespace detail
}  // namespace statsim
