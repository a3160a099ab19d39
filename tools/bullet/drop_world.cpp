#include "bullet/drop_world.hpp"

#include "bullet/bullet.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace statsim::tools::bullet {

// ---- shapes ----------------------------------------------------------------------------------------

struct Shapes::Store {
  // A GImpact shape reads its triangles through the interface, which points into these arrays.
  struct Mesh {
    std::vector<btScalar> vertices;
    std::vector<int> indices;
    std::unique_ptr<btTriangleIndexVertexArray> array;
  };
  std::vector<std::unique_ptr<Mesh>> meshes;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;

  btCollisionShape* keep(std::unique_ptr<btCollisionShape> shape)
  {
    shapes.push_back(std::move(shape));
    return shapes.back().get();
  }
};

Shapes::Shapes() : store_(std::make_unique<Store>()) {}

Shapes::~Shapes() = default;

btCollisionShape* Shapes::mesh(const std::vector<Eigen::Vector3d>& vertices, const std::vector<int>& indices,
                               double margin)
{
  auto m = std::make_unique<Store::Mesh>();
  for (const auto& p : vertices) m->vertices.insert(m->vertices.end(), {p.x(), p.y(), p.z()});
  m->indices = indices;
  m->array = std::make_unique<btTriangleIndexVertexArray>(
      static_cast<int>(m->indices.size() / 3), m->indices.data(), static_cast<int>(3 * sizeof(int)),
      static_cast<int>(vertices.size()), m->vertices.data(), static_cast<int>(3 * sizeof(btScalar)));
  auto shape = std::make_unique<btGImpactMeshShape>(m->array.get());
  shape->setMargin(margin);
  shape->updateBound();
  store_->meshes.push_back(std::move(m));
  return store_->keep(std::move(shape));
}

btCollisionShape* Shapes::hull(const std::vector<Eigen::Vector3d>& points, double margin)
{
  auto shape = std::make_unique<btConvexHullShape>();
  for (const auto& p : points) shape->addPoint(to_bt(p), false);
  shape->recalcLocalAabb();
  shape->setMargin(margin);
  return store_->keep(std::move(shape));
}

btCollisionShape* Shapes::spheres(const std::vector<Eigen::Vector4d>& spheres)
{
  auto compound = std::make_unique<btCompoundShape>();
  for (const auto& s : spheres) {
    btCollisionShape* child = store_->keep(std::make_unique<btSphereShape>(s[3]));
    btTransform t;
    t.setIdentity();
    t.setOrigin(btVector3(s[0], s[1], s[2]));
    compound->addChildShape(t, child);
  }
  return store_->keep(std::move(compound));
}

btCollisionShape* Shapes::sphere(double radius)
{
  return store_->keep(std::make_unique<btSphereShape>(radius));
}

