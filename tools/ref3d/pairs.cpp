#include "ref3d/pairs.hpp"

#include "common/ks_distance.hpp"
#include "common/pi.hpp"

#include "bullet/bullet.hpp"
#include "ref3d/bullet_state.hpp"
#include "bullet/drop_world.hpp"
#include "common/format.hpp"
#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "common/support_map.hpp"
#include "ref3d/reference.hpp"
#include "ref3d/sampling.hpp"
#include "scenes/scenes.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace statsim::tools::ref3d {

namespace {

std::vector<bullet::Shapes::Box> shape_boxes(const ShapeModel& m)
{
  std::vector<bullet::Shapes::Box> boxes;
  for (const BodyBox& b : m.boxes) boxes.push_back({b.centre, b.rotation, b.half_extents});
  return boxes;
}

// The shape's Bullet geometries for pair queries: its hull without margin (GJK distance) and its
// true geometry (box, box compound, GImpact mesh) with `margin`.
struct PairGeometry {
  bullet::Shapes shapes;
  btConvexShape* hull = nullptr;
  btCollisionShape* full = nullptr;
  bool convex = false;  ///< the true geometry is its hull (a box)
  PairGeometry(const ShapeModel& m, double margin)
  {
    hull = static_cast<btConvexShape*>(shapes.hull(m.hull, 0.0));
    convex = m.kind == ShapeKind::box;
    if (m.kind == ShapeKind::mesh) {
      std::vector<int> idx;
      for (const auto& t : m.body_mesh.triangles) idx.insert(idx.end(), {t[0], t[1], t[2]});
      full = shapes.mesh(m.body_mesh.vertices, idx, margin);
    } else {
      full = shapes.boxes(shape_boxes(m), margin);
    }
  }
};

// Signed distance of two convex shapes (GJK; negative: they overlap, by EPA's depth).
double convex_distance(const btConvexShape* a, const btTransform& ta, const btConvexShape* b, const btTransform& tb)
{
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  btGjkPairDetector gjk(a, b, &simplex, &epa);
  btGjkPairDetector::ClosestPointInput in;
  in.m_transformA = ta;
  in.m_transformB = tb;
  btPointCollector out;
  gjk.getClosestPoints(in, out, nullptr);
  return out.m_hasResult ? double(out.m_distance) : -1.0;
}

// Whether two bodies of the true geometry touch (a manifold point at distance <= 0), by Bullet's
// narrow phase on a collision world of the two alone; manifolds are cleared before each query,
// so a query depends only on the two poses.
class TouchQuery {
public:
  explicit TouchQuery(btCollisionShape* shape)
      : dispatcher_(&config_), world_(&dispatcher_, &broadphase_, &config_)
  {
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher_);
    for (btCollisionObject* o : {&a_, &b_}) {
      o->setCollisionShape(shape);
      o->setCollisionFlags(0);
      world_.addCollisionObject(o);
    }
  }
  ~TouchQuery()
  {
    world_.removeCollisionObject(&b_);
    world_.removeCollisionObject(&a_);
  }
  bool touching(const btTransform& ta, const btTransform& tb)
  {
    a_.setWorldTransform(ta);
    b_.setWorldTransform(tb);
    for (int i = 0; i < dispatcher_.getNumManifolds(); ++i) dispatcher_.getManifoldByIndexInternal(i)->clearManifold();
    world_.performDiscreteCollisionDetection();
    for (int i = 0; i < dispatcher_.getNumManifolds(); ++i) {
      const btPersistentManifold* m = dispatcher_.getManifoldByIndexInternal(i);
      for (int k = 0; k < m->getNumContacts(); ++k)
        if (m->getContactPoint(k).getDistance() <= 0) return true;
    }
    return false;
  }

private:
  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btCollisionWorld world_;
  btCollisionObject a_, b_;
};

struct PairStart {
  RigidState a, b;
  double rate = 0.0;  ///< bound of the rate at which any two points of the bodies approach, m/s
};

// Body a at the origin, b 2 L away along +x coming at speed u; both at uniform random
// orientations, spinning at s u / L about uniform random axes.
PairStart pair_start(const ShapeModel& m, double spin_ratio, double u, std::uint64_t seed, std::uint64_t index)
{
  TrialRng rng(seed, kPairStream, index);
  const double L = m.bounding_radius;
  PairStart p;
  p.a.orientation = rng.rotation();
  p.a.spin = rng.direction() * (spin_ratio * u / L);
  p.b.orientation = rng.rotation();
  p.b.spin = rng.direction() * (spin_ratio * u / L);
  p.b.position = Eigen::Vector3d(2 * L * (1 + 1e-9), 0, 0);
  p.b.velocity = Eigen::Vector3d(-u, 0, 0);
  const FreeFlight flight(m.unit_inertia);
  p.rate = u + (flight.spin_bound(p.a) + flight.spin_bound(p.b)) * L;
  return p;
}

// The pair's states at time t after `s` (each body in its own torque-free flight).
std::pair<RigidState, RigidState> advance(const FreeFlight& f, const std::pair<RigidState, RigidState>& s, double t)
{
  return {f.advance(s.first, t), f.advance(s.second, t)};
}

double centre_distance(const std::pair<RigidState, RigidState>& s)
{
  return (s.second.position - s.first.position).norm();
}

