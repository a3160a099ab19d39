#include "ref3d/reference.hpp"

#include "bullet/bullet.hpp"
#include "ref3d/bullet_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace statsim::tools::ref3d {

std::string bullet_version()
{
  const int v = btGetVersion();
  return std::to_string(v / 100) + "." + std::to_string(v % 100);
}

void apply_solver_settings(btContactSolverInfo& info, const ReferenceSettings& s)
{
  info.m_numIterations = s.solver_iterations;
  info.m_restitutionVelocityThreshold = s.restitution_threshold;
  info.m_splitImpulse = s.split_impulse ? 1 : 0;
  info.m_splitImpulsePenetrationThreshold = s.split_impulse ? 1e30 : -0.04;
  info.m_erp = s.erp;
  info.m_erp2 = s.erp;
  info.m_linearSlop = 0.0;
  info.m_solverMode = SOLVER_USE_2_FRICTION_DIRECTIONS | (s.warm_starting ? SOLVER_USE_WARMSTARTING : 0);
}

namespace {

using bullet::to_bt;
using bullet::to_eigen;

}  // namespace

struct Reference::Impl {
  btDefaultCollisionConfiguration config;
  std::vector<std::unique_ptr<btCollisionShape>> children;
  std::unique_ptr<btCollisionShape> body_shape;
  std::unique_ptr<btCollisionShape> ground_shape;
  // GImpact's mesh data (the interface points into these arrays).
  std::vector<double> vertices;
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> mesh_interface;
  btVector3 local_inertia;
  double mass = 1.0;

  // One trial's world.
  struct World {
    btCollisionDispatcher dispatcher;
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world;
    std::unique_ptr<btRigidBody> ground;
    std::unique_ptr<btRigidBody> body;
    explicit World(btDefaultCollisionConfiguration* config)
        : dispatcher(config), world(&dispatcher, &broadphase, &solver, config)
    {
    }
    ~World()
    {
      if (body) world.removeRigidBody(body.get());
      if (ground) world.removeRigidBody(ground.get());
    }
  };

  std::unique_ptr<World> make_world(const ReferenceSettings& s, Ground g, const RigidState& start, double gravity,
                                    double rolling_friction)
  {
    auto w = std::make_unique<World>(&config);
    btGImpactCollisionAlgorithm::registerAlgorithm(&w->dispatcher);
    w->world.setGravity(btVector3(0, 0, -gravity));
    apply_solver_settings(w->world.getSolverInfo(), s);

    // Ground: static, restitution 1 and friction 1, so the combined values (Bullet multiplies)
    // are the body's.
    btTransform ground_pose;
    ground_pose.setIdentity();
    if (g == Ground::box) ground_pose.setOrigin(btVector3(0, 0, -10.0));
    btRigidBody::btRigidBodyConstructionInfo gi(0.0, nullptr, ground_shape.get(), btVector3(0, 0, 0));
    gi.m_startWorldTransform = ground_pose;
    gi.m_restitution = 1.0;
    gi.m_friction = 1.0;
    w->ground = std::make_unique<btRigidBody>(gi);
    w->world.addRigidBody(w->ground.get());

    btRigidBody::btRigidBodyConstructionInfo bi(mass, nullptr, body_shape.get(), local_inertia);
    bi.m_startWorldTransform = to_bt(start);
    bi.m_restitution = s.restitution;
    bi.m_friction = s.friction;
    bi.m_rollingFriction = rolling_friction;
    bi.m_spinningFriction = rolling_friction;
    bi.m_linearDamping = 0.0;
    bi.m_angularDamping = 0.0;
    bi.m_additionalDamping = false;
    w->body = std::make_unique<btRigidBody>(bi);
    w->body->setFlags(BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY);
    w->body->setActivationState(DISABLE_DEACTIVATION);
    // Speculative contacts (points reported at a positive distance) stop the approach over the
    // step before the touch, and the touch then sees a slower approach: restitution is lost.
    // Process only touching or penetrating points.
    if (!s.speculative_contacts) w->body->setContactProcessingThreshold(0.0);
    w->body->setLinearVelocity(to_bt(start.velocity));
    w->body->setAngularVelocity(to_bt(start.spin));
    w->world.addRigidBody(w->body.get());
    return w;
  }
};