btCollisionShape* Shapes::boxes(const std::vector<Box>& boxes, double margin)
{
  // A box's margin is inside its extents: it rounds the corners without growing the box.
  const bool single = boxes.size() == 1 && boxes[0].centre.norm() < 1e-12 &&
                      (boxes[0].rotation - Eigen::Matrix3d::Identity()).norm() < 1e-12;
  if (single) {
    auto box = std::make_unique<btBoxShape>(to_bt(boxes[0].half_extents));
    box->setMargin(margin);
    return store_->keep(std::move(box));
  }
  auto compound = std::make_unique<btCompoundShape>();
  for (const Box& b : boxes) {
    auto child = std::make_unique<btBoxShape>(to_bt(b.half_extents));
    child->setMargin(margin);
    const Eigen::Matrix3d& r = b.rotation;
    const btMatrix3x3 basis(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
    compound->addChildShape(btTransform(basis, to_bt(b.centre)), child.get());
    store_->keep(std::move(child));
  }
  return store_->keep(std::move(compound));
}

// ---- the world -------------------------------------------------------------------------------------

namespace {

using Clock = std::chrono::steady_clock;

std::int64_t elapsed_ns(Clock::time_point a, Clock::time_point b)
{
  return std::chrono::duration_cast<std::chrono::nanoseconds>(b - a).count();
}

/// btDiscreteDynamicsWorld with the collision phase timed: the calls of
/// btCollisionWorld::performDiscreteCollisionDetection (update AABBs, find overlapping pairs,
/// dispatch the pairs to the narrow phase) with a clock read between them.
class TimedWorld final : public btDiscreteDynamicsWorld {
public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;

  void performDiscreteCollisionDetection() override
  {
    const Clock::time_point t0 = Clock::now();
    updateAabbs();
    computeOverlappingPairs();
    const Clock::time_point t1 = Clock::now();
    btDispatcher* dispatcher = getDispatcher();
    if (dispatcher)
      dispatcher->dispatchAllCollisionPairs(m_broadphasePairCache->getOverlappingPairCache(), getDispatchInfo(),
                                            m_dispatcher1);
    const Clock::time_point t2 = Clock::now();
    broad_ns += elapsed_ns(t0, t1);
    narrow_ns += elapsed_ns(t1, t2);
  }

  std::int64_t broad_ns = 0;
  std::int64_t narrow_ns = 0;
};

std::unique_ptr<btBroadphaseInterface> make_broad_phase(const DropSettings& s, int handles)
{
  if (s.broad_phase == BroadPhase::dbvt) return std::make_unique<btDbvtBroadphase>();
  // btAxisSweep3 stores handles in 16 bits.
  if (handles <= 16000)
    return std::make_unique<btAxisSweep3>(to_bt(s.bounds_lo), to_bt(s.bounds_hi), static_cast<unsigned short>(handles));
  return std::make_unique<bt32BitAxisSweep3>(to_bt(s.bounds_lo), to_bt(s.bounds_hi), static_cast<unsigned int>(handles));
}

}  // namespace

struct DropWorld::Impl {
  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btBroadphaseInterface> broadphase;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver;
  std::vector<std::unique_ptr<btStaticPlaneShape>> plane_shapes;
  std::vector<std::unique_ptr<btRigidBody>> statics;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::unique_ptr<TimedWorld> world;  // destroyed first (declared last): it removes its objects' proxies
};

DropWorld::DropWorld(const DropBody& body, const std::vector<scenes::BodyState3>& states,
                     const DropSettings& settings)
    : DropWorld(std::vector<DropBody>{body}, std::vector<int>{}, states, settings)
{
}

DropWorld::DropWorld(const std::vector<DropBody>& bodies, const std::vector<int>& of_body,
                     const std::vector<scenes::BodyState3>& states, const DropSettings& settings)
    : impl_(std::make_unique<Impl>())
{
  if (bodies.empty()) throw std::invalid_argument("Bullet drop world: no body");
  for (const DropBody& body : bodies)
    if (!body.shape) throw std::invalid_argument("Bullet drop world: no collision shape");
  if (!of_body.empty() && of_body.size() != states.size())
    throw std::invalid_argument("Bullet drop world: one shape index per body");
  for (int k : of_body)
    if (k < 0 || static_cast<std::size_t>(k) >= bodies.size())
      throw std::invalid_argument("Bullet drop world: shape index out of range");
  Impl& m = *impl_;
  const int n = static_cast<int>(states.size());
  btDefaultCollisionConstructionInfo cci;
  cci.m_defaultMaxPersistentManifoldPoolSize = std::max(4096, 4 * n);
  cci.m_defaultMaxCollisionAlgorithmPoolSize = std::max(4096, 4 * n);
  m.config = std::make_unique<btDefaultCollisionConfiguration>(cci);
  m.dispatcher = std::make_unique<btCollisionDispatcher>(m.config.get());
  btGImpactCollisionAlgorithm::registerAlgorithm(m.dispatcher.get());
  m.broadphase = make_broad_phase(settings, n + 2);
  m.solver = std::make_unique<btSequentialImpulseConstraintSolver>();
  m.world = std::make_unique<TimedWorld>(m.dispatcher.get(), m.broadphase.get(), m.solver.get(), m.config.get());
  m.world->setGravity(to_bt(settings.gravity));
  if (!settings.update_all_aabbs) m.world->setForceUpdateAllAabbs(false);
  m.world->getSolverInfo().m_restitutionVelocityThreshold = settings.restitution_threshold;
  m.world->getSolverInfo().m_numIterations = settings.solver_iterations;
  gDeactivationTime = settings.sleep_time;

  const double friction = std::sqrt(settings.friction);
  const double restitution = std::sqrt(settings.restitution);
  for (const Plane& p : settings.planes) {
    m.plane_shapes.push_back(std::make_unique<btStaticPlaneShape>(to_bt(p.normal), p.offset));
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, m.plane_shapes.back().get());
    info.m_friction = friction;
    info.m_restitution = restitution;
    m.statics.push_back(std::make_unique<btRigidBody>(info));
    m.world->addRigidBody(m.statics.back().get());
  }
  const double rolling = settings.rolling_radius > 0 && friction > 0
                             ? settings.rolling_resistance * settings.rolling_radius / friction
                             : 0.0;
  m.bodies.reserve(states.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    const scenes::BodyState3& s = states[i];
    const DropBody& body = bodies[of_body.empty() ? 0 : static_cast<std::size_t>(of_body[i])];
    btRigidBody::btRigidBodyConstructionInfo info(body.mass, nullptr, body.shape, to_bt(body.inertia));
    info.m_friction = friction;
    info.m_restitution = restitution;
    info.m_rollingFriction = rolling;
    info.m_linearSleepingThreshold = settings.sleep_speed;
    info.m_angularSleepingThreshold = settings.sleep_speed / body.bounding_radius;
    const Eigen::Quaterniond& q = s.orientation;
    info.m_startWorldTransform = btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), to_bt(s.position));
    auto rb = std::make_unique<btRigidBody>(info);
    rb->setUserIndex(static_cast<int>(m.bodies.size()));
    rb->setLinearVelocity(to_bt(s.linear_velocity));
    rb->setAngularVelocity(to_bt(s.angular_velocity));
    if (!settings.sleeping) rb->setActivationState(DISABLE_DEACTIVATION);
    // A sleeping body is neither integrated nor pulled by gravity until something wakes it.
    if (s.asleep) rb->setActivationState(ISLAND_SLEEPING);
    m.world->addRigidBody(rb.get());
    m.bodies.push_back(std::move(rb));
  }
}

