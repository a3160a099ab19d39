// Bullet's side is tools/bullet's drop world with the settings of `statsim bench` (the reasons are
// in tools/bench/bench_bullet.cpp): the table's material, statsim's restitution threshold and sleep
// thresholds, the full mesh's principal moments scaled to the table's mass, btDbvtBroadphase.
// Differences: AABBs of sleeping bodies are updated (Bullet's default), and every 1/60 s frame is
// 4 internal steps, since this run is the picture of the truth.
#include "render/reference_run.hpp"

#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "bullet/drop_world.hpp"
#include "render/frames.hpp"
#include "scenes/body_def.hpp"
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
using RunWorld = World3<kCapacity>;

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
  if (!o.hull_contacts && o.engine != "statsim") {
    error = "--body-contacts is statsim's (Bullet touches at its meshes)";
    return false;
  }
  if (o.substeps < 1 || o.substeps > 256) {
    error = "--substeps must be in 1..256";
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
    if (!o.hull_contacts) def.body_contacts = BodyContacts::collision_spheres;
    // A world of its own for every run (large: on the heap, not the stack), so that a run never
    // sees the bodies of the one before.
    const auto world = std::make_unique<RunWorld>(def);
    RunWorld& w = *world;
    const Status configured = w.construction_status();
    const Added<ShapeId> added = w.add_shape(sig);
    if (configured != Status::ok || !added.ok() || !w.add_plane(Vector3(0, 0, 1), 0).ok()) {
      error = "statsim world set-up failed";
      return false;
    }
    const ShapeId shape = added.id;
    for (const scenes::BodyState3& s : scene.bodies) {
      BodyDef3 b = scenes::body_def(s);
      b.shape = shape;
      b.mass = sig.mass;
      if (!w.add_body(b).ok()) {
        error = "statsim add_body failed";
        return false;
      }
    }
    for (int s = 0; s < steps; ++s) {
      if (w.step(Scalar(dt)).status != Status::ok) {
        error = "statsim step failed";
        return false;
      }
      if (s % o.every != 0) continue;
      for (std::uint32_t i = 0; i < w.body_count(); ++i) {
        const Body3& b = w.body(i);
        write_frame_row(out.f, s, double(s + 1) * dt, int(i), "bunny", b.position.cast<double>(),
                        b.orientation.cast<double>(), int(b.state), double(b.radius));
      }
    }
    std::printf("reference-run: %s, statsim (tables/bunny.hpp), %d steps of 1/60 s, %u of %u asleep -> %s\n",
                o.scene.c_str(), steps, w.count(MotionState::asleep), w.body_count(), o.frames.c_str());
    return true;
  }

  // Bullet: the full bunny mesh as one shared GImpact shape, the table's material and the statsim
  // world's thresholds.
  std::vector<int> indices;
  for (const auto& t : mesh.triangles) indices.insert(indices.end(), {t[0], t[1], t[2]});
  bullet::Shapes shapes;
  bullet::DropBody body;
  body.shape = shapes.mesh(mesh.vertices, indices);
  body.mass = double(sig.mass);
  const double scale = double(sig.mass) / mp.mass;
  body.inertia = Eigen::Vector3d(mp.principal_moments.x() * scale, mp.principal_moments.y() * scale,
                                 mp.principal_moments.z() * scale);
  body.bounding_radius = mp.bounding_radius;
  bullet::DropSettings settings;
  settings.restitution = double(sig.material.restitution);
  settings.friction = double(sig.material.friction);
  settings.restitution_threshold = double(defaults.restitution_threshold);
  settings.sleep_speed = double(defaults.sleep_speed);
  settings.sleep_time = double(defaults.sleep_time);
  bullet::DropWorld world(body, scene.bodies, settings);
  std::size_t asleep = 0;
  for (int s = 0; s < steps; ++s) {
    world.step(dt, o.substeps);
    if (s % o.every != 0) continue;
    asleep = 0;
    for (std::size_t i = 0; i < world.size(); ++i) {
      const scenes::BodyState3 b = world.state(i);
      const bool sleeping = world.asleep(i);
      asleep += sleeping ? 1 : 0;
      write_frame_row(out.f, s, double(s + 1) * dt, int(i), "bunny", b.position, b.orientation, sleeping ? 2 : 0, 0.0);
    }
  }
  std::printf("reference-run: %s, Bullet (full bunny mesh, GImpact), %d steps of 1/60 s (%d substeps), %zu of %zu "
              "asleep at the last written frame -> %s\n",
              o.scene.c_str(), steps, o.substeps, asleep, world.size(), o.frames.c_str());
  return true;
}

}  // namespace statsim::tools::render