// Both phases of a pair flight with given geometry (see the header); `out`: the states at contact.
double pair_flight_states(const ShapeModel& m, PairGeometry& g, TouchQuery* touch, const PairStart& start,
                          bool hull_only, double* hull_distance, std::pair<RigidState, RigidState>& out)
{
  const auto done = [&](const std::pair<RigidState, RigidState>& x) {
    out = x;
    return centre_distance(x);
  };
  const double L = m.bounding_radius;
  const FreeFlight flight(m.unit_inertia);
  std::pair<RigidState, RigidState> s{start.a, start.b};
  // Hulls: conservative advancement (no two points approach faster than `rate`).
  const double tol = 1e-7 * L;
  for (int it = 0; it < 100000; ++it) {
    const double d = convex_distance(g.hull, to_bt(s.first), g.hull, to_bt(s.second));
    if (d <= tol) break;
    s = advance(flight, s, d / start.rate);
    if (s.second.position.x() < s.first.position.x()) break;  // centres passed: cannot happen for hulls
  }
  if (hull_distance) *hull_distance = centre_distance(s);
  if (hull_only || g.convex || !touch) return done(s);
  // True geometry: steps of at most 0.005 L of relative motion, then bisection.
  const double step = 0.005 * L / start.rate;
  if (touch->touching(to_bt(s.first), to_bt(s.second))) return done(s);
  for (int it = 0; it < 400; ++it) {
    const auto next = advance(flight, s, step);
    if (touch->touching(to_bt(next.first), to_bt(next.second))) {
      double lo = 0, hi = step;
      for (int k = 0; k < 24; ++k) {
        const double mid = 0.5 * (lo + hi);
        const auto x = advance(flight, s, mid);
        if (touch->touching(to_bt(x.first), to_bt(x.second))) hi = mid;
        else lo = mid;
      }
      return done(advance(flight, s, hi));
    }
    s = next;
    if (centre_distance(s) < 0.02 * L) break;
  }
  return done(s);
}

double pair_flight(const ShapeModel& m, PairGeometry& g, TouchQuery* touch, const PairStart& start, bool hull_only,
                   double* hull_distance, std::pair<RigidState, RigidState>* at_contact = nullptr)
{
  std::pair<RigidState, RigidState> contact;
  const double d = pair_flight_states(m, g, touch, start, hull_only, hull_distance, contact);
  if (at_contact) *at_contact = contact;
  return d;
}

double quantile(const std::vector<double>& sorted, double q)
{
  if (sorted.empty()) return 0.0;
  const double x = q * static_cast<double>(sorted.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(x));
  const std::size_t j = std::min(sorted.size() - 1, i + 1);
  return sorted[i] + (x - static_cast<double>(i)) * (sorted[j] - sorted[i]);
}

// The outcome of one pair impact: |v_b+ - v_a+| / u and |w_b+| L / u (u the approach speed).
struct PairOutcome {
  double speed = 0.0, spin = 0.0;
};

// Bullet: the two bodies of the true geometry from their states at first contact, b moved a
// hair towards a so that the first step has the contact, with the reference's settings (those
// of `statsim gather`'s impacts: ref3d/reference.hpp) and each body's material the square root
// of the pair's (Bullet multiplies them), until they have been apart for 50 steps.
PairOutcome bullet_pair_impact(const ShapeModel& m, btCollisionShape* shape, const ReferenceSettings& rs,
                               std::pair<RigidState, RigidState> s, double u)
{
  const double L = m.bounding_radius;
  const Eigen::Vector3d e = (s.second.position - s.first.position).normalized();
  s.second.position -= 1e-6 * L * e;
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, 0, 0));
  apply_solver_settings(world.getSolverInfo(), rs);
  std::unique_ptr<btRigidBody> body[2];
  for (int k = 0; k < 2; ++k) {
    const RigidState& st = k ? s.second : s.first;
    btRigidBody::btRigidBodyConstructionInfo bi(m.mass.mass, nullptr, shape, bullet::to_bt(m.mass.principal_moments));
    bi.m_startWorldTransform = to_bt(st);
    bi.m_restitution = std::sqrt(rs.restitution);
    bi.m_friction = std::sqrt(rs.friction);
    bi.m_linearDamping = 0.0;
    bi.m_angularDamping = 0.0;
    body[k] = std::make_unique<btRigidBody>(bi);
    body[k]->setFlags(BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY);
    body[k]->setActivationState(DISABLE_DEACTIVATION);
    if (!rs.speculative_contacts) body[k]->setContactProcessingThreshold(0.0);
    body[k]->setLinearVelocity(bullet::to_bt(st.velocity));
    body[k]->setAngularVelocity(bullet::to_bt(st.spin));
    world.addRigidBody(body[k].get());
  }
  const int max_steps = static_cast<int>(std::ceil(2.0 / rs.dt));
  int apart = 0;
  for (int step = 0; step < max_steps && apart < 50; ++step) {
    world.stepSimulation(rs.dt, 0, rs.dt);
    bool touching = false;
    for (int i = 0; i < dispatcher.getNumManifolds(); ++i) {
      const btPersistentManifold* mf = dispatcher.getManifoldByIndexInternal(i);
      for (int k = 0; k < mf->getNumContacts(); ++k) touching = touching || mf->getContactPoint(k).getDistance() <= 0;
    }
    apart = touching ? 0 : apart + 1;
  }
  PairOutcome o;
  const Eigen::Vector3d va = bullet::to_eigen(body[0]->getLinearVelocity());
  const Eigen::Vector3d vb = bullet::to_eigen(body[1]->getLinearVelocity());
  o.speed = (vb - va).norm() / u;
  o.spin = bullet::to_eigen(body[1]->getAngularVelocity()).norm() * L / u;
  world.removeRigidBody(body[1].get());
  world.removeRigidBody(body[0].get());
  return o;
}

