// The Bullet methods of the benchmark (full, low, hull, spheres7, sphere) and the settings that
// make Bullet fair to a 20 cm body: bullet_drop_settings() chooses them, tools/bullet's drop world
// builds them, bullet_settings() lists every value for the report. The reasons are below.
//
// Settings (Bullet's defaults are tuned for 1 m bodies):
//  - margins 0.002 m (1% of the bunny's 0.2 m extent) on GImpact meshes, convex hulls and boxes,
//    instead of 0.04 m (20% of the body): a GImpact margin inflates every triangle, a hull's grows
//    the hull; a box's is inside its extents but rounds its corners. Spheres have none (the margin
//    is the radius).
//  - contact breaking threshold: left at gContactBreakingThreshold = 0.02 with Bullet's default
//    relative threshold (CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD), so manifolds break at 0.02 x
//    the shape's angular motion disc (the report prints the value for each shape);
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
#include "bullet/bullet.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace statsim::tools::bench {

namespace {
std::string fmt(const char* format, double a)
{
  char buf[256];
  std::snprintf(buf, sizeof buf, format, a);
  return buf;
}

std::vector<bullet::Shapes::Box> boxes_of(const Body3& body)
{
  std::vector<bullet::Shapes::Box> out;
  for (const Body3::Box& b : body.boxes) out.push_back({b.centre, b.rotation, b.half_extents});
  return out;
}
}  // namespace

class BulletShapes {
public:
  explicit BulletShapes(const Body3& body) : body_(body)
  {
    if (!body.full_indices.empty() && body.boxes.empty()) full_ = store_.mesh(body.full_vertices, body.full_indices);
    if (!body.boxes.empty()) full_ = store_.boxes(boxes_of(body));
    if (!body.low_indices.empty()) low_ = store_.mesh(body.low_vertices, body.low_indices);
    const std::vector<Eigen::Vector3d>& hv = hull_points(body);
    if (!hv.empty()) hull_ = store_.hull(hv);
    if (!body.spheres.empty()) spheres_ = store_.spheres(body.spheres);
    sphere_ = store_.sphere(body.sphere_radius);
  }

  /// Convex hull of the low mesh (bunny) or of the full mesh (box, lshape).
  static const std::vector<Eigen::Vector3d>& hull_points(const Body3& body)
  {
    return body.low_vertices.empty() ? body.full_vertices : body.low_vertices;
  }

  btCollisionShape* shape(const std::string& method) const
  {
    if (method == "full") return full_;
    if (method == "low") return low_;
    if (method == "hull") return hull_;
    if (method == "spheres7") return spheres_;
    if (method == "sphere") return sphere_;
    return nullptr;
  }
  const Body3& body() const { return body_; }

private:
  Body3 body_;
  bullet::Shapes store_;
  btCollisionShape* full_ = nullptr;
  btCollisionShape* low_ = nullptr;
  btCollisionShape* hull_ = nullptr;
  btCollisionShape* spheres_ = nullptr;
  btCollisionShape* sphere_ = nullptr;
};

namespace {

class BulletSim final : public Sim {
public:
  BulletSim(const std::vector<std::shared_ptr<BulletShapes>>& shapes, const std::vector<int>& of_body,
            const std::string& method, const bullet::DropSettings& settings,
            const std::vector<scenes::BodyState3>& states, double dt)
      : shapes_(shapes), of_body_(of_body), method_(method), dt_(dt)
  {
    std::vector<bullet::DropBody> kinds;
    for (const std::shared_ptr<BulletShapes>& sh : shapes) {
      const Body3& body = sh->body();
      bullet::DropBody b;
      b.shape = sh->shape(method);
      if (!b.shape) throw std::runtime_error("Bullet: no shape for method " + method + " of " + body.shape);
      b.mass = body.mass;
      b.inertia = body.inertia;
      b.bounding_radius = body.bounding_radius;
      kinds.push_back(b);
    }
    world_ = std::make_unique<bullet::DropWorld>(kinds, of_body, states, settings);
  }