DropWorld::~DropWorld() = default;

void DropWorld::step(double dt, int substeps)
{
  TimedWorld& w = *impl_->world;
  w.broad_ns = 0;
  w.narrow_ns = 0;
  // stepSimulation(dt, 0): one internal step of exactly dt, no interpolation.
  if (substeps <= 1)
    w.stepSimulation(dt, 0);
  else
    w.stepSimulation(dt, substeps, dt / substeps);
}

std::size_t DropWorld::size() const
{
  return impl_->bodies.size();
}

scenes::BodyState3 DropWorld::state(std::size_t i) const
{
  const btRigidBody& b = *impl_->bodies[i];
  const btQuaternion q = b.getOrientation();
  scenes::BodyState3 s;
  s.position = to_eigen(b.getCenterOfMassPosition());
  s.orientation = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z());
  s.linear_velocity = to_eigen(b.getLinearVelocity());
  s.angular_velocity = to_eigen(b.getAngularVelocity());
  return s;
}

bool DropWorld::asleep(std::size_t i) const
{
  return impl_->bodies[i]->getActivationState() == ISLAND_SLEEPING;
}

void DropWorld::set_state(std::size_t i, const scenes::BodyState3& s)
{
  btRigidBody& b = *impl_->bodies[i];
  const Eigen::Quaterniond& q = s.orientation;
  b.setCenterOfMassTransform(btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), to_bt(s.position)));
  b.setLinearVelocity(to_bt(s.linear_velocity));
  b.setAngularVelocity(to_bt(s.angular_velocity));
  b.activate(true);
}

std::size_t DropWorld::asleep_count() const
{
  std::size_t k = 0;
  for (std::size_t i = 0; i < size(); ++i) k += asleep(i);
  return k;
}

std::size_t DropWorld::touching_pairs() const
{
  btDispatcher* d = impl_->world->getDispatcher();
  std::size_t k = 0;
  for (int i = 0; i < d->getNumManifolds(); ++i) k += d->getManifoldByIndexInternal(i)->getNumContacts() > 0;
  return k;
}

std::vector<DropWorld::BodyContact> DropWorld::body_contacts(double max_distance) const
{
  btDispatcher* d = impl_->world->getDispatcher();
  std::vector<BodyContact> out;
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    const btPersistentManifold* m = d->getManifoldByIndexInternal(i);
    const auto* b0 = btRigidBody::upcast(m->getBody0());
    const auto* b1 = btRigidBody::upcast(m->getBody1());
    if (!b0 || !b1 || b0->getInvMass() == 0 || b1->getInvMass() == 0) continue;
    const bool swap = b0->getUserIndex() > b1->getUserIndex();
    for (int k = 0; k < m->getNumContacts(); ++k) {
      const btManifoldPoint& p = m->getContactPoint(k);
      if (p.getDistance() > max_distance) continue;
      BodyContact c;
      // m_normalWorldOnB points from body 1 towards body 0.
      const Eigen::Vector3d n = to_eigen(p.m_normalWorldOnB);
      c.a = static_cast<std::size_t>(swap ? b1->getUserIndex() : b0->getUserIndex());
      c.b = static_cast<std::size_t>(swap ? b0->getUserIndex() : b1->getUserIndex());
      c.normal = swap ? n : Eigen::Vector3d(-n);
      c.point_a = to_eigen(swap ? p.getPositionWorldOnB() : p.getPositionWorldOnA());
      c.point_b = to_eigen(swap ? p.getPositionWorldOnA() : p.getPositionWorldOnB());
      c.distance = p.getDistance();
      out.push_back(c);
    }
  }
  return out;
}

double DropWorld::deepest_penetration() const
{
  btDispatcher* d = impl_->world->getDispatcher();
  double deepest = 0;
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    const btPersistentManifold* m = d->getManifoldByIndexInternal(i);
    for (int k = 0; k < m->getNumContacts(); ++k) deepest = std::max(deepest, -double(m->getContactPoint(k).getDistance()));
  }
  return deepest;
}

std::int64_t DropWorld::broad_ns() const
{
  return impl_->world->broad_ns;
}

std::int64_t DropWorld::narrow_ns() const
{
  return impl_->world->narrow_ns;
}

}  // namespace statsim::tools::bullet