// The runtime: a World3 without gravity or planes holding the two bodies at the same
// orientations, velocities and spins, their centres along the same line at 0.999 of the sum of
// their collision radii, stepped at 1/240 s until they separate (at most 0.25 s).
PairOutcome runtime_pair_impact(const SignatureView<3>& sig, double L, const std::pair<RigidState, RigidState>& s,
                                double u, std::uint64_t seed)
{
  WorldDef3 def;
  def.gravity = Vector3::Zero();
  def.seed = seed;
  auto w = std::make_unique<World3<2>>(def);
  const ShapeId shape = w->add_shape(sig).id;
  const Eigen::Vector3d e = (s.second.position - s.first.position).normalized();
  Scalar radius[2];
  BodyDef3 def_[2];
  for (int k = 0; k < 2; ++k) {
    const RigidState& st = k ? s.second : s.first;
    BodyDef3& b = def_[k];
    b.shape = shape;
    b.mass = 1;  // kg, both alike as before bodies took the table's mass (the same bits as then)
    b.orientation = st.orientation.cast<Scalar>();
    b.linear_velocity = st.velocity.cast<Scalar>();
    b.angular_velocity = st.spin.cast<Scalar>();
    radius[k] = collision_radius<3>(sig, b.linear_velocity, b.angular_velocity);
  }
  def_[1].position = (e * (0.999 * double(radius[0] + radius[1]))).cast<Scalar>();
  if (!w->add_body(def_[0]).ok() || !w->add_body(def_[1]).ok()) throw std::runtime_error("runtime: add_body failed");
  for (int step = 0; step < 60; ++step) {
    if (!w->step(Scalar(1) / 240).ok()) throw std::runtime_error("runtime: step failed");
    const Vector3 rel = w->body(1).position - w->body(0).position;
    const Vector3 dv = w->body(1).linear_velocity - w->body(0).linear_velocity;
    if (rel.norm() > radius[0] + radius[1] && rel.dot(dv) > 0) break;
  }
  PairOutcome o;
  o.speed = double((w->body(1).linear_velocity - w->body(0).linear_velocity).norm()) / u;
  o.spin = double(w->body(1).angular_velocity.norm()) * L / u;
  return o;
}

bool table_for(const std::string& name, SignatureView<3>& out)
{
  if (name == "box") out = tables::box.view();
  else if (name == "lshape") out = tables::lshape.view();
  else if (name == "bunny") out = tables::bunny.view();
  else return false;
  return true;
}

}  // namespace

Summary summarise(std::vector<double> v)
{
  Summary s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  double sq = 0.0;
  for (double x : v) sq += (x - s.mean) * (x - s.mean);
  s.std = v.size() > 1 ? std::sqrt(sq / static_cast<double>(v.size() - 1)) : 0.0;
  s.p10 = quantile(v, 0.1);
  s.p50 = quantile(v, 0.5);
  s.p90 = quantile(v, 0.9);
  s.min = v.front();
  s.max = v.back();
  return s;
}

std::vector<Eigen::Vector3d> faces_by_area(const ShapeModel& m)
{
  const double L = m.bounding_radius;
  std::vector<std::pair<double, Eigen::Vector3d>> faces;
  for (const Eigen::Vector4d& plane : m.hull_planes) {
    const Eigen::Vector3d n = plane.head<3>();
    const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
    std::vector<Eigen::Vector2d> pts;
    for (const Eigen::Vector3d& p : m.hull)
      if (std::fabs(n.dot(p) - plane.w()) <= 1e-6 * L) pts.emplace_back(a.dot(p), b.dot(p));
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const auto& q : pts) c += q;
    if (!pts.empty()) c /= static_cast<double>(pts.size());
    std::sort(pts.begin(), pts.end(), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
      return std::atan2(p.y() - c.y(), p.x() - c.x()) < std::atan2(q.y() - c.y(), q.x() - c.x());
    });
    double area = 0.0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector2d& p = pts[i];
      const Eigen::Vector2d& q = pts[(i + 1) % pts.size()];
      area += 0.5 * (p.x() * q.y() - q.x() * p.y());
    }
    faces.emplace_back(area, n);
  }
  // Largest first; equal areas in the hull's order.
  std::stable_sort(faces.begin(), faces.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  std::vector<Eigen::Vector3d> out;
  for (const auto& f : faces) out.push_back(f.second);
  return out;
}

std::vector<double> face_offsets(const ShapeModel& m, const std::vector<Eigen::Vector3d>& faces)
{
  std::vector<double> out;
  for (const Eigen::Vector3d& f : faces) out.push_back(support(m.hull, f));
  return out;
}

