// The Bullet methods of the benchmark (full, low, hull, spheres7, sphere) and the settings that
// make Bullet fair to a 20 cm body. Every value set here is listed by bullet_settings(), which the
// report prints; the reasons are in the comments below.
//
// Settings (Bullet's defaults are tuned for 1 m bodies):
//  - margins 0.002 m (1% of the bunny's 0.2 m extent) on GImpact meshes, convex hulls and boxes,
//    instead of 0.04 m (20% of the body): a GImpact margin inflates every triangle, a hull's grows
//    the hull; a box's is inside its extents but rounds its corners. Spheres have none (the margin
//    is the radius).
//  - contact breaking threshold: left at gContactBreakingThreshold = 0.02 with Bullet's default
//    relative threshold (CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD), so manifolds break at 0.02 x
//    the shape's angular motion disc (about 3 to 4 mm for the bunny; the report prints the value);
//    Bullet also pads every AABB by the 0.02 m.
//  - sleeping: linear threshold = statsim's sleep_speed (0.05 m/s, Bullet default 0.8), angular
//    threshold = sleep_speed / bounding radius (statsim compares |w| R with sleep_speed; Bullet
//    default 1 rad/s), gDeactivationTime = statsim's sleep_time (0.5 s, default 2 s). Bullet
//    puts whole islands to sleep, statsim single bodies.
//  - material: restitution e and friction mu of the statistical table; Bullet multiplies the two
//    bodies' values, so every body and the ground get sqrt(e) and sqrt(mu): every contact then
//    has exactly e and mu. Restitution below the statsim world's restitution threshold (0.5 m/s)
//    is dropped (m_restitutionVelocityThreshold; default 0.2).
//  - rolling friction, `sphere` only (a ball rolls for ever without it; the other shapes stop by
//    their geometry): Bullet limits the rolling torque to (combined coefficient) x normal force,
//    combined = rolling_a friction_b + rolling_b friction_a; statsim's rolling resistance c takes
//    c x normal impulse off the contact point's rolling speed, a torque arm of c r. The sphere
//    gets rolling friction c r / sqrt(mu) so that against the ground the combined value is c r.
//  - mass and inertia: the full mesh's (principal moments about the centre of mass, density
//    1000 kg/m^3 scaled to the table's mass) for every representation, so only the collision
//    shape differs between methods.
//  - solver: btSequentialImpulseConstraintSolver with its defaults (10 iterations, split impulse,
//    warm starting); gravity (0, 0, -9.81); no CCD; one internal step of dt per call
//    (stepSimulation(dt, 0): no substeps, no interpolation).
//  - collision configuration: pools for max(4096, 4 N) manifolds and algorithms (the default
//    4096 falls back to malloc for bigger scenes); setForceUpdateAllAabbs(false) (Bullet's own
//    optimisation: AABBs of sleeping and static objects are not recomputed; safe here, nothing
//    static moves).
//  - broad phase: `sap` = btAxisSweep3 (16-bit sweep-and-prune; bt32BitAxisSweep3 above 16,000
//    bodies) with the scene's world bounds, maxHandles N + 2; `dbvt` = btDbvtBroadphase (default).
//  - ground: btStaticPlaneShape z = 0.
//  - GImpact: btGImpactCollisionAlgorithm registered on the dispatcher; one shape shared by all
//    bodies (its BVH is in the body frame).
#include "bench/bench_internal.hpp"
#include "bench/bullet.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace statsim::tools::bench {

namespace {
constexpr double kMargin = 0.002;
constexpr double kGravity = 9.81;

btVector3 bt(const Eigen::Vector3d& v)
{
  return btVector3(v.x(), v.y(), v.z());
}

std::string fmt(const char* format, double a)
{
  char buf[256];
  std::snprintf(buf, sizeof buf, format, a);
  return buf;
}
}  // namespace

