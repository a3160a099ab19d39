#pragma once
/// @file
/// The contact solver: the passes of a step over the contacts of bodies with planes and with
/// each other, one function per pass over two shared contact loops.
///
/// The impact pass resolves impacts with the bodies' responses: statistical bodies get the
/// statistical response (paper 3.3.2), plain spheres the particle response. Support passes only
/// take out what approach velocity is left (inelastic, with friction), so that a stack passes its
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
///
/// Overlaps between bodies are corrected once per step: in the shock pass, or in the impact pass
/// without one. Pushing overlaps apart in every pass, split between both bodies, squeezes bodies
/// sideways and upward out of a packed pile each step, and the lift comes back as kinetic
/// energy, so the pile never sleeps.

#include "statsim/detail/hull.hpp"
#include "statsim/detail/narrow_phase.hpp"
#include "statsim/detail/response.hpp"
#include "statsim/detail/slope.hpp"
#include "statsim/detail/slope_contact.hpp"
#include "statsim/detail/tipping.hpp"
#include "statsim/detail/workers.hpp"
#include "statsim/detail/world_data.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace statsim {
namespace detail {

/// Approach speed used as restitution threshold after the impact pass: nothing bounces there.
constexpr Scalar no_bounce = std::numeric_limits<Scalar>::infinity();
/// Passes after the impact pass count spheres within this fraction of their radius as touching:
/// the impact pass leaves resting contacts exactly touching, not overlapping.
constexpr Scalar contact_slop = Scalar(1e-3);

/// The response of one body alone against a plane with normal `n` (towards the body), with
/// its velocity taken relative to `other_velocity`: the statistical response for statistical
/// shapes (paper 3.3.2; for body-body contacts each body responds on its own, as in the
/// paper), the rest turn for bodies settling on the ground (paper 3.4), else (plain spheres,
/// and resting contacts of statistical bodies) the particle response against a static plane.
/// `tilted_plane`: the contact is with a plane that gravity pulls the body along. `sunk` (m):
/// how far the step had taken the body into the plane, for a plane contact of the impact pass.
template <int D, class FS>
void respond_alone(const WorldData<D>& w, StepContext<FS>& ctx, Body<D>& b, const typename Space<D>::Vec& n,
                   const typename Space<D>::Vec& other_velocity, bool ground_contact, bool tilted_plane = false,
                   Scalar gap = 0, Scalar sunk = 0)
{
  using Vec = typename Space<D>::Vec;
  const Shape<D>& shape = w.shapes[b.shape];
  const WorldDef<D>& def = w.def;
  Vec v = b.linear_velocity - other_velocity;
  const Scalar threshold = restitution_threshold(w, b, n, ctx.dt);
  const bool resting = -v.dot(n) <= threshold;
  // On a slope a body with no rest pose meets the plane with its hull, as a rigid body does, its
  // impacts included (statsim/detail/slope_contact.hpp): how far it tumbles and rolls downhill follows
  // from the strikes of its faces one after the other, each set by the last, which independent
  // samples of the tables' single-impact responses do not reproduce. A body that rolled through
  // the step in substeps (`roll_on_slopes`) has had its slope contacts there. On level ground
  // the same holds for a body that was on the ground as the step began, or lands as slowly as a
  // hop's landing (`ground_hull`, `slow_landing`): its tumbles and hops after
  // the first impact are its hull's.
  if ((tilted_plane || ground_contact) && rolls_on<FS>(w, b, n)) {
    if (!bit_set(w.rolled, std::uint32_t(&b - w.bodies)))
      slope_hull_response(shape, b, n, def.gravity, gap, ctx.dt, threshold);
    return;
  }
  if (FS::slopes && shape.statistical && tilted_plane && resting && !(ground_contact && b.rest_pose != no_rest_pose)) {
    // Rolling resistance taken off the velocity of a point without lever arm brakes its sliding
    // as extra friction: a slide down the plane at g (sin a - (mu + c) cos a) instead of
    // g (sin a - mu cos a), and sliding only from tan a > mu + c. On a tilted plane it slows the
    // spin alone, and the velocity only where it stops it (what is left of the slip once
    // friction held the body); the normal impulse is -v.n, as nothing bounces at a resting
    // contact.
    Material slide = shape.material;
    slide.rolling_resistance = 0;
    const Scalar jn = -v.dot(n);
    if (!particle_plane_response<D>(v, b.angular_velocity, Scalar(0), n, slide, def.restitution_threshold)) return;
    const Scalar c = shape.material.rolling_resistance;
    if (c > 0) {
      const Vec vt = v - n * v.dot(n);
      const Scalar speed = vt.norm();
      const Scalar cut = c * jn;
      if (speed > cut) {
        b.angular_velocity = b.angular_velocity * (1 - cut / speed);
      } else {
        v -= vt;
        b.angular_velocity = Space<D>::zero_spin();
      }
    }
  } else if (!shape.statistical || (resting && !(ground_contact && b.rest_pose != no_rest_pose))) {
    particle_plane_response<D>(v, b.angular_velocity, contact_radius(w, b), n, shape.material,
                               def.restitution_threshold);
  } else if (ground_contact && b.rest_pose != no_rest_pose) {
    if (!(v.dot(n) < 0)) return;
    // A rigid body tipping onto a face turns about the edge or corner it stands on, not about
    // its centre, and its centre moves along the ground as it falls: from above the edge to
    // above the face's middle, up to half its width. So the turn of a body with no other body
    // near (`WorldData::paired`) pivots about p, the hull's support point along -n (the middle
    // of the edge or face it stands on): its centre's velocity along the plane is that of the
    // point p plus (w x (c - p))_t. Friction acts on p's velocity, the slip, found with the
    // spin the body came with; the centre then takes the new turn's part. A body turning
    // without slip moves exactly with its turn, and one that has reached its pose (w = 0)
    // slides to a stop as before. Near other bodies the turn stays about the centre: a pivot
    // pushes the neighbours it turns into, and the bottom layers of a bin pack far too densely
    // (tools/fidelity/LOG.md). It pivots only while its pose is the one it leans towards, the
    // nearest by angle: a pose the rest conditions chose against that (a basin's bias,
    // `rest_basin_biases`, which also moves a body placed exactly in a pose that is not its
    // basin's) is the statistics' and has no tip to copy, and the turn stays about the centre.
    // A table without a support map turns about the centre.
    const ContactView<D>& hull = shape.signature.contact;
    const bool pivots = hull.present() && !bit_set(w.paired, std::uint32_t(&b - w.bodies)) &&
                        nearest_rest_pose<D>(shape.signature, b.orientation, n) == b.rest_pose;
    Vec arm = Vec::Zero();
    const auto along_plane = [&n](const Vec& x) { return Vec(x - n * x.dot(n)); };
    if (pivots) {
      arm = -to_world(b.orientation, support_point<D>(hull, to_body(b.orientation, Vec(-n))));
      v -= along_plane(cross(b.angular_velocity, arm));
    }
    v = point_particle_velocity<D>(v, n, shape.material, def.restitution_threshold);
    const auto offset = rest_turn(b.orientation, shape.signature.rest.normal(b.rest_pose), n, Scalar(1));
    if (b.slow_time < 0) {
      // Its settling time runs (`SettleView`, a negative `slow_time`): it turns into its pose and
      // rocks about it at the amplitude at which its farthest point swings at the sleep speed.
      const Scalar omega = 1 / def.rest_turn_time;
      b.angular_velocity = settle_rock(offset, n, -b.slow_time, omega, def.sleep_speed / (omega * shape.bounding_radius),
                                       def.rest_turn_time);
    } else {
      b.angular_velocity = offset / def.rest_turn_time;
    }
    // A small turn (paper 3.4): its farthest point moves at most at the settle speed, so a
    // slow body is not spun up (sin(angle) / rest_turn_time alone reaches 10 rad/s).
    const Scalar cap = def.settle_speed / shape.bounding_radius;
    const Scalar spin2 = squared_norm(b.angular_velocity);
    if (spin2 > cap * cap) b.angular_velocity = b.angular_velocity * (cap / std::sqrt(spin2));
    if (pivots) v += along_plane(cross(b.angular_velocity, arm));
  } else {
    Pcg32 rng = rng_of(w, b);
    // Against a plane, the part of gravity pressing the body onto it decides how often the
    // body stays there (the signature's landing data); body-body contacts take none.
    const Scalar gravity = ground_contact ? Scalar(-def.gravity.dot(n)) : Scalar(0);
    // The table is looked up at the impact, the velocity the sphere met the plane with: it
    // crossed it about `sunk` / |v_n| before the step's end (at most the step), and gravity has
    // added g that long since. At 60 Hz that is up to g dt, 0.16 m/s, and g dt / 2 on average,
    // by which every response would be scaled up.
    if (gravity > 0 && sunk > 0) {
      const Scalar vn = v.dot(n);
      if (vn < 0) {
        const Scalar since = sunk < -vn * ctx.dt ? sunk / -vn : ctx.dt;
        v -= def.gravity * since;
      }
    }
    const ResponseOutcome o =
        statistical_response<D>(shape.signature, b.orientation, n, v, b.angular_velocity, rng, gravity);
    b.rng_state = rng.state();
    ctx.energy_clamps += o.energy_clamped;
    ctx.statistical_responses += o.applied;
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
template <int D, class FS>
void respond_pair(const WorldData<D>& w, StepContext<FS>& ctx, Body<D>& a, Body<D>& b, const typename Space<D>::Vec& n,
                  Scalar ima, Scalar imb)
{
  using Vec = typename Space<D>::Vec;
  const Vec va = a.linear_velocity, vb = b.linear_velocity;
  if (ima > 0) respond_alone(w, ctx, a, -n, vb, false);
  if (imb > 0) respond_alone(w, ctx, b, n, va, false);
  if (w.def.pair_response != PairResponse::momentum) return;
  // Change of (vb - va) as each body saw it; a static side saw none, so the other counts alone.
  const Vec from_b = (b.linear_velocity - va) - (vb - va);
  const Vec from_a = (vb - a.linear_velocity) - (vb - va);
  const Vec change = ima > 0 && imb > 0 ? Vec((from_a + from_b) * Scalar(0.5)) : (ima > 0 ? from_a : from_b);
  const Scalar ims = ima + imb;
  a.linear_velocity = va - change * (ima / ims);
  b.linear_velocity = vb + change * (imb / ims);
}

/// The particle response of two bodies (`particle_point_response` when neither has a lever
/// arm, the same rule without the terms that vanish). True when an impulse was applied.
template <int D>
bool particle_pair(const WorldData<D>& w, Body<D>& a, Body<D>& b, const typename Space<D>::Vec& n, Scalar ima,
                   Scalar imb, Scalar threshold)
{
  const Scalar ra = contact_radius(w, a), rb = contact_radius(w, b);
  // Bodies of one shape need no mixed material: sqrt(f * f) == f in IEEE arithmetic.
  const Material m = a.shape == b.shape ? w.shapes[a.shape].material
                                        : mix(w.shapes[a.shape].material, w.shapes[b.shape].material);
  const ContactSide<D> sa{a.linear_velocity, a.angular_velocity, ima, ra};
  const ContactSide<D> sb{b.linear_velocity, b.angular_velocity, imb, rb};
  return ra == 0 && rb == 0 ? particle_point_response<D>(sa, sb, n, m, threshold)
                            : particle_response<D>(sa, sb, n, m, threshold);
}

/// Inverse masses of a touching pair: 0 for a sleeper. In the bottom-up passes (shock and
/// position) a contact that mostly supports (normal within 60 degrees of up) also freezes its
/// lower body; the normal points from a to b, so n_up > 0 means a is below. Returns their sum.
template <int D>
Scalar inverse_masses(const Body<D>& a, const Body<D>& b, const typename Space<D>::Vec& n, bool bottom_up,
                      Scalar& ima, Scalar& imb)
{
  const int up = Space<D>::up_axis;
  ima = a.state == MotionState::asleep ? 0 : a.inv_mass;
  imb = b.state == MotionState::asleep ? 0 : b.inv_mass;
  if (bottom_up && n[up] >= Scalar(0.5) && imb > 0) ima = 0;
  if (bottom_up && n[up] <= Scalar(-0.5) && ima > 0) imb = 0;
  return ima + imb;
}

/// Pushes two bodies apart by the part of their overlap beyond `WorldDef::allowed_overlap` (of
/// `reach`, the separation at which they touch),
/// times `overlap_correction`, split in proportion to inverse mass (in the bottom-up passes the
/// lower body's is 0), so a sleeper does not move.
template <int D, class FS>
void correct_overlap(const WorldData<D>& w, StepContext<FS>& ctx, Body<D>& a, Body<D>& b, const Contact<D>& c,
                     Scalar slop, Scalar reach, Scalar ima, Scalar imb, Scalar ims)
{
  const Scalar depth = (c.depth - slop - w.def.allowed_overlap * reach) * w.def.overlap_correction;
  if (!(depth > 0)) return;
  a.position -= c.normal * (depth * ima / ims);
  b.position += c.normal * (depth * imb / ims);
  ++ctx.moves;
}

/// The shared loop over plane contacts: for every awake body and plane that touch (spheres grown
/// by `contact_slop` when `grown`), moves the body out of the plane, marks it touching (and on
/// the ground for a near-horizontal plane), then calls `respond(body, contact, ground, tilted,
/// moved)` (tilted: gravity pulls the body along the plane; moved: how far, m, the body was just
/// moved out of it); on a tilted plane it then takes the
/// downhill move back that the response's friction cancelled.
/// Returns the number of contacts.
template <int D, class FS, class Respond>
std::uint32_t plane_contacts(WorldData<D>& w, StepContext<FS>& ctx, bool grown, Respond&& respond)
{
  using Vec = typename Space<D>::Vec;
  const Vec& g = w.def.gravity;
  std::uint32_t contacts = 0;
  for_each_set(w.awake, w.body_count, [&](std::uint32_t i) {
    Body<D>& b = w.bodies[i];
    for (std::uint32_t p = 0; p < w.plane_count; ++p) {
      Contact<D> c;
      // Passes after the impact pass also see a body that the last pass left exactly touching. A
      // body that meets a slope with its hull is seen within `slope_reach` of its bounding radius
      // (a speculative contact: `slope_hull_response` lets it close the gap in the step and no
      // more): turning about a corner, the hull's support falls away from the plane by about
      // (1 - cos(w dt)) times the support in a step, and the corner would lose the plane.
      const bool hull = hull_planes<FS>(w) && rolls_on<FS>(w, b, w.planes[p].normal);
      const Scalar slop = hull ? w.shapes[b.shape].bounding_radius * slope_reach
                               : (grown ? b.radius * contact_slop : Scalar(0));
      if (!sphere_plane_contact<D>(b.position, plane_radius<FS>(w, b, w.planes[p]) + slop, w.planes[p], c)) continue;
      const Scalar moved = c.depth > slop ? c.depth - slop : Scalar(0);
      if (moved > 0) {
        b.position += c.normal * moved;
        ++ctx.moves;
        ++ctx.changes;
      }
      // From here on the depth is that of the body itself: 0 once moved out, or minus the gap.
      c.depth = c.depth > slop ? Scalar(0) : c.depth - slop;
      b.touching = true;
      const bool ground = c.normal[Space<D>::up_axis] >= w.def.ground_cosine;
      b.on_ground = b.on_ground || ground;
      ++contacts;
      // The step has already moved the body by its velocity with this step's gravity in it. On a
      // tilted plane the friction that holds a resting body takes gravity's pull along the plane,
      // g_t dt, out of its velocity but not out of that move, so it would creep downhill by
      // g_t dt^2 every step however firmly it is held (at g sin(a) dt, metres per second). The
      // same part is taken out of the move: what the response removed of the downhill velocity,
      // at most g_t dt, times dt. Planes that carry no weight (n.g >= 0, walls) and level ones
      // (g_t = 0 exactly) are left alone.
      Scalar gn;
      if (!FS::slopes || !ctx.tilted_planes || !is_tilted_plane(g, c.normal, gn)) {
        respond(b, c, ground, false, moved);
        continue;
      }
      const Vec gt = g - c.normal * gn;
      const Scalar pull = gt.norm();
      const Vec downhill = gt / pull;
      const Scalar before = b.linear_velocity.dot(downhill);
      respond(b, c, ground, true, moved);
      const Scalar taken = before - b.linear_velocity.dot(downhill);
      const Scalar held = pull * ctx.dt;
      if (taken > 0) b.position -= downhill * ((taken < held ? taken : held) * ctx.dt);
    }
  });
  return contacts;
}

/// The shared loop over body-body contacts among the first `count` candidate pairs (grown by
/// `contact_slop` of their reach when `grown`; the impact pass, not grown, finds each pair's
/// hull contact afresh unless `search_witnesses_first` has). For each touching pair it calls
/// `resolve(a, b, contact, slop, reach)`,
/// which returns false when neither body can move, and else marks both touching. With
/// `compact`, touching pairs move to the front of the buffer, in their order. With `keep`, each
/// pair's face contact is kept for the later passes (`WorldData::pair_hulls`, at the pair's new
/// place), which read it. Returns the number of touching pairs.
template <class FS, int D, class Resolve>
std::uint32_t pair_contacts(WorldData<D>& w, std::uint32_t count, bool grown, bool compact, bool keep,
                            Resolve&& resolve, bool fresh = true)
{
  std::uint32_t touching = 0;
  for (std::uint32_t k = 0; k < count; ++k) {
    Body<D>& a = w.bodies[w.pairs[k].a];
    Body<D>& b = w.bodies[w.pairs[k].b];
    Contact<D> c;
    Scalar reach, slop;
    // A compacted pair's entry goes where the pair will go; a pair that does not touch leaves
    // that place to the next.
    const std::uint32_t slot = compact ? touching : k;
    PairHull<D>* kept = STATSIM_HULL_CACHE && slot < w.max_pair_hulls ? &w.pair_hulls[slot] : nullptr;
    if (!body_contact<FS>(w, a, b, w.pairs[k], fresh && !grown, grown ? contact_slop : Scalar(0), c, reach, slop, kept, keep))
      continue;
    if (compact) std::swap(w.pairs[touching], w.pairs[k]);
    ++touching;
    if (!resolve(a, b, c, slop, reach)) continue;
    a.touching = true;
    b.touching = true;
  }
  return touching;
}

/// Clears the contact flags of every body: the passes of this step set them again. Only awake
/// bodies, bodies of last step's touching pairs and bodies that fell asleep in it can have them
/// set. Runs before the broad phase replaces the pairs.
template <int D>
void forget_contacts(WorldData<D>& w)
{
  const auto forget = [&w](std::uint32_t i) {
    w.bodies[i].touching = false;
    w.bodies[i].on_ground = false;
  };
  for_each_set(w.awake, w.body_count, forget);
  for_each_set(w.flagged, w.body_count, forget);
  for (std::uint32_t k = 0; k < w.touching_pairs; ++k) {
    forget(w.pairs[k].a);
    forget(w.pairs[k].b);
  }
  for (std::uint32_t k = 0; k < bit_words(w.body_count); ++k) w.flagged[k] = 0;
}

/// Marks in `WorldData::paired` the bodies of this step's candidate pairs (the broad phase's,
/// before the impact pass compacts them).
template <int D>
void mark_paired(WorldData<D>& w)
{
  for (std::uint32_t k = 0; k < bit_words(w.body_count); ++k) w.paired[k] = 0;
  for (std::uint32_t k = 0; k < w.pair_count; ++k) {
    set_bit(w.paired, w.pairs[k].a);
    set_bit(w.paired, w.pairs[k].b);
  }
}

/// The plane contacts of a support pass (and of the shock pass): inelastic particle responses.
template <int D, class FS>
void support_planes(WorldData<D>& w, StepContext<FS>& ctx)
{
  // On level ground a body that rolled on its hull in the step's substeps (`ground_hull`) meets
  // it here as every other resting body does, at its sphere: what approach the substeps left at
  // the step's end goes, and friction there brakes its slide and spin.
  plane_contacts(w, ctx, true, [&](Body<D>& b, const Contact<D>& c, bool, bool tilted, Scalar) {
    if (tilted && rolls_on<FS>(w, b, c.normal)) {
      if (!bit_set(w.rolled, std::uint32_t(&b - w.bodies)) &&
          slope_hull_response(w.shapes[b.shape], b, c.normal, w.def.gravity, -c.depth, ctx.dt, no_bounce))
        ++ctx.changes;
      return;
    }
    if (particle_plane_response<D>(b.linear_velocity, b.angular_velocity, contact_radius(w, b), c.normal,
                                   w.shapes[b.shape].material, no_bounce))
      ++ctx.changes;
  });
}

/// The impact pass: planes, then pairs, each with the bodies' own response; awake bodies that hit
/// a sleeper faster than `wake_speed` wake it. Leaves the touching pairs at the front of the pair
/// buffer and their number in `ctx.touching`. Returns the number of contacts.
template <int D, class FS>
std::uint32_t impact_pass(WorldData<D>& w, StepContext<FS>& ctx)
{
  using Vec = typename Space<D>::Vec;
  const WorldDef<D>& def = w.def;
  const std::uint32_t plane_count = plane_contacts(w, ctx, false, [&](Body<D>& b, const Contact<D>& c, bool ground,
                                                                      bool tilted, Scalar moved) {
    if (FS::statistical && w.shapes[b.shape].statistical)
      respond_alone(w, ctx, b, c.normal, Vec::Zero(), ground, tilted, -c.depth, moved);
    else if (particle_plane_response<D>(b.linear_velocity, b.angular_velocity, contact_radius(w, b), c.normal,
                                        w.shapes[b.shape].material, def.restitution_threshold))
      ++ctx.changes;
  });
  const bool searched = search_witnesses_first<FS>(w);
  ctx.touching = pair_contacts<FS>(w, w.pair_count, false, true, true, [&](Body<D>& a, Body<D>& b, const Contact<D>& c,
                                                                       Scalar slop, Scalar reach) {
    const Vec& n = c.normal;
    const bool a_asleep = a.state == MotionState::asleep;
    const bool b_asleep = b.state == MotionState::asleep;
    if (a_asleep || b_asleep) {
      // An awake body hitting a sleeper fast enough, or pressed deep into its hull, wakes it;
      // otherwise the sleeper is static.
      const Scalar approach = (a.linear_velocity - b.linear_velocity).dot(n);
      // (With `WorldDef::sleep_islands` a slower awake body joins the sleeper to its island at
      // the end of the step: `join_islands`.)
      if (approach > def.wake_speed || wakes_by_overlap<FS>(w, a, b, c.depth, reach)) {
        if (a_asleep) wake(w, a);
        if (b_asleep) wake(w, b);
      }
    }
    Scalar ima, imb;
    const Scalar ims = inverse_masses(a, b, n, false, ima, imb);
    if (ims <= 0) return false;
    if (FS::statistical && (w.shapes[a.shape].statistical || w.shapes[b.shape].statistical)) respond_pair(w, ctx, a, b, n, ima, imb);
    else if (particle_pair(w, a, b, n, ima, imb, def.restitution_threshold)) ++ctx.changes;
    if (!def.shock_propagation) correct_overlap(w, ctx, a, b, c, slop, reach, ima, imb, ims);
    return true;
  }, !searched);
  return plane_count + ctx.touching;
}

/// A support pass over the touching pairs, then the planes: inelastic particle responses, planes
/// last, since a pair push can drive a body into the ground and the ground has the last word on
/// position and velocity. Returns the number of impulses and position corrections.
template <int D, class FS>
std::uint32_t support_pass(WorldData<D>& w, StepContext<FS>& ctx)
{
  ctx.changes = 0;
  pair_contacts<FS>(w, ctx.touching, true, false, false, [&](Body<D>& a, Body<D>& b, const Contact<D>& c, Scalar, Scalar) {
    Scalar ima, imb;
    if (inverse_masses(a, b, c.normal, false, ima, imb) <= 0) return false;
    if (particle_pair(w, a, b, c.normal, ima, imb, no_bounce)) ++ctx.changes;
    return true;
  });
  support_planes(w, ctx);
  return ctx.changes;
}

/// Orders the first `count` pairs by the height of their lower centre, ties by body index, so
/// the order is a total one and the same on every platform.
template <int D>
void sort_bottom_up(WorldData<D>& w, std::uint32_t count)
{
  constexpr int up = Space<D>::up_axis;
  const Body<D>* bodies = w.bodies;
  std::sort(w.pairs, w.pairs + count, [bodies](const Pair& x, const Pair& y) {
    const Scalar xa = bodies[x.a].position[up], xb = bodies[x.b].position[up];
    const Scalar ya = bodies[y.a].position[up], yb = bodies[y.b].position[up];
    const Scalar kx = xa < xb ? xa : xb, ky = ya < yb ? ya : yb;
    if (kx != ky) return kx < ky;
    if (x.a != y.a) return x.a < y.a;
    return x.b < y.b;
  });
}

/// The shock pass: the touching pairs from the bottom up, lower bodies frozen, inelastic
/// responses and the step's overlap correction; then the planes as in a support pass. Returns
/// the number of position corrections.
template <int D, class FS>
std::uint32_t shock_pass(WorldData<D>& w, StepContext<FS>& ctx)
{
  sort_bottom_up(w, ctx.touching);
  ctx.moves = 0;
  typename Space<D>::Vec gravity_unit = Space<D>::Vec::Zero();
  Scalar gravity = 0;
  bool tipping = false;
  if constexpr (FS::hull_contacts) tipping = tip_gravity<FS>(w, gravity_unit, gravity);
  bool overhangs = false;
  if (tipping)
    for (std::uint32_t k = 0; k < ctx.touching; ++k) {
      w.bodies[w.pairs[k].a].supports = 0;
      w.bodies[w.pairs[k].b].supports = 0;
    }
  // The sort moved the pairs away from their kept contacts: the pass keeps them afresh.
  pair_contacts<FS>(w, ctx.touching, true, false, true, [&](Body<D>& a, Body<D>& b, const Contact<D>& c, Scalar slop,
                                                        Scalar reach) {
    // Marked before the correction moves the pair: where the step's passes left it.
    if constexpr (FS::hull_contacts) {
      if (tipping && mark_supports<FS>(w, a, b, c.normal, gravity_unit)) overhangs = true;
    }
    Scalar ima, imb;
    const Scalar ims = inverse_masses(a, b, c.normal, true, ima, imb);
    if (ims <= 0) return false;
    if (particle_pair(w, a, b, c.normal, ima, imb, no_bounce)) ++ctx.changes;
    correct_overlap(w, ctx, a, b, c, slop, reach, ima, imb, ims);
    return true;
  });
  support_planes(w, ctx);
  if constexpr (FS::hull_contacts) {
    if (overhangs) tip_unsupported<FS>(w, ctx.touching, gravity_unit, gravity, contact_slop);
  }
  return ctx.moves;
}

/// A position pass: the shock pass's overlap correction alone, in its order and with its frozen
/// bodies, then bodies moved out of planes; velocities are left as the passes before settled
/// them. Returns the number of position corrections.
template <int D, class FS>
std::uint32_t position_pass(WorldData<D>& w, StepContext<FS>& ctx)
{
  ctx.moves = 0;
  pair_contacts<FS>(w, ctx.touching, true, false, false, [&](Body<D>& a, Body<D>& b, const Contact<D>& c, Scalar slop, Scalar reach) {
    Scalar ima, imb;
    const Scalar ims = inverse_masses(a, b, c.normal, true, ima, imb);
    if (ims <= 0) return false;
    correct_overlap(w, ctx, a, b, c, slop, reach, ima, imb, ims);
    return true;
  });
  plane_contacts(w, ctx, true, [](Body<D>&, const Contact<D>&, bool, bool, Scalar) {});
  return ctx.moves;
}

}  // namespace detail
}  // namespace statsim