double pair_trial(const ShapeModel& model, double spin_ratio, std::uint64_t seed, std::uint64_t index, bool hull_only,
                  double margin, double* hull_distance, std::pair<RigidState, RigidState>* at_contact)
{
  PairGeometry g(model, margin);
  std::unique_ptr<TouchQuery> touch;
  if (!hull_only && !g.convex) touch = std::make_unique<TouchQuery>(g.full);
  return pair_flight(model, g, touch.get(), pair_start(model, spin_ratio, 1.0, seed, index), hull_only,
                     hull_distance, at_contact);
}

namespace {

// The touching pairs of one reference pile (contact points grouped by pair).
struct PileOutcome {
  std::vector<PilePair> pairs;
  int bodies = 0;
  bool asleep = false;
};

PileOutcome run_pile(const ShapeModel& m, const PairOptions& o, const SupportMap3& map, std::uint64_t seed)
{
  const ReferencePile pile = reference_pile(m, o, seed);
  PileOutcome out;
  out.bodies = pile.bodies;
  out.asleep = pile.asleep;
  const std::vector<Eigen::Vector3d> faces = faces_by_area(m);
  const std::vector<double> offsets = face_offsets(m, faces);
  for (const PileContact& c : pile.contacts) {
    const Eigen::Vector3d& n = c.normal;
    const Eigen::Vector3d ab = c.b.position - c.a.position;
    const Eigen::Vector3d e = ab.normalized();
    const Eigen::Matrix3d ra = c.a.orientation.toRotationMatrix(), rb = c.b.orientation.toRotationMatrix();
    PilePair p;
    p.distance = ab.norm();
    p.angle_deg = std::acos(std::min(1.0, std::fabs(e.z()))) * 180.0 / kPi;
    p.along_normal = ab.dot(n);
    p.support_e = support(m.hull, ra.transpose() * e) + support(m.hull, -(rb.transpose() * e));
    p.support_e_map = map.lookup(ra.transpose() * e) + map.lookup(-(rb.transpose() * e));
    p.support_n = support(m.hull, ra.transpose() * n) + support(m.hull, -(rb.transpose() * n));
    p.penetration = c.penetration;
    const auto exact = [&](const Eigen::Vector3d& u) { return support(m.hull, u); };
    const auto table = [&](const Eigen::Vector3d& u) { return map.lookup(u); };
    p.radial6 = radial_estimate(exact, ra, rb, e, faces, 6);
    p.radial16 = radial_estimate(exact, ra, rb, e, faces, 16);
    p.radial_all = radial_estimate(exact, ra, rb, e, faces, faces.size());
    p.radial_map = radial_estimate(table, ra, rb, e, faces, static_cast<std::size_t>(o.candidate_faces), &offsets);
    out.pairs.push_back(p);
  }
  return out;
}

}  // namespace

ReferencePile reference_pile(const ShapeModel& m, const PairOptions& o, std::uint64_t seed)
{
  bullet::Shapes shapes;
  bullet::DropBody body;
  if (m.kind == ShapeKind::mesh) {
    std::vector<int> idx;
    for (const auto& t : m.body_mesh.triangles) idx.insert(idx.end(), {t[0], t[1], t[2]});
    body.shape = shapes.mesh(m.body_mesh.vertices, idx, bullet::kMargin);
  } else {
    body.shape = shapes.boxes(shape_boxes(m), bullet::kMargin);
  }
  body.mass = m.mass.mass;
  body.inertia = m.mass.principal_moments;
  body.bounding_radius = m.bounding_radius;
  // statsim bench's Bullet settings (tools/bench/bench_bullet.cpp), the pile reference of
  // `statsim fidelity`: the table's material, the statsim world's restitution threshold and sleep.
  bullet::DropSettings s;
  s.restitution = o.shape.reference.restitution;
  s.friction = o.shape.reference.friction;
  s.restitution_threshold = 0.5;
  s.sleep_speed = 0.05;
  s.sleep_time = 0.5;
  s.update_all_aabbs = false;
  std::vector<scenes::BodyState3> states;
  if (o.bin > 0) {
    const double L = m.bounding_radius, half = o.bin * L, cell = 2.1 * L;
    const int side = std::max(1, static_cast<int>(std::floor(2 * half / cell)));
    for (const Eigen::Vector3d& n : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 1, 0),
                                     Eigen::Vector3d(0, -1, 0)})
      s.planes.push_back({n, -half});
    for (int i = 0; i < o.pile_count; ++i) {
      TrialRng rng(seed, kBinStream, static_cast<std::uint64_t>(i));
      const int layer = i / (side * side), k = i % (side * side);
      scenes::BodyState3 b;
      b.position = Eigen::Vector3d(-half + cell * (0.5 + k % side), -half + cell * (0.5 + k / side),
                                   1.05 * L + cell * layer);
      b.orientation = rng.rotation();
      states.push_back(b);
    }
  } else {
    scenes::DropOptions d;
    d.count = o.pile_count;
    d.bounding_radius = m.bounding_radius;
    d.seed = seed;
    states = scenes::drop_scene3(d).bodies;
  }
  bullet::DropWorld w(body, states, s);
  const long steps = static_cast<long>(std::ceil(o.pile_time / o.pile_dt));
  ReferencePile out;
  out.bodies = static_cast<int>(w.size());
  for (long k = 0; k < steps; ++k) {
    w.step(o.pile_dt);
    ++out.steps;
    if (k % 24 == 0 && w.asleep_count() == w.size()) {
      out.asleep = true;
      break;
    }
  }
  out.asleep = out.asleep || w.asleep_count() == w.size();
  std::map<std::pair<std::size_t, std::size_t>, std::vector<bullet::DropWorld::BodyContact>> by_pair;
  for (const auto& c : w.body_contacts(o.touch_distance)) by_pair[{c.a, c.b}].push_back(c);
  for (const auto& [key, points] : by_pair) {
    const scenes::BodyState3 a = w.state(key.first), b = w.state(key.second);
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    double deepest = 0.0;
    for (const auto& c : points) {
      n += c.normal;
      deepest = std::max(deepest, -c.distance);
    }
    PileContact p;
    p.a.position = a.position;
    p.a.orientation = a.orientation;
    p.b.position = b.position;
    p.b.orientation = b.orientation;
    // Points of a nested pair can point opposite ways: then the first stands.
    p.normal = n.norm() > 0.5 ? Eigen::Vector3d(n.normalized()) : points.front().normal;
    p.penetration = deepest;
    out.contacts.push_back(p);
  }
  return out;
}