class BulletShapes {
public:
  explicit BulletShapes(const Body3& body) : body_(body)
  {
    ground_ = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0);
    if (!body.full_indices.empty() && body.boxes.empty()) {
      full_ = make_gimpact(body.full_vertices, body.full_indices, full_v_, full_i_, full_array_);
    }
    if (!body.boxes.empty()) full_box_ = make_boxes(body.boxes);
    if (!body.low_indices.empty()) low_ = make_gimpact(body.low_vertices, body.low_indices, low_v_, low_i_, low_array_);
    // Convex hull of the low mesh (bunny) or of the full mesh (box, lshape).
    const std::vector<Eigen::Vector3d>& hv = body.low_vertices.empty() ? body.full_vertices : body.low_vertices;
    if (!hv.empty()) {
      hull_ = std::make_unique<btConvexHullShape>();
      for (const auto& p : hv) hull_->addPoint(bt(p), false);
      hull_->recalcLocalAabb();
      hull_->setMargin(kMargin);
    }
    if (!body.spheres.empty()) {
      spheres_ = std::make_unique<btCompoundShape>();
      for (const auto& s : body.spheres) {
        sphere_children_.push_back(std::make_unique<btSphereShape>(s[3]));
        btTransform t;
        t.setIdentity();
        t.setOrigin(btVector3(s[0], s[1], s[2]));
        spheres_->addChildShape(t, sphere_children_.back().get());
      }
    }
    sphere_ = std::make_unique<btSphereShape>(body.sphere_radius);
    inertia_ = bt(body.inertia);
  }

  btCollisionShape* shape(const std::string& method) const
  {
    if (method == "full") return full_box_ ? full_box_.get() : static_cast<btCollisionShape*>(full_.get());
    if (method == "low") return low_.get();
    if (method == "hull") return hull_.get();
    if (method == "spheres7") return spheres_.get();
    if (method == "sphere") return sphere_.get();
    return nullptr;
  }
  btCollisionShape* ground() const { return ground_.get(); }
  const Body3& body() const { return body_; }
  const btVector3& inertia() const { return inertia_; }

private:
  std::unique_ptr<btGImpactMeshShape> make_gimpact(const std::vector<Eigen::Vector3d>& vertices,
                                                   const std::vector<int>& indices, std::vector<btScalar>& v,
                                                   std::vector<int>& i,
                                                   std::unique_ptr<btTriangleIndexVertexArray>& array)
  {
    for (const auto& p : vertices) v.insert(v.end(), {p.x(), p.y(), p.z()});
    i = indices;
    array = std::make_unique<btTriangleIndexVertexArray>(static_cast<int>(i.size() / 3), i.data(),
                                                         static_cast<int>(3 * sizeof(int)),
                                                         static_cast<int>(vertices.size()), v.data(),
                                                         static_cast<int>(3 * sizeof(btScalar)));
    auto shape = std::make_unique<btGImpactMeshShape>(array.get());
    shape->setMargin(kMargin);
    shape->updateBound();
    return shape;
  }

  std::unique_ptr<btCollisionShape> make_boxes(const std::vector<Body3::Box>& boxes)
  {
    const bool single = boxes.size() == 1 && boxes[0].centre.norm() < 1e-12 &&
                        (boxes[0].rotation - Eigen::Matrix3d::Identity()).norm() < 1e-12;
    if (single) {
      auto box = std::make_unique<btBoxShape>(bt(boxes[0].half_extents));
      box->setMargin(kMargin);
      return box;
    }
    auto compound = std::make_unique<btCompoundShape>();
    for (const auto& b : boxes) {
      box_children_.push_back(std::make_unique<btBoxShape>(bt(b.half_extents)));
      box_children_.back()->setMargin(kMargin);
      const Eigen::Matrix3d& r = b.rotation;
      btMatrix3x3 basis(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
      compound->addChildShape(btTransform(basis, bt(b.centre)), box_children_.back().get());
    }
    return compound;
  }

  Body3 body_;
  std::vector<btScalar> full_v_, low_v_;
  std::vector<int> full_i_, low_i_;
  std::unique_ptr<btTriangleIndexVertexArray> full_array_, low_array_;
  std::unique_ptr<btGImpactMeshShape> full_, low_;
  std::unique_ptr<btCollisionShape> full_box_;
  std::vector<std::unique_ptr<btBoxShape>> box_children_;
  std::unique_ptr<btConvexHullShape> hull_;
  std::unique_ptr<btCompoundShape> spheres_;
  std::vector<std::unique_ptr<btSphereShape>> sphere_children_;
  std::unique_ptr<btSphereShape> sphere_;
  std::unique_ptr<btStaticPlaneShape> ground_;
  btVector3 inertia_;
};

