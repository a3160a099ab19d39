#pragma once
/// @file
/// Collision radius, rest and sleep: the statistical bodies' radius at the start of a step
/// (paper 3.3.1), and at its end the resting conditions (paper 3.4) and the motion states
/// (moving, settling, asleep).

#include "statsim/hull_contact.hpp"
#include "statsim/slope_contact.hpp"
#include "statsim/tipping.hpp"
#include "statsim/world_data.hpp"

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
template <int D>
void update_radii(WorldData<D>& w)
{
  using Vec = typename Space<D>::Vec;
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
      if (!slope_hull(w, b, n)) b.position += n * (blended - b.radius);
    } else if (b.pile_rest) {
      b.position[Space<D>::up_axis] += blended - b.radius;
    }
    b.radius = blended;
  });
}

/// Resting conditions (paper 3.4): a statistical body settling on the ground picks the rest
/// pose nearest to its orientation relative to the ground's normal `ground` and blends its
/// radius toward that pose's height; a body that speeds up again blends back and forgets the
/// pose; a body briefly off the ground keeps it.
template <int D>
void update_rest_pose(const WorldData<D>& w, Body<D>& b, bool settling_on_ground, bool settling_on_bodies, bool fast,
                      Scalar dt, const typename Space<D>::Vec& ground)
{
  const Shape<D>& shape = w.shapes[b.shape];
  const WorldDef<D>& def = w.def;
  if (!shape.statistical || !def.rest_conditions || shape.signature.rest.count == 0) return;
  const Scalar step = dt / def.rest_blend_time;
  if (settling_on_ground) {
    if (b.rest_pose == no_rest_pose) {
      const std::uint32_t pose = nearest_rest_pose<D>(shape.signature, b.orientation, ground, shape.rest_bias.data());
      if (pose >= shape.signature.rest.count) return;  // only with a non-finite orientation
      b.rest_pose = std::uint8_t(pose);
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

/// On a ground plane of unit normal `n` that gravity pulls bodies along (`downhill`, and
/// `slope` = |g_t| / |g.n| = tan of the tilt a): whether rest pose `pose` of a body of shape
/// `shape`, turned from `orientation` into the pose against the plane, fails to hold it. A rigid
/// body stands on its support set, the face under it; the line of gravity through its centre
/// meets the plane h tan(a) downhill of the point under the centre (h the support toward the
/// plane), and the body tips over the face's downhill edge once that point is beyond the edge:
/// e < h tan(a), e the face's extent downhill (`support_extent`). The tilt at which a pose stops
/// holding, atan(e / h), thus depends on the direction the slope falls in the body's frame, and
/// is read from the support map: no table holds it. The shape must have a support map.
template <int D>
bool pose_tips(const Shape<D>& shape, const typename Space<D>::Rot& orientation, std::uint32_t pose,
               const typename Space<D>::Vec& n, const typename Space<D>::Vec& downhill, Scalar slope)
{
  using Vec = typename Space<D>::Vec;
  const SignatureView<D>& sig = shape.signature;
  const typename Space<D>::Rot at_rest = snap_to_rest(orientation, sig.rest.normal(pose), n);
  const Vec down = to_body(at_rest, Vec(-n));
  const Scalar h = support_along(sig.contact, down);
  return h * slope > support_extent(shape, down, to_body(at_rest, downhill), h);
}

/// What `settle_on_slope` decided for a body settling on a tilted ground plane.
enum class SlopeSettle {
  pose,     ///< it settles as on level ground, in its pose or the nearest that holds it
  tipping,  ///< it tips on: no pose, no sleep in this step
  held,     ///< no pose holds it, but what it stands on does: no pose, it may sleep where it is
};

/// A statistical body settling on a tilted ground plane of unit normal `n`: a pose that does not
/// hold it there (`pose_tips`) is no rest pose. Its pose (the chosen one, else the nearest) is
/// kept where it holds. Else, where the line of gravity passes downhill of the support set the
/// body stands on now, it tips over that set's downhill edge (`tip_over`) toward the next pose
/// downhill and takes none; where that set holds it, it settles into the nearest pose that
/// holds on this plane, or, with none, stays where it is (it may sleep there, as a body propped
/// out of its poses). Level ground (no pull along it) never gets here: its bits are unchanged.
template <int D>
SlopeSettle settle_on_slope(const WorldData<D>& w, Body<D>& b, const typename Space<D>::Vec& n)
{
  using Vec = typename Space<D>::Vec;
  const Shape<D>& shape = w.shapes[b.shape];
  const SignatureView<D>& sig = shape.signature;
  const WorldDef<D>& def = w.def;
  if (!shape.statistical || !def.rest_conditions || sig.rest.count == 0 || !sig.contact.present())
    return SlopeSettle::pose;
  const Scalar gn = def.gravity.dot(n);
  const Vec gt = def.gravity - n * gn;
  const Scalar pull = gt.norm();
  if (!(gn < 0) || !(pull > 0)) return SlopeSettle::pose;
  const Vec downhill = gt / pull;
  const Scalar slope = pull / -gn;
  const Scalar* bias = shape.rest_bias.data();
  const std::uint32_t pose =
      b.rest_pose != no_rest_pose ? b.rest_pose : nearest_rest_pose<D>(sig, b.orientation, n, bias);
  if (pose >= sig.rest.count || !pose_tips(shape, b.orientation, pose, n, downhill, slope)) return SlopeSettle::pose;
  // The support set it stands on now: the line of gravity meets the plane h tan(a) downhill of
  // the point under the centre; beyond the set's downhill extent e the body turns about the
  // set's edge, e downhill of that point.
  const Vec down = to_body(b.orientation, Vec(-n));
  const Scalar h = support_along(sig.contact, down);
  const Scalar e = support_extent(shape, down, to_body(b.orientation, downhill), h);
  // A tip slower than the sleep speed (the body near balance over the edge: on a curved part of
  // its hull it rolls until the line of gravity meets the point it stands on) counts as held.
  const Scalar g = def.gravity.norm();
  if (h * slope > e) {
    const Scalar spin = tip_over(shape, b, Vec(b.position - n * h + downhill * e), Vec(def.gravity / g), g,
                                 def.settle_speed);
    if (spin * shape.bounding_radius >= def.sleep_speed) {
      b.rest_pose = no_rest_pose;
      b.rest_blend = 0;
      return SlopeSettle::tipping;
    }
  }
  // Held where it stands: the nearest pose among those that hold (the score of
  // `nearest_rest_pose`); a new pose starts its radius blend afresh.
  std::uint32_t best = no_rest_pose;
  Scalar best_score = -std::numeric_limits<Scalar>::infinity();
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) {
    const Scalar score = (b.orientation * sig.rest.normal(i)).dot(n) + bias[i];
    if (score > best_score && !pose_tips(shape, b.orientation, i, n, downhill, slope)) {
      best_score = score;
      best = i;
    }
  }
  if (best != b.rest_pose) b.rest_blend = 0;
  b.rest_pose = std::uint8_t(best);
  return best == no_rest_pose ? SlopeSettle::held : SlopeSettle::pose;
}

/// True when the chosen rest pose's normal is within `rest_snap_cosine` of the ground's normal.
template <int D>
bool in_rest_pose(const WorldData<D>& w, const Body<D>& b, const typename Space<D>::Vec& ground)
{
  const SignatureView<D>& sig = w.shapes[b.shape].signature;
  const typename Space<D>::Vec u = b.orientation * sig.rest.normal(b.rest_pose);
  return u.dot(ground) >= w.def.rest_snap_cosine;
}

/// The last phase of a step: each awake body is moving, settling (touching and slower than
/// `settle_speed`) or, once still for `sleep_time`, asleep; settling bodies follow the resting
/// conditions.
template <int D>
void update_motion_states(WorldData<D>& w, Scalar dt, bool tilted_planes)
{
  using Vec = typename Space<D>::Vec;
  const WorldDef<D>& def = w.def;
  const Scalar settle2 = def.settle_speed * def.settle_speed;
  const Scalar sleep2 = def.sleep_speed * def.sleep_speed;
  const Scalar common = w.common_bound;
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
    // A body rolling on its hull down a slope (statsim/slope_contact.hpp) takes a pose only once
    // its contacts have all but stopped it there: the faces it rolls over are not poses it rests in.
    const bool rolling = tilted_planes && settling && b.on_ground && speed2 >= sleep2 && rolls_on(w, b, ground);
    const SlopeSettle slope = rolling                                   ? SlopeSettle::tipping
                              : tilted_planes && settling && b.on_ground ? settle_on_slope(w, b, ground)
                                                                         : SlopeSettle::pose;
    const bool tipping = slope == SlopeSettle::tipping;
    update_rest_pose(w, b, settling && b.on_ground && slope == SlopeSettle::pose, settling && !b.on_ground,
                     speed2 >= settle2, dt, ground);
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
    if (sleeps_from_anchor(w, b)) {
      const Scalar reach = def.sleep_speed * def.sleep_time;
      if (moved2 < reach * reach) lin2 = 0;
    }
    // It turns at ground contacts: one that keeps its pose while held up by other bodies cannot
    // reach it there, and may sleep where it is.
    // (On a slope `settle_on_slope` may have taken the pose away in this step.)
    const bool posed = !turning || b.rest_pose == no_rest_pose || !b.on_ground || in_rest_pose(w, b, ground);
    // On its hull (`hull_radius`) a body propped by others may stay still out of its pose; it
    // sleeps where it is after three sleep times.
    const bool wedged = !posed && hull_radius(w, b, ground) > b.radius;
    const bool still = !tipping && (lin2 > w2 ? lin2 : w2) < sleep2 && (posed || wedged);
    b.slow_time = still ? b.slow_time + dt : 0;
    if (still && b.slow_time >= (posed ? def.sleep_time : 3 * def.sleep_time)) {
      b.state = MotionState::asleep;
      clear_bit(w.awake, i);
      --w.awake_count;
      set_bit(w.flagged, i);  // its contact flags stay set until the next step clears them
      b.linear_velocity = Vec::Zero();
      b.angular_velocity = Space<D>::zero_spin();
      if (b.rest_pose != no_rest_pose && b.on_ground && posed) {
        // Fall asleep exactly in the pose, at its height: the last few degrees and the rest of
        // the radius blend are below what a slow body would show.
        // The centre stood `hull_radius` above the ground (the collision radius, or the hull's
        // support where that is more): it ends at the pose's height above it.
        const SignatureView<D>& sig = w.shapes[b.shape].signature;
        const Scalar above = hull_radius(w, b, ground);
        b.orientation = snap_to_rest(b.orientation, sig.rest.normal(b.rest_pose), ground);
        const Scalar h = sig.rest.heights[b.rest_pose];
        b.position += ground * (h - above);
        b.radius = h;
        b.rest_blend = 1;
      }
    }
  });
}

}  // namespace detail
}  // namespace statsim