PairDistances pair_distances(const ShapeModel& m, const std::vector<double>& spin_ratios, int trials, double speed,
                             double margin, std::uint64_t seed, unsigned threads, bool show_progress)
{
  PairDistances r;
  const std::size_t ns = spin_ratios.size(), nt = static_cast<std::size_t>(trials);
  constexpr std::size_t chunk = 20;
  const std::size_t chunks = (nt + chunk - 1) / chunk;
  std::vector<double> dist(ns * nt), hull(ns * nt);
  Progress progress("pair flights", ns * nt, show_progress);
  parallel_for(
      ns * chunks,
      [&](std::size_t task) {
        const std::size_t si = task / chunks, c = task % chunks;
        PairGeometry g(m, margin);
        std::unique_ptr<TouchQuery> touch;
        if (!g.convex) touch = std::make_unique<TouchQuery>(g.full);
        for (std::size_t t = c * chunk; t < std::min(nt, (c + 1) * chunk); ++t) {
          const PairStart st = pair_start(m, spin_ratios[si], speed, seed, si * nt + t);
          dist[si * nt + t] = pair_flight(m, g, touch.get(), st, false, &hull[si * nt + t]);
        }
        progress.add(std::min(nt, (c + 1) * chunk) - c * chunk);
      },
      threads);
  progress.finish();
  for (std::size_t si = 0; si < ns; ++si) {
    const Summary s = summarise(std::vector<double>(dist.begin() + si * nt, dist.begin() + (si + 1) * nt));
    const Summary sh = summarise(std::vector<double>(hull.begin() + si * nt, hull.begin() + (si + 1) * nt));
    r.mean.push_back(s.mean);
    r.std.push_back(s.std);
    r.hull_mean.push_back(sh.mean);
  }
  r.flights = static_cast<long long>(ns * nt);
  return r;
}