namespace {

/// btDiscreteDynamicsWorld with the collision phase timed: the same calls as
/// btCollisionWorld::performDiscreteCollisionDetection (update AABBs, find overlapping pairs,
/// dispatch the pairs to the narrow phase), with a clock read between them.
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
    phases.broad += elapsed_ns(t0, t1);
    phases.narrow += elapsed_ns(t1, t2);
  }

  PhaseTimes phases{0, 0};
};

class BulletSim final : public Sim {
public:
  BulletSim(const std::shared_ptr<BulletShapes>& shapes, const std::string& method, const std::string& broadphase,
            const scenes::DropScene3& scene, double dt)
      : shapes_(shapes), dt_(dt)
  {
    const Body3& body = shapes->body();
    btCollisionShape* shape = shapes->shape(method);
    if (!shape) throw std::runtime_error("Bullet: no shape for method " + method);
    const int n = static_cast<int>(scene.bodies.size());

    btDefaultCollisionConstructionInfo cci;
    cci.m_defaultMaxPersistentManifoldPoolSize = std::max(4096, 4 * n);
    cci.m_defaultMaxCollisionAlgorithmPoolSize = std::max(4096, 4 * n);
    config_ = std::make_unique<btDefaultCollisionConfiguration>(cci);
    dispatcher_ = std::make_unique<btCollisionDispatcher>(config_.get());
    btGImpactCollisionAlgorithm::registerAlgorithm(dispatcher_.get());
    if (broadphase == "sap") {
      if (n + 2 <= 16000)
        broadphase_ = std::make_unique<btAxisSweep3>(bt(scene.bounds_lo), bt(scene.bounds_hi),
                                                     static_cast<unsigned short>(n + 2));
      else
        broadphase_ = std::make_unique<bt32BitAxisSweep3>(bt(scene.bounds_lo), bt(scene.bounds_hi),
                                                          static_cast<unsigned int>(n + 2));
    } else if (broadphase == "dbvt") {
      broadphase_ = std::make_unique<btDbvtBroadphase>();
    } else {
      throw std::runtime_error("Bullet: unknown broad phase " + broadphase);
    }
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<TimedWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(), config_.get());
    world_->setGravity(btVector3(0, 0, -kGravity));
    world_->setForceUpdateAllAabbs(false);
    world_->getSolverInfo().m_restitutionVelocityThreshold = body.surface.restitution_threshold;
    gDeactivationTime = body.surface.sleep_time;

