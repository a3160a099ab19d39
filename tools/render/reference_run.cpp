// Bullet's side uses the settings of `statsim bench` (tools/bench/bench_bullet.cpp, read there for
// the reasons): margin 0.002 m, sqrt of the table's restitution and friction on every body and the
// ground (Bullet multiplies the two), statsim's restitution threshold and sleep thresholds, the
// full mesh's principal moments scaled to the table's mass, btDbvtBroadphase, the sequential
// impulse solver with its defaults. One difference: 4 internal steps of 1/240 s per 1/60 s frame,
// since this run is the picture of the truth (GImpact at 1/60 s lets fast bunnies sink).
#include "render/reference_run.hpp"

#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "ref3d/bullet.hpp"
#include "render/frames.hpp"
#include "scenes/scenes.hpp"
#include "statsim/world3.hpp"
#include "tables/bunny.hpp"

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace statsim::tools::render {

namespace {

constexpr std::uint32_t kCapacity = 4096;
World3<kCapacity> g_world;  // large: kept out of the stack

struct Written {
  std::FILE* f = nullptr;
  ~Written()
  {
    if (f) std::fclose(f);
  }
};

}  // namespace

bool reference_run(const ReferenceRunOptions& o, std::string& error)
{
  const std::string prefix = "bunnies";
  if (o.scene.compare(0, prefix.size(), prefix) != 0 || o.scene.size() == prefix.size()) {
    error = "unknown scene '" + o.scene + "' (bunniesN, e.g. bunnies50)";
    return false;
  }
  const long n = std::strtol(o.scene.c_str() + prefix.size(), nullptr, 10);
  if (n < 1 || n > long(kCapacity)) {
    error = "scene '" + o.scene + "': N must be 1.." + std::to_string(kCapacity);
    return false;
  }
  if (o.engine != "bullet" && o.engine != "statsim") {
    error = "unknown engine '" + o.engine + "' (bullet, statsim)";
    return false;
  }
  if (o.every < 1 || !(o.seconds > 0)) {
    error = "--every must be >= 1 and --seconds > 0";
    return false;
  }
  const SignatureView<3> sig = tables::bunny.view();
  TriMesh raw;
  MeshError me;
  if (!load_obj(o.meshes_dir + "/bunny.obj", raw, me)) {
    error = me.message;
    return false;
  }
  const MassProperties mp = compute_mass_properties(raw, 1000.0);
  const TriMesh mesh = to_body_frame(raw, mp);

  scenes::DropOptions drop;
  drop.count = int(n);
  drop.bounding_radius = double(sig.bounding_radius);
  drop.seed = o.seed;
  const scenes::DropScene3 scene = scenes::drop_scene3(drop);

  Written out;
  out.f = std::fopen(o.frames.c_str(), "w");
  if (!out.f) {
    error = o.frames + ": cannot write";
    return false;
  }
  std::fprintf(out.f, "%s\n", frames_header());
  const double dt = 1.0 / 60;
  const int steps = int(std::lround(o.seconds / dt));
  const WorldDef3 defaults{};

  if (o.engine == "statsim") {
    WorldDef3 def;
    def.seed = o.seed;
    const Status configured = g_world.configure(def);
    const Added<ShapeId> added = g_world.add_shape(sig);
    if (configured != Status::ok || !added.ok() || !g_world.add_plane(Vector3(0, 0, 1), 0).ok()) {
      error = "statsim world set-up failed";
      return false;
    }
    const ShapeId shape = added.id;
    for (const scenes::BodyState3& s : scene.bodies) {
      BodyDef3 b;
      b.position = s.position.cast<Scalar>();
      b.orientation = s.orientation.cast<Scalar>().normalized();
      b.linear_velocity = s.linear_velocity.cast<Scalar>();
      b.angular_velocity = s.angular_velocity.cast<Scalar>();
      b.shape = shape;
      b.mass = sig.mass;
      if (!g_world.add_body(b).ok()) {
        error = "statsim add_body failed";
        return false;
      }
    }
    for (int s = 0; s < steps; ++s) {
      if (g_world.step(Scalar(dt)).status != Status::ok) {
        error = "statsim step failed";
        return false;
      }
      if (s % o.every != 0) continue;
      for (std::uint32_t i = 0; i < g_world.body_count(); ++i) {
        const Body3& b = g_world.body(i);
        write_frame_row(out.f, s, double(s + 1) * dt, int(i), "bunny", b.position.cast<double>(),
                        b.orientation.cast<double>(), int(b.state), double(b.radius));
      }
    }
    std::printf("reference-run: %s, statsim (tables/bunny.hpp), %d steps of 1/60 s, %u of %u asleep -> %s\n",
                o.scene.c_str(), steps, g_world.count(MotionState::asleep), g_world.body_count(), o.frames.c_str());
    return true;
  }

  // Bullet: the full bunny mesh as one shared btGImpactMeshShape.
  std::vector<btScalar> vertices;
  std::vector<int> indices;
  for (const Eigen::Vector3d& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
  for (const auto& t : mesh.triangles) indices.insert(indices.end(), {t[0], t[1], t[2]});
  btTriangleIndexVertexArray array(int(mesh.triangles.size()), indices.data(), int(3 * sizeof(int)),
                                   int(mesh.vertices.size()), vertices.data(), int(3 * sizeof(btScalar)));
  btGImpactMeshShape shape(&array);
  shape.setMargin(0.002);
  shape.updateBound();
  btStaticPlaneShape ground_shape(btVector3(0, 0, 1), 0);
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, 0, -9.81));
  world.getSolverInfo().m_restitutionVelocityThreshold = double(defaults.restitution_threshold);
  gDeactivationTime = double(defaults.sleep_time);
  const double friction = std::sqrt(double(sig.material.friction));
  const double restitution = std::sqrt(double(sig.material.restitution));
  btRigidBody::btRigidBodyConstructionInfo ground_info(0, nullptr, &ground_shape);
  ground_info.m_friction = friction;
  ground_info.m_restitution = restitution;
  btRigidBody ground(ground_info);
  world.addRigidBody(&ground);
  const double scale = double(sig.mass) / mp.mass;
  const btVector3 inertia(mp.principal_moments.x() * scale, mp.principal_moments.y() * scale,
                          mp.principal_moments.z() * scale);
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  for (const scenes::BodyState3& s : scene.bodies) {
    btRigidBody::btRigidBodyConstructionInfo info(double(sig.mass), nullptr, &shape, inertia);
    info.m_friction = friction;
    info.m_restitution = restitution;
    info.m_linearSleepingThreshold = double(defaults.sleep_speed);
    info.m_angularSleepingThreshold = double(defaults.sleep_speed) / mp.bounding_radius;
    const Eigen::Quaterniond& q = s.orientation;
    info.m_startWorldTransform = btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()),
                                             btVector3(s.position.x(), s.position.y(), s.position.z()));
    bodies.push_back(std::make_unique<btRigidBody>(info));
    bodies.back()->setLinearVelocity(btVector3(s.linear_velocity.x(), s.linear_velocity.y(), s.linear_velocity.z()));
    bodies.back()->setAngularVelocity(
        btVector3(s.angular_velocity.x(), s.angular_velocity.y(), s.angular_velocity.z()));
    world.addRigidBody(bodies.back().get());
  }
  std::size_t asleep = 0;
  for (int s = 0; s < steps; ++s) {
    world.stepSimulation(dt, 4, dt / 4);
    if (s % o.every != 0) continue;
    asleep = 0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const btTransform& t = bodies[i]->getWorldTransform();
      const btQuaternion q = t.getRotation();
      const bool sleeping = bodies[i]->getActivationState() == ISLAND_SLEEPING;
      asleep += sleeping ? 1 : 0;
      write_frame_row(out.f, s, double(s + 1) * dt, int(i), "bunny",
                      Eigen::Vector3d(t.getOrigin().x(), t.getOrigin().y(), t.getOrigin().z()),
                      Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()), sleeping ? 2 : 0, 0.0);
    }
  }
  for (auto& b : bodies) world.removeRigidBody(b.get());
  world.removeRigidBody(&ground);
  std::printf("reference-run: %s, Bullet (full bunny mesh, GImpact), %d steps of 1/60 s (4 substeps), %zu of %zu "
              "asleep at the last written frame -> %s\n",
              o.scene.c_str(), steps, asleep, bodies.size(), o.frames.c_str());
  return true;
}

}  // namespace statsim::tools::render