PairResult gather_pairs(const PairOptions& options)
{
  PairResult r;
  r.options = options;
  const PairOptions& o = options;
  if (o.trials < 2 || o.height_trials < 2) throw std::runtime_error("--trials and --height-trials must be >= 2");
  if (o.support_size < 2) throw std::runtime_error("--support-size must be >= 2");
  validate_gather_options(o.shape);
  r.model = build_model(o.shape);
  if (!o.shape.name.empty()) r.model.name = o.shape.name;
  const ShapeModel& m = r.model;
  const unsigned threads = o.shape.threads;

  // h_coll at s = 0: the plane's counterpart.
  {
    std::vector<double> h(static_cast<std::size_t>(o.height_trials));
    parallel_for(h.size(), [&](std::size_t i) { h[i] = height_trial(m, 0.0, o.shape.seed ^ kPairHeightStream, i); },
                 threads);
    const Summary s = summarise(h);
    r.h_coll = s.mean;
    r.h_coll_std = s.std;
  }

  // Pair distance per spin ratio.
  const auto t0 = std::chrono::steady_clock::now();
  {
    const PairDistances d = pair_distances(m, o.spin_ratios, o.trials, o.speed, o.shape.reference.margin,
                                           o.shape.seed, threads, o.shape.progress);
    r.pair_mean = d.mean;
    r.pair_std = d.std;
    r.pair_hull_mean = d.hull_mean;
    r.pair_flights = d.flights;
  }
  r.pair_seconds = seconds_since(t0);

  // Support maps.
  for (int size : o.support_sizes) {
    const SupportMap3 map = SupportMap3::build(m.hull, size);
    const SupportError e = measure_support_error(map, m.hull, o.support_directions);
    r.support.push_back({size, 6 * size * size * 4, map.error_bound(m.hull), e.mean, e.max, e.min});
  }
  const SupportMap3 map = SupportMap3::build(m.hull, o.support_size);
  r.support_map = map.values;
  r.support_bound = map.error_bound(m.hull);

  // Reference piles.
  const auto t1 = std::chrono::steady_clock::now();
  if (o.piles > 0) {
    std::vector<PileOutcome> piles(static_cast<std::size_t>(o.piles));
    Progress progress("reference piles", piles.size(), o.shape.progress);
    parallel_for(
        piles.size(),
        [&](std::size_t i) {
          piles[i] = run_pile(m, o, map, i + 1);
          progress.add(1);
        },
        threads);
    progress.finish();
    for (const PileOutcome& p : piles) {
      r.pile_pairs.insert(r.pile_pairs.end(), p.pairs.begin(), p.pairs.end());
      r.pile_bodies += p.bodies;
      r.piles_asleep += p.asleep ? 1 : 0;
    }
  }
  r.pile_seconds = seconds_since(t1);

  // Pair responses: Bullet against the runtime from the same contact states.
  const auto t2 = std::chrono::steady_clock::now();
  SignatureView<3> sig{};
  if (o.response_trials > 0 && o.shape.box_size.empty() && o.shape.mesh_file.empty() && table_for(o.shape.shape, sig)) {
    const std::size_t n = static_cast<std::size_t>(o.response_trials);
    std::vector<PairOutcome> ref(n), run(n), ref_b(n);
    Progress progress("pair impacts", n, o.shape.progress);
    parallel_for(
        n,
        [&](std::size_t i) {
          PairGeometry g(m, o.shape.reference.margin);
          std::unique_ptr<TouchQuery> touch;
          if (!g.convex) touch = std::make_unique<TouchQuery>(g.full);
          // Spin ratios spread uniformly over 0..2, as impacts in a pile.
          TrialRng rng(o.shape.seed, kPairStream + 2, i);
          const double spin = 2.0 * rng.uniform();
          const PairStart st = pair_start(m, spin, o.speed, o.shape.seed + 7, i);
          std::pair<RigidState, RigidState> contact;
          pair_flight(m, g, touch.get(), st, false, nullptr, &contact);
          ref[i] = bullet_pair_impact(m, g.full, o.shape.reference, contact, o.speed);
          run[i] = runtime_pair_impact(sig, m.bounding_radius, contact, o.speed, o.shape.seed + i);
          // A second, independent reference sample: the noise floor of the KS distances.
          TrialRng rng_b(o.shape.seed, kPairStream + 3, i);
          const PairStart st_b = pair_start(m, 2.0 * rng_b.uniform(), o.speed, o.shape.seed + 8, i);
          pair_flight(m, g, touch.get(), st_b, false, nullptr, &contact);
          ref_b[i] = bullet_pair_impact(m, g.full, o.shape.reference, contact, o.speed);
          progress.add(1);
        },
        threads);
    progress.finish();
    std::vector<double> bs, bw, rs, rw, bs2, bw2;
    for (std::size_t i = 0; i < n; ++i) {
      bs.push_back(ref[i].speed);
      bw.push_back(ref[i].spin);
      rs.push_back(run[i].speed);
      rw.push_back(run[i].spin);
      bs2.push_back(ref_b[i].speed);
      bw2.push_back(ref_b[i].spin);
    }
    r.response_trials = static_cast<int>(n);
    r.ks_speed = ks_distance(bs, rs);
    r.ks_spin = ks_distance(bw, rw);
    r.ks_speed_floor = ks_distance(bs, bs2);
    r.ks_spin_floor = ks_distance(bw, bw2);
    r.bullet_speed = summarise(bs);
    r.bullet_spin = summarise(bw);
    r.runtime_speed = summarise(rs);
    r.runtime_spin = summarise(rw);
  }
  r.response_seconds = seconds_since(t2);
  return r;
}

// ---- output ----------------------------------------------------------------------------------

namespace {

using json = nlohmann::ordered_json;

json summary_json(const Summary& s)
{
  return {{"n", s.n}, {"mean", s.mean}, {"std", s.std}, {"p10", s.p10}, {"p50", s.p50}, {"p90", s.p90},
          {"min", s.min}, {"max", s.max}};
}

// The angle bins of the line of centres to the vertical, degrees.
const std::vector<std::pair<double, double>> kAngleBins = {{0, 30}, {30, 60}, {60, 90.001}, {0, 90.001}};

std::string bin_name(const std::pair<double, double>& b)
{
  return b.first == 0 && b.second > 90 ? std::string("all") : num(b.first) + "-" + num(std::floor(b.second)) + " deg";
}

// The ratios of the pile pairs in an angle bin: what each candidate predicts of the distance.
struct Ratios {
  Summary to_hcoll, to_pair, to_support_e, to_support_e_map, normal_to_support_n, residual_support_e_mm,
      residual_support_n_mm, to_radial6, to_radial16, to_radial_all, to_radial_map, residual_radial_map_mm;
};

Ratios ratios(const PairResult& r, const std::pair<double, double>& bin)
{
  std::vector<double> a, b, c, d, e, f, g, h, i, j, k, l;
  for (const PilePair& p : r.pile_pairs) {
    if (!(p.angle_deg >= bin.first && p.angle_deg < bin.second)) continue;
    h.push_back(p.distance / p.radial6);
    i.push_back(p.distance / p.radial16);
    j.push_back(p.distance / p.radial_all);
    k.push_back(p.distance / p.radial_map);
    l.push_back(1000 * (p.distance - p.radial_map));
    a.push_back(p.distance / (2 * r.h_coll));
    b.push_back(p.distance / r.pair_mean.front());
    c.push_back(p.distance / p.support_e);
    d.push_back(p.distance / p.support_e_map);
    e.push_back(p.along_normal / p.support_n);
    f.push_back(1000 * (p.distance - p.support_e));
    g.push_back(1000 * (p.along_normal - p.support_n));
  }
  return {summarise(a), summarise(b), summarise(c), summarise(d), summarise(e), summarise(f),
          summarise(g), summarise(h), summarise(i), summarise(j), summarise(k), summarise(l)};
}

std::string ms(const Summary& s, const char* f = "%.3f")
{
  return fmt(f, s.mean) + " +- " + fmt(f, s.std) + " [" + fmt(f, s.p10) + ", " + fmt(f, s.p90) + "]";
}

}  // namespace