    const double friction = std::sqrt(body.surface.friction);
    const double restitution = std::sqrt(body.surface.restitution);
    {
      btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shapes->ground());
      info.m_friction = friction;
      info.m_restitution = restitution;
      ground_ = std::make_unique<btRigidBody>(info);
      world_->addRigidBody(ground_.get());
    }
    const double rolling = method == "sphere" && friction > 0
                               ? body.surface.rolling_resistance * body.sphere_radius / friction
                               : 0.0;
    bodies_.reserve(scene.bodies.size());
    for (const scenes::BodyState3& s : scene.bodies) {
      btRigidBody::btRigidBodyConstructionInfo info(body.mass, nullptr, shape, shapes->inertia());
      info.m_friction = friction;
      info.m_restitution = restitution;
      info.m_rollingFriction = rolling;
      info.m_linearSleepingThreshold = body.surface.sleep_speed;
      info.m_angularSleepingThreshold = body.surface.sleep_speed / body.bounding_radius;
      const Eigen::Quaterniond& q = s.orientation;
      info.m_startWorldTransform = btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), bt(s.position));
      auto rb = std::make_unique<btRigidBody>(info);
      rb->setLinearVelocity(bt(s.linear_velocity));
      rb->setAngularVelocity(bt(s.angular_velocity));
      world_->addRigidBody(rb.get());
      bodies_.push_back(std::move(rb));
    }
  }

  ~BulletSim() override
  {
    // The world's destructor removes the proxies of its objects; the bodies go after it.
    world_.reset();
  }

  void step() override
  {
    world_->phases = PhaseTimes{0, 0};
    world_->stepSimulation(dt_, 0);
  }
  PhaseTimes phases() const override { return world_->phases; }
  std::size_t asleep() const override
  {
    std::size_t k = 0;
    for (const auto& b : bodies_) k += b->getActivationState() == ISLAND_SLEEPING;
    return k;
  }
  std::size_t body_count() const override { return bodies_.size(); }
  scenes::BodyState3 body_state(std::size_t i) const override
  {
    const btRigidBody& b = *bodies_[i];
    const btVector3& p = b.getCenterOfMassPosition();
    const btQuaternion q = b.getOrientation();
    const btVector3& v = b.getLinearVelocity();
    const btVector3& w = b.getAngularVelocity();
    scenes::BodyState3 s;
    s.position = Eigen::Vector3d(p.x(), p.y(), p.z());
    s.orientation = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z());
    s.linear_velocity = Eigen::Vector3d(v.x(), v.y(), v.z());
    s.angular_velocity = Eigen::Vector3d(w.x(), w.y(), w.z());
    return s;
  }
  bool body_asleep(std::size_t i) const override { return bodies_[i]->getActivationState() == ISLAND_SLEEPING; }
  EndState end_state() const override
  {
    EndState e;
    e.asleep = asleep();
    double z = 0;
    for (const auto& b : bodies_) z += b->getCenterOfMassPosition().z();
    e.mean_height = bodies_.empty() ? 0.0 : z / static_cast<double>(bodies_.size());
    btDispatcher* d = world_->getDispatcher();
    for (int i = 0; i < d->getNumManifolds(); ++i)
      e.contacts += d->getManifoldByIndexInternal(i)->getNumContacts() > 0;
    return e;
  }

private:
  std::shared_ptr<BulletShapes> shapes_;
  double dt_;
  std::unique_ptr<btDefaultCollisionConfiguration> config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btRigidBody> ground_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::unique_ptr<TimedWorld> world_;  // destroyed first (declared last), see ~BulletSim
};

}  // namespace

std::shared_ptr<BulletShapes> make_bullet_shapes(const Body3& body)
{
  return std::make_shared<BulletShapes>(body);
}

bool bullet_supports(const BulletShapes& shapes, const std::string& method, std::string& why_not)
{
  if (shapes.shape(method)) return true;
  if (method == "low") why_not = "no low-resolution mesh for " + shapes.body().shape;
  else if (method == "spheres7") why_not = "no sphere set for " + shapes.body().shape;
  else why_not = "no Bullet shape for " + method;
  return false;
}

std::unique_ptr<Sim> make_bullet(const std::shared_ptr<BulletShapes>& shapes, const std::string& method,
                                 const std::string& broadphase, const scenes::DropScene3& scene, double dt)
{
  return std::make_unique<BulletSim>(shapes, method, broadphase, scene, dt);
}