  void step() override { world_->step(dt_); }
  PhaseTimes phases() const override { return PhaseTimes{world_->broad_ns(), world_->narrow_ns()}; }
  std::size_t asleep() const override { return world_->asleep_count(); }
  std::size_t body_count() const override { return world_->size(); }
  scenes::BodyState3 body_state(std::size_t i) const override { return world_->state(i); }
  bool body_asleep(std::size_t i) const override { return world_->asleep(i); }
  void place_body(std::size_t i, const scenes::BodyState3& s) override { world_->set_state(i, s); }
  EndState end_state() const override
  {
    EndState e;
    e.asleep = asleep();
    double z = 0;
    for (std::size_t i = 0; i < world_->size(); ++i) z += world_->state(i).position.z();
    e.mean_height = world_->size() == 0 ? 0.0 : z / static_cast<double>(world_->size());
    e.contacts = world_->touching_pairs();
    return e;
  }
  double kinetic_energy() const override
  {
    double ke = 0;
    for (std::size_t i = 0; i < world_->size(); ++i) {
      const Body3& body = body_of(i);
      const scenes::BodyState3 s = world_->state(i);
      const Eigen::Vector3d wb = s.orientation.conjugate() * s.angular_velocity;
      ke += 0.5 * body.mass * s.linear_velocity.squaredNorm() + 0.5 * wb.dot(body.inertia.cwiseProduct(wb));
    }
    return ke;
  }
  double overlap() const override { return world_->deepest_penetration(); }
  double lowest(std::size_t i) const override
  {
    const scenes::BodyState3 s = world_->state(i);
    return s.position.z() + lowest_offset(body_of(i), method_, s.orientation);
  }

private:
  const Body3& body_of(std::size_t i) const
  {
    return shapes_[of_body_.empty() ? 0 : static_cast<std::size_t>(of_body_[i])]->body();
  }

  std::vector<std::shared_ptr<BulletShapes>> shapes_;  // outlive the world, which points to their shapes
  std::vector<int> of_body_;
  std::string method_;
  double dt_;
  std::unique_ptr<bullet::DropWorld> world_;
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

double lowest_offset(const Body3& body, const std::string& method, const Eigen::Quaterniond& q)
{
  const Eigen::Matrix3d r = q.toRotationMatrix();
  double lo = std::numeric_limits<double>::infinity();
  if (method == "full" || method == "low" || method == "hull") {
    const auto& vs = method == "full" ? body.full_vertices
                                      : (method == "low" ? body.low_vertices : BulletShapes::hull_points(body));
    for (const auto& p : vs) lo = std::min(lo, r.row(2).dot(p));
  } else if (method == "spheres7") {
    for (const auto& s : body.spheres) lo = std::min(lo, r.row(2).dot(s.head<3>()) - s[3]);
  } else {
    lo = -body.sphere_radius;
  }
  return lo;
}

bullet::DropSettings bullet_drop_settings(const Body3& body, const std::string& method, const std::string& broadphase,
                                          const scenes::DropScene3& scene)
{
  bullet::DropSettings s;
  if (broadphase == "sap") {
    s.broad_phase = bullet::BroadPhase::sap;
    s.bounds_lo = scene.bounds_lo;
    s.bounds_hi = scene.bounds_hi;
  } else if (broadphase != "dbvt") {
    throw std::runtime_error("Bullet: unknown broad phase " + broadphase);
  }
  s.restitution = body.surface.restitution;
  s.friction = body.surface.friction;
  s.rolling_resistance = body.surface.rolling_resistance;
  s.rolling_radius = method == "sphere" ? body.sphere_radius : 0.0;
  s.restitution_threshold = body.surface.restitution_threshold;
  s.sleep_speed = body.surface.sleep_speed;
  s.sleep_time = body.surface.sleep_time;
  s.update_all_aabbs = false;
  return s;
}

std::unique_ptr<Sim> make_bullet(const std::shared_ptr<BulletShapes>& shapes, const std::string& method,
                                 const bullet::DropSettings& settings, const std::vector<scenes::BodyState3>& states,
                                 double dt)
{
  return std::make_unique<BulletSim>(std::vector<std::shared_ptr<BulletShapes>>{shapes}, std::vector<int>{}, method,
                                     settings, states, dt);
}

std::unique_ptr<Sim> make_bullet_mixed(const std::vector<std::shared_ptr<BulletShapes>>& shapes,
                                       const std::vector<int>& of_body, const std::string& method,
                                       const bullet::DropSettings& settings,
                                       const std::vector<scenes::BodyState3>& states, double dt)
{
  return std::make_unique<BulletSim>(shapes, of_body, method, settings, states, dt);
}

std::unique_ptr<Sim> make_bullet(const std::shared_ptr<BulletShapes>& shapes, const std::string& method,
                                 const std::string& broadphase, const scenes::DropScene3& scene, double dt)
{
  return make_bullet(shapes, method, bullet_drop_settings(shapes->body(), method, broadphase, scene), scene.bodies,
                     dt);
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
                  bullet::kMargin));
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