std::string pairs_json(const PairResult& r, const std::string& command)
{
  json j;
  j["generated_by"] = command;
  j["shape"] = r.model.name;
  j["source"] = r.model.source;
  j["bounding_radius"] = r.model.bounding_radius;
  j["h_coll"] = {{"spin_ratio", 0.0}, {"mean", r.h_coll}, {"std", r.h_coll_std}, {"flights", r.options.height_trials}};
  j["pair_distance"] = {{"spin_ratios", r.options.spin_ratios},
                        {"mean", r.pair_mean},
                        {"std", r.pair_std},
                        {"hull_mean", r.pair_hull_mean},
                        {"flights_per_ratio", r.options.trials},
                        {"speed", r.options.speed}};
  json sup = json::array();
  for (const SupportRow& s : r.support)
    sup.push_back({{"size", s.size}, {"bytes_f32", s.bytes}, {"bound", s.bound}, {"mean_error", s.mean},
                   {"max_error", s.max}, {"min_error", s.min}});
  j["support_errors"] = sup;
  std::vector<float> values(r.support_map.begin(), r.support_map.end());
  std::vector<double> as_float(values.begin(), values.end());
  j["support_map"] = {{"size", r.options.support_size},
                      {"values", "table.support"},
                      {"layout", "6 faces (+x,-x,+y,-y,+z,-z) x S x S, index (f S + i) S + j, i along axis m+1, j "
                                 "along m+2, node -1 + 2 i / (S - 1); s(u) = |u_m| bilinear(h)"},
                      {"bound", r.support_bound}};
  json piles;
  piles["piles"] = r.options.piles;
  piles["bodies"] = r.pile_bodies;
  piles["piles_asleep"] = r.piles_asleep;
  piles["pairs"] = r.pile_pairs.size();
  piles["dt"] = r.options.pile_dt;
  json bins = json::array();
  for (const auto& bin : kAngleBins) {
    const Ratios x = ratios(r, bin);
    bins.push_back({{"bin", bin_name(bin)},
                    {"distance_over_2hcoll", summary_json(x.to_hcoll)},
                    {"distance_over_pair", summary_json(x.to_pair)},
                    {"distance_over_support_e", summary_json(x.to_support_e)},
                    {"distance_over_support_e_map", summary_json(x.to_support_e_map)},
                    {"normal_separation_over_support_n", summary_json(x.normal_to_support_n)},
                    {"distance_minus_support_e_mm", summary_json(x.residual_support_e_mm)},
                    {"normal_separation_minus_support_n_mm", summary_json(x.residual_support_n_mm)},
                    {"distance_over_radial_faces6", summary_json(x.to_radial6)},
                    {"distance_over_radial_faces16", summary_json(x.to_radial16)},
                    {"distance_over_radial_all_faces", summary_json(x.to_radial_all)},
                    {"distance_over_radial_map", summary_json(x.to_radial_map)},
                    {"distance_minus_radial_map_mm", summary_json(x.residual_radial_map_mm)}});
  }
  piles["by_angle"] = bins;
  j["packing"] = piles;
  // The proposed table fields in one place (tools/ref3d/README.md, "Body-body statistics").
  {
    const std::vector<Eigen::Vector3d> faces = faces_by_area(r.model);
    const std::vector<double> offsets = face_offsets(r.model, faces);
    const std::size_t k = std::min<std::size_t>(faces.size(), static_cast<std::size_t>(r.options.candidate_faces));
    json normals = json::array(), off = json::array();
    for (std::size_t i = 0; i < k; ++i) {
      normals.push_back({static_cast<double>(static_cast<float>(faces[i].x())),
                         static_cast<double>(static_cast<float>(faces[i].y())),
                         static_cast<double>(static_cast<float>(faces[i].z()))});
      off.push_back(static_cast<double>(static_cast<float>(offsets[i])));
    }
    json packing_mean = json::array(), packing_std = json::array(), packing_n = json::array();
    for (std::size_t b = 0; b < 3; ++b) {
      const Ratios x = ratios(r, kAngleBins[b]);
      packing_mean.push_back(x.to_radial_map.n > 0 ? x.to_radial_map.mean : 1.0);
      packing_std.push_back(x.to_radial_map.std);
      packing_n.push_back(x.to_radial_map.n);
    }
    j["table"] = {{"pair_spin_ratios", r.options.spin_ratios},
                  {"pair_mean", r.pair_mean},
                  {"pair_stddev", r.pair_std},
                  {"support_size", r.options.support_size},
                  {"support", as_float},
                  {"face_normals", normals},
                  {"face_offsets", off},
                  {"packing_bins_deg", {0, 30, 60, 90}},
                  {"packing_mean", packing_mean},
                  {"packing_stddev", packing_std},
                  {"packing_pairs", packing_n}};
  }
  if (r.response_trials > 0) {
    j["responses"] = {{"trials", r.response_trials},
                      {"ks_speed", r.ks_speed},
                      {"ks_spin", r.ks_spin},
                      {"ks_speed_floor", r.ks_speed_floor},
                      {"ks_spin_floor", r.ks_spin_floor},
                      {"bullet_speed", summary_json(r.bullet_speed)},
                      {"bullet_spin", summary_json(r.bullet_spin)},
                      {"runtime_speed", summary_json(r.runtime_speed)},
                      {"runtime_spin", summary_json(r.runtime_spin)}};
  }
  return j.dump(2) + "\n";
}