Reference::Reference(const ShapeModel& model, const ReferenceSettings& settings)
    : model_(model), settings_(settings), flight_(model.unit_inertia), impl_(std::make_unique<Impl>())
{
  Impl& m = *impl_;
  ground_ = settings.ground_auto ? (model.kind == ShapeKind::mesh ? Ground::plane : Ground::box) : settings.ground;
  if (settings.multipoint_plane) m.config.setPlaneConvexMultipointIterations(3, 3);
  const double margin = settings.margin;
  auto make_box = [&](const BodyBox& b) {
    auto box = std::make_unique<btBoxShape>(to_bt(b.half_extents));
    box->setMargin(margin);  // btBoxShape keeps its outer size: the margin is inside the extents
    return box;
  };
  switch (model.kind) {
    case ShapeKind::box: {
      const BodyBox& b = model.boxes.at(0);
      // The body frame of a box is its own frame up to a permutation of axes: use the half
      // extents along the body axes (|R| h).
      const Eigen::Vector3d h = b.rotation.cwiseAbs() * b.half_extents;
      BodyBox aligned;
      aligned.half_extents = h;
      m.body_shape = make_box(aligned);
      break;
    }
    case ShapeKind::compound: {
      auto compound = std::make_unique<btCompoundShape>();
      for (const BodyBox& b : model.boxes) {
        auto child = make_box(b);
        btMatrix3x3 basis(b.rotation(0, 0), b.rotation(0, 1), b.rotation(0, 2), b.rotation(1, 0), b.rotation(1, 1),
                          b.rotation(1, 2), b.rotation(2, 0), b.rotation(2, 1), b.rotation(2, 2));
        compound->addChildShape(btTransform(basis, to_bt(b.centre)), child.get());
        m.children.push_back(std::move(child));
      }
      compound->setMargin(margin);
      m.body_shape = std::move(compound);
      break;
    }
    case ShapeKind::mesh: {
      if (settings.mesh_hull) {
        auto hull = std::make_unique<btConvexHullShape>();
        for (const auto& p : model.hull) hull->addPoint(to_bt(p), false);
        hull->recalcLocalAabb();
        hull->setMargin(margin);
        m.body_shape = std::move(hull);
        break;
      }
      for (const auto& v : model.body_mesh.vertices) m.vertices.insert(m.vertices.end(), {v.x(), v.y(), v.z()});
      for (const auto& t : model.body_mesh.triangles) m.indices.insert(m.indices.end(), {t[0], t[1], t[2]});
      m.mesh_interface = std::make_unique<btTriangleIndexVertexArray>(
          static_cast<int>(model.body_mesh.triangles.size()), m.indices.data(), static_cast<int>(3 * sizeof(int)),
          static_cast<int>(model.body_mesh.vertices.size()), m.vertices.data(), static_cast<int>(3 * sizeof(double)));
      auto gimpact = std::make_unique<btGImpactMeshShape>(m.mesh_interface.get());
      gimpact->setMargin(margin);
      gimpact->updateBound();
      m.body_shape = std::move(gimpact);
      break;
    }
  }
  if (ground_ == Ground::box) {
    m.ground_shape = std::make_unique<btBoxShape>(btVector3(100.0, 100.0, 10.0));
    m.ground_shape->setMargin(margin);
  } else {
    m.ground_shape = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0.0);
  }
  m.mass = model.mass.mass;
  m.local_inertia = to_bt(model.mass.principal_moments);
}

Reference::~Reference() = default;

namespace {

RigidState state_of(const btRigidBody& body)
{
  RigidState s;
  const btTransform& t = body.getCenterOfMassTransform();
  s.position = to_eigen(t.getOrigin());
  const btQuaternion q = t.getRotation();
  s.orientation = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized();
  s.velocity = to_eigen(body.getLinearVelocity());
  s.spin = to_eigen(body.getAngularVelocity());
  return s;
}

// Contact points Bullet holds for the body (distance at or below `distance`).
int touching_points(btDiscreteDynamicsWorld& world, double distance)
{
  int count = 0;
  btDispatcher* d = world.getDispatcher();
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    const btPersistentManifold* m = d->getManifoldByIndexInternal(i);
    for (int k = 0; k < m->getNumContacts(); ++k)
      if (m->getContactPoint(k).getDistance() <= distance) ++count;
  }
  return count;
}

}  // namespace