std::vector<std::string> bullet_settings(const Body3& body)
{
  std::vector<std::string> s;
  s.push_back("Bullet 3.24 (Debian libbullet-dev, double-precision build: tools/ref3d links it into the same "
              "executable; no SSE paths on Linux in either build)");
  s.push_back("Bullet solver: btSequentialImpulseConstraintSolver, defaults (10 iterations, split impulse, warm "
              "starting); gravity (0, 0, -9.81) m/s^2; no CCD; stepSimulation(dt, 0) = one internal step of dt");
  s.push_back(fmt("Bullet margins: %.3g m on GImpact meshes, convex hulls and boxes (default 0.04); spheres: "
                  "none (the radius)",
                  kMargin));
  {
    // The contact breaking threshold Bullet will use for this body's manifolds.
    BulletShapes shapes(body);
    std::string line = fmt("Bullet contact breaking threshold: gContactBreakingThreshold = %.3g m (default), "
                           "relative to each shape: ",
                           double(gContactBreakingThreshold));
    for (const char* m : {"full", "low", "hull", "spheres7", "sphere"}) {
      const btCollisionShape* sh = shapes.shape(m);
      if (!sh) continue;
      line += std::string(" ") + m + " " +
              fmt("%.2f mm", 1e3 * double(sh->getContactBreakingThreshold(gContactBreakingThreshold)));
    }
    line += "; AABBs padded by 0.02 m";
    s.push_back(line);
  }
  s.push_back(fmt("Bullet sleeping: linear threshold %.3g m/s (default 0.8), ", body.surface.sleep_speed) +
              fmt("angular threshold %.3g rad/s (= sleep speed / bounding radius; default 1), ",
                  body.surface.sleep_speed / body.bounding_radius) +
              fmt("gDeactivationTime %.3g s (default 2); Bullet sleeps whole islands", body.surface.sleep_time));
  s.push_back(fmt("Bullet material: friction sqrt(%.3g) ", body.surface.friction) +
              fmt("and restitution sqrt(%.3g) on bodies and ground (Bullet multiplies: every contact gets the "
                  "table's values); ",
                  body.surface.restitution) +
              fmt("restitution velocity threshold %.3g m/s (default 0.2)", body.surface.restitution_threshold));
  s.push_back(fmt("Bullet rolling friction (sphere only): %.4g m ",
                  body.surface.friction > 0
                      ? body.surface.rolling_resistance * body.sphere_radius / std::sqrt(body.surface.friction)
                      : 0.0) +
              fmt("(= statsim rolling resistance %.3g x radius / sqrt(friction))", body.surface.rolling_resistance));
  s.push_back(fmt("Bullet bodies: mass %.4g kg, ", body.mass) +
              fmt("principal moments (%.4g, ", body.inertia.x()) + fmt("%.4g, ", body.inertia.y()) +
              fmt("%.4g) kg m^2 for every representation", body.inertia.z()));
  s.push_back(fmt("Bullet sphere method: radius %.4g m, ", body.sphere_radius) + body.sphere_radius_note);
  s.push_back("Bullet pools: max(4096, 4 N) persistent manifolds and collision algorithms; "
              "setForceUpdateAllAabbs(false); ground btStaticPlaneShape z = 0");
  s.push_back("Bullet broad phases: sap = btAxisSweep3 (16-bit; bt32BitAxisSweep3 above 16000 bodies), world "
              "bounds from the scene, maxHandles N + 2; dbvt = btDbvtBroadphase (Bullet's default)");
  s.push_back("Bullet shapes: full = btGImpactMeshShape of the full mesh; low = btGImpactMeshShape of the "
              "~100-vertex mesh; hull = btConvexHullShape of the ~100-vertex mesh's vertices; spheres7 = "
              "btCompoundShape of 7 btSphereShape; sphere = btSphereShape; box = btBoxShape, lshape = "
              "btCompoundShape of 2 btBoxShape");
  s.push_back("Bullet timing: collision = updateAabbs + computeOverlappingPairs (broad) + "
              "dispatchAllCollisionPairs (narrow), timed inside performDiscreteCollisionDetection; response = "
              "the rest of the step (gravity, integration, islands, constraint solver, sleeping)");
  return s;
}

}  // namespace statsim::tools::bench