std::string pairs_markdown(const PairResult& r, const std::string& command)
{
  std::ostringstream s;
  const double L = r.model.bounding_radius;
  s << "### " << r.model.name << "\n\n`" << command << "`\n\n";
  s << "L = " << fmt("%.4f", L) << " m; h_coll (s = 0) = " << fmt("%.4f", r.h_coll) << " m (std "
    << fmt("%.4f", r.h_coll_std) << "), 2 h_coll = " << fmt("%.4f", 2 * r.h_coll) << " m.\n\n";
  s << "Pair distance at first contact (" << r.options.trials << " flights per spin ratio, " << fmt("%.1f", r.pair_seconds)
    << " s):\n\n| spin ratio | mean (m) | std (m) | mean / 2 h_coll | hulls' mean (m) |\n|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < r.pair_mean.size(); ++i)
    s << "| " << num(r.options.spin_ratios[i]) << " | " << fmt("%.4f", r.pair_mean[i]) << " | "
      << fmt("%.4f", r.pair_std[i]) << " | " << fmt("%.3f", r.pair_mean[i] / (2 * r.h_coll)) << " | "
      << fmt("%.4f", r.pair_hull_mean[i]) << " |\n";
  s << "\nSupport cube map against the exact hull support (" << r.options.support_directions
    << " random directions), errors in units of L:\n\n| S | bytes (f32) | bound | mean | max |\n|---|---|---|---|---|\n";
  for (const SupportRow& x : r.support)
    s << "| " << x.size << " | " << x.bytes << " | " << fmt("%.4f", x.bound / L) << " | " << fmt("%.5f", x.mean / L)
      << " | " << fmt("%.4f", x.max / L) << " |\n";
  if (!r.pile_pairs.empty()) {
    s << "\nPacking in " << r.options.piles << " reference piles of " << r.options.pile_count << " (" << r.piles_asleep
      << " all asleep, " << r.pile_pairs.size() << " touching pairs, " << fmt("%.1f", r.pile_seconds)
      << " s): ratio mean +- std [p10, p90]; residuals in mm.\n\n";
    s << "| angle of e to vertical | pairs | d / 2 h_coll | d / pair distance | d / support(e) | d / map(e) | "
         "(d.n) / support(n) | d - support(e) (mm) | d.n - support(n) (mm) |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& bin : kAngleBins) {
      const Ratios x = ratios(r, bin);
      s << "| " << bin_name(bin) << " | " << x.to_hcoll.n << " | " << ms(x.to_hcoll) << " | " << ms(x.to_pair) << " | "
        << ms(x.to_support_e) << " | " << ms(x.to_support_e_map) << " | " << ms(x.normal_to_support_n) << " | "
        << ms(x.residual_support_e_mm, "%.1f") << " | " << ms(x.residual_support_n_mm, "%.1f") << " |\n";
    }
    s << "\nThe same pairs against the upper bound min over candidate normals n of support sum / (n.e) "
         "(radial_estimate): candidates e and the hull's K largest faces of either body.\n\n"
         "| angle of e to vertical | d / K = 6 | d / K = 16 | d / all faces | d / map, K = "
      << r.options.candidate_faces << " | d - map (mm) |\n|---|---|---|---|---|---|\n";
    for (const auto& bin : kAngleBins) {
      const Ratios x = ratios(r, bin);
      s << "| " << bin_name(bin) << " | " << ms(x.to_radial6) << " | " << ms(x.to_radial16) << " | "
        << ms(x.to_radial_all) << " | " << ms(x.to_radial_map) << " | " << ms(x.residual_radial_map_mm, "%.1f") << " |\n";
    }
  }
  if (r.response_trials > 0) {
    s << "\nPair responses (" << r.response_trials << " impacts): KS runtime vs Bullet |v+|/|v-| " << fmt("%.3f", r.ks_speed)
      << " (floor " << fmt("%.3f", r.ks_speed_floor) << "), |w+| L/|v-| " << fmt("%.3f", r.ks_spin) << " (floor "
      << fmt("%.3f", r.ks_spin_floor) << "); Bullet |v+|/|v-| " << ms(r.bullet_speed) << ", runtime " << ms(r.runtime_speed)
      << "; Bullet |w+| L/|v-| " << ms(r.bullet_spin) << ", runtime " << ms(r.runtime_spin) << " ("
      << fmt("%.1f", r.response_seconds) << " s).\n";
  }
  return s.str();
}

}  // namespace statsim::tools::ref3d