ImpactResult Reference::impact(const RigidState& start, double max_time) const
{
  auto w = impl_->make_world(settings_, ground_, start, 0.0, 0.0);
  ImpactResult r;
  const double dt = settings_.dt;
  const double clearance = settings_.margin;
  const double radius = model_.bounding_radius;
  const int max_steps = static_cast<int>(std::ceil(max_time / dt));
  int next_check = 1;
  for (int step = 1; step <= max_steps; ++step) {
    w->world.stepSimulation(dt, 0, dt);
    r.steps = step;
    const RigidState s = state_of(*w->body);
    const double gap = lowest_point(model_.hull, s);
    r.max_penetration = std::max(r.max_penetration, -gap);
    if (step < next_check || gap <= clearance || touching_points(w->world, 0.0) > 0) continue;
    // Clear of the ground: done if the exact free flight never comes back within the margin.
    double horizon = std::numeric_limits<double>::infinity();
    if (s.velocity.z() > 0) horizon = (radius + clearance - s.position.z()) / s.velocity.z();
    const FirstContact fc = first_contact(model_.hull, radius, flight_, s, clearance, horizon, 1e-9 * radius, 2000);
    if (!fc.hit && !fc.undecided) {
      r.after = s;
      return r;
    }
    // Not yet: check again after a few more steps (more when the check was expensive).
    next_check = step + (fc.undecided ? 16 : 4);
  }
  r.after = state_of(*w->body);
  r.time_limited = true;
  return r;
}

DropResult Reference::drop(const RigidState& start, double still_speed, double still_time, double max_time,
                           const SettleSpeeds& speeds) const
{
  auto w = impl_->make_world(settings_, ground_, start, settings_.gravity, settings_.rest_rolling_friction);
  DropResult r;
  const double dt = settings_.dt;
  const double radius = model_.bounding_radius;
  const int max_steps = static_cast<int>(std::ceil(max_time / dt));
  const int window = std::max(1, static_cast<int>(std::ceil(still_time / dt)));
  // Still: over two consecutive windows of `still_time`, the average speed of the centre and of
  // the farthest point (|w| R) stays below `still_speed`. Averages, not instantaneous speeds:
  // a resting GImpact body jitters by a few mm/s from step to step while going nowhere.
  RigidState anchor = start;
  int quiet = 0;
  // The settling time's two ends, in steps: the last step at the settle speed or faster, and the
  // last at the quiet speed or faster (0: none; the state at the start is not a step).
  int last_fast = 0, last_moving = 0;
  int step = 0;
  while (step < max_steps) {
    ++step;
    w->world.stepSimulation(dt, 0, dt);
    r.time = step * dt;
    const double speed = std::max(to_eigen(w->body->getLinearVelocity()).norm(),
                                  to_eigen(w->body->getAngularVelocity()).norm() * radius);
    if (speed >= speeds.settle) last_fast = step;
    if (speed >= speeds.quiet) last_moving = step;
    if (step % window != 0) continue;
    const RigidState s = state_of(*w->body);
    const double moved = (s.position - anchor.position).norm();
    const double turned = s.orientation.angularDistance(anchor.orientation) * radius;
    const double limit = still_speed * window * dt;
    quiet = (moved < limit && turned < limit) ? quiet + 1 : 0;
    anchor = s;
    if (quiet >= 2) {
      r.settled = true;
      break;
    }
  }
  // Quiet from the step after the last moving one; a drop that never got there within its run
  // (not settled, or moving at its last step) counts to the run's end, a lower bound.
  const int quiet_from = r.settled ? std::min(last_moving + 1, step) : step;
  r.settle_time = std::max(0, quiet_from - last_fast) * dt;
  r.rest = state_of(*w->body);
  r.height = r.rest.position.z() - lowest_point(model_.hull, r.rest);
  return r;
}

struct Reference::Run::World {
  std::unique_ptr<Reference::Impl::World> w;
};

Reference::Run::Run() = default;
Reference::Run::~Run() = default;

std::unique_ptr<Reference::Run> Reference::run(const RigidState& start) const
{
  std::unique_ptr<Run> r(new Run());
  r->world_ = std::make_unique<Run::World>();
  r->world_->w = impl_->make_world(settings_, ground_, start, settings_.gravity, settings_.rest_rolling_friction);
  r->dt_ = settings_.dt;
  return r;
}

void Reference::Run::step()
{
  world_->w->world.stepSimulation(dt_, 0, dt_);
}

RigidState Reference::Run::state() const
{
  return state_of(*world_->w->body);
}

}  // namespace statsim::tools::ref3d
