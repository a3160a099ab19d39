// The web page's live scene (examples/web): bodies of one shape poured onto the ground from a
// column above it, in worlds of fixed capacity (10,000 bodies) in static storage. Built to
// WebAssembly (statsim.wasm) it exports the C functions below to the page's script (app.js);
// built for the host with WEB_DEMO_MAIN (web_demo_host) it runs the same scene from the command
// line, so that the page's step times and state hash can be set beside the native ones:
//   web_demo_host [--shape bunny|box|lshape|square] [--n N] [--steps S] [--seed S] [--no-rest] [--warmup W]
// prints "web_demo SHAPE bodies N steps S ms_per_step T asleep A hash 0x...". The timed pour
// follows an untimed one of W steps (default 60), as the page's does: a browser first runs
// WebAssembly from a quickly compiled baseline and swaps in optimised code while it runs.
//
// The pour draws from the runtime's Pcg32 with arithmetic only (no trigonometry, whose library
// rounding differs between the host's libm and emscripten's), so a host build and the wasm build
// compute the same bits.

#include <statsim/config.hpp>
#ifdef __EMSCRIPTEN__
// Eigen's own assertion handler prints through stdio, which the wasm does not link.
#define eigen_assert(x) STATSIM_ASSERT(x)
#define EIGEN_NO_IO
#endif
#include <statsim/mesh_pose.hpp>
#include <statsim/queries.hpp>
#include <statsim/snapshot.hpp>
#include <statsim/world2.hpp>
#include <statsim/world3.hpp>
#include <tables/box.hpp>
#include <tables/bunny.hpp>
#include <tables/lshape.hpp>
#include <tables/square2d.hpp>

#include <cmath>
#include <cstdint>
#include <new>

namespace {

constexpr std::uint32_t capacity = 10000;
// Candidate pairs per body: a bunny's bounding radius is over twice the height it rests at, so
// its piles have many more candidate pairs per body than piles of boxes
// (examples/firmware/README.md). Planes: the ground and a bin's four walls. The impact buffer
// holds what the page flashes; recording impacts only reads the world (same bits without it).
constexpr std::uint32_t max_impacts = 64;
using World3 = statsim::World3<capacity, 5, 8 * capacity, 1, max_impacts>;
using World2 = statsim::World2<capacity, 3, 3 * capacity, 1, max_impacts>;
World3 world3;
World2 world2;

/// Scenes, in the order of the page's menu (set by `demo_configure` for the next reset).
enum Scene : int { pour = 0, bin = 1, column = 2, heap = 3 };
/// Body-body models: the library's default (hulls where the tables have the data), or the
/// paper's collision spheres.
enum Model : int { model_default = 0, model_spheres = 1 };
int scene = pour;
int model = model_default;
/// Heap scene: bodies waiting asleep above the nozzle, released one a step in slot order.
std::uint32_t heap_bodies = 0, heap_released = 0;
float heap_cell = 0, heap_nozzle = 0;
statsim::Pcg32 heap_rng(1, 4);
std::uint32_t current_seed = 1;
bool current_rest = true;
/// Draws of spawned bodies and of removals: a stream of their own, so that the pour's bits do
/// not depend on them.
statsim::Pcg32 extra_rng(1, 3);

/// Snapshot storage, one per dimension (a world's snapshot is at most this size).
unsigned char snapshot3[statsim::snapshot_capacity<3>(capacity, 5, 1)];
unsigned char snapshot2[statsim::snapshot_capacity<2>(capacity, 3, 1)];
std::size_t snapshot_bytes = 0;
int snapshot_shape = -1;
std::uint32_t snapshot_released = 0;  // the heap's release count when saved

/// Shapes, in the order of the page's menu.
enum Shape : int { bunny = 0, box = 1, lshape = 2, square = 3 };

/// What the page draws: per live body the model matrix of its shape's mesh (3 rows of 4: the
/// mesh-to-world map of `statsim::mesh_to_world`; a 2D body's plane x, y drawn as the 3D x, z),
/// then its drawing class (`draw_class`), its slot, and two unused floats.
constexpr int stride = 16;
float transforms[capacity * stride];
std::uint32_t drawn = 0;
/// Per impact of the last step: the point (x, y, z, in the page's 3D frame) and the speed, m/s.
float impacts[max_impacts * 4];

int current = bunny;

const statsim::SignatureView<3> signature3(int shape)
{
  return shape == box ? statsim::tables::box.view() : shape == lshape ? statsim::tables::lshape.view()
                                                                       : statsim::tables::bunny.view();
}

float mass3(int shape)
{
  return shape == box ? statsim::tables::box.mass : shape == lshape ? statsim::tables::lshape.mass
                                                                     : statsim::tables::bunny.mass;
}

/// A point uniform in the unit disc, by rejection from the square around it.
void disc_point(statsim::Pcg32& rng, float& x, float& y)
{
  do {
    x = rng.uniform(-1, 1);
    y = rng.uniform(-1, 1);
  } while (x * x + y * y > 1);
}

/// A uniformly distributed unit quaternion: a point uniform in the 4-ball (by rejection),
/// normalised; points too near the centre are redrawn, as their direction is poorly rounded.
statsim::Quaternion random_orientation(statsim::Pcg32& rng)
{
  for (;;) {
    const float w = rng.uniform(-1, 1);
    const float x = rng.uniform(-1, 1);
    const float y = rng.uniform(-1, 1);
    const float z = rng.uniform(-1, 1);
    const float n2 = w * w + x * x + y * y + z * z;
    if (n2 <= 1 && n2 > 0.01f) return statsim::detail::normalized(statsim::Quaternion(w, x, y, z));
  }
}

/// A body of the current 3D shape with the pour's random orientation and spin.
statsim::BodyDef3 body3(statsim::ShapeId id, int shape, statsim::Pcg32& rng, float x, float y, float z)
{
  statsim::BodyDef3 b;
  b.shape = id;
  b.position = statsim::Vector3(x, y, z);
  b.orientation = random_orientation(rng);
  const float vx = rng.uniform(-0.5f, 0.5f);
  const float vy = rng.uniform(-0.5f, 0.5f);
  b.linear_velocity = statsim::Vector3(vx, vy, 0);
  const float wx = rng.uniform(-5, 5);
  const float wy = rng.uniform(-5, 5);
  const float wz = rng.uniform(-5, 5);
  b.angular_velocity = statsim::Vector3(wx, wy, wz);
  b.mass = mass3(shape);
  return b;
}

/// Bin scene: the side of a lattice cell (m) and the cells per row, for n bodies of bounding
/// radius r in about eight layers (tools/scenes' bin: bodies in lattice cells inside four walls,
/// layer after layer from one cell up).
float bin_cell(float r) { return 2.2f * r; }
std::uint32_t bin_cells(std::uint32_t n)
{
  std::uint32_t c = 3;
  while (c * c * 8 < n) ++c;
  return c;
}

/// 3D scenes. pour: a column of radius 0.1 sqrt(n) m over the ground plane (the heap of paper
/// Figure 6), one body per `rise` of height from 0.3 m up. bin: four walls round a square lattice
/// filled layer by layer. column: columns of ten bodies, every body in the orientation of the
/// table's body frame, one bounding diameter apart, the columns in a square grid. heap (as
/// tools/scenes' heap): the bodies wait asleep in a lattice far above a nozzle and `demo_step`
/// releases one a step from the corners of a square round the axis in turn, at
/// (1.5 + 0.75 cbrt(n)) cells above the ground, falling at 2 m/s.
statsim::Status pour3(int shape, std::uint32_t n, bool rest, std::uint32_t seed)
{
  world3.~World3();
  statsim::WorldDef3 def;
  def.seed = seed;
  def.rest_conditions = rest;
  if (model == model_spheres) def.body_contacts = statsim::BodyContacts::collision_spheres;
  ::new (static_cast<void*>(&world3)) World3(def);
  const auto added = world3.add_shape(signature3(shape));
  if (!added.ok()) return added.status;
  const statsim::Status ground = world3.add_plane(statsim::Vector3(0, 0, 1), 0).status;
  if (ground != statsim::Status::ok) return ground;
  statsim::Pcg32 rng(seed, 1);
  const float r = world3.shape(added.id).bounding_radius;
  const float cell = bin_cell(r);
  const std::uint32_t cells = bin_cells(n);
  const float half = 0.5f * cell * float(cells);
  if (scene == bin) {
    if (!world3.add_plane(statsim::Vector3(1, 0, 0), -half).ok() || !world3.add_plane(statsim::Vector3(-1, 0, 0), -half).ok() ||
        !world3.add_plane(statsim::Vector3(0, 1, 0), -half).ok() || !world3.add_plane(statsim::Vector3(0, -1, 0), -half).ok())
      return statsim::Status::capacity_exceeded;
  }
  const float radius = 0.1f * std::sqrt(float(n));
  const float rise = 2.0f / float(n) + 0.0004f;
  std::uint32_t side = 1;
  while (side * side * 10 < n) ++side;
  std::uint32_t root = 1;
  while (root * root * root < n) ++root;
  heap_bodies = scene == heap ? n : 0;
  heap_released = 0;
  heap_cell = cell;
  heap_nozzle = (1.5f + 0.75f * float(root)) * cell;
  heap_rng = statsim::Pcg32(seed, 4);
  for (std::uint32_t i = 0; i < n; ++i) {
    statsim::Status s = statsim::Status::ok;
    if (scene == heap) {
      const std::uint32_t row = 4 * root, layer = i / (row * row), k = i % (row * row);
      const float x = cell * (float(k % row) - 0.5f * float(row)), y = cell * (float(k / row) - 0.5f * float(row));
      const auto a = world3.add_body(body3(added.id, shape, rng, x, y, heap_nozzle + cell * (10 + float(layer))));
      s = a.ok() ? world3.sleep(a.id) : a.status;
    } else if (scene == bin) {
      const std::uint32_t layer = i / (cells * cells), k = i % (cells * cells);
      const float jx = rng.uniform(-0.05f, 0.05f) * cell, jy = rng.uniform(-0.05f, 0.05f) * cell;
      const float x = -half + cell * (0.5f + float(k % cells)) + jx;
      const float y = -half + cell * (0.5f + float(k / cells)) + jy;
      s = world3.add_body(body3(added.id, shape, rng, x, y, cell * (1 + float(layer)))).status;
    } else if (scene == column) {
      const std::uint32_t c = i / 10, level = i % 10;
      statsim::BodyDef3 b;
      b.shape = added.id;
      const float pitch = 2.05f * r;
      b.position = statsim::Vector3(pitch * (float(c % side) - 0.5f * float(side - 1)),
                                    pitch * (float(c / side) - 0.5f * float(side - 1)), r + pitch * float(level));
      b.mass = mass3(shape);
      s = world3.add_body(b).status;
    } else {
      float x = 0, y = 0;
      disc_point(rng, x, y);
      const float z = 0.3f + rise * float(i) + rng.uniform(0, rise);
      s = world3.add_body(body3(added.id, shape, rng, radius * x, radius * y, z)).status;
    }
    if (s != statsim::Status::ok) return s;
  }
  return statsim::Status::ok;
}

/// 2D: unit squares poured into a bin 1.2 sqrt(n) + 2 m wide, one per `rise` of height (the pour
/// and the bin scene); column: columns of ten squares, upright, 1.05 m apart.
statsim::Status pour2(std::uint32_t n, bool rest, std::uint32_t seed)
{
  world2.~World2();
  statsim::WorldDef2 def;
  def.seed = seed;
  def.rest_conditions = rest;
  if (model == model_spheres) def.body_contacts = statsim::BodyContacts::collision_spheres;
  ::new (static_cast<void*>(&world2)) World2(def);
  const auto added = world2.add_shape(statsim::tables::square2d.view());
  if (!added.ok()) return added.status;
  const float half = 0.6f * std::sqrt(float(n)) + 1;
  if (!world2.add_plane(statsim::Vector2(0, 1), 0).ok() || !world2.add_plane(statsim::Vector2(1, 0), -half).ok() ||
      !world2.add_plane(statsim::Vector2(-1, 0), -half).ok())
    return statsim::Status::capacity_exceeded;
  statsim::Pcg32 rng(seed, 2);
  const float rise = 1.2f * 4 / (half + 1);
  for (std::uint32_t i = 0; i < n; ++i) {
    statsim::BodyDef2 b;
    b.shape = added.id;
    b.mass = statsim::tables::square2d.mass;
    if (scene == column) {
      const std::uint32_t columns = (n + 9) / 10;
      b.position = statsim::Vector2(1.05f * (float(i / 10) - 0.5f * float(columns - 1)), 0.5f + 1.05f * float(i % 10));
    } else {
      const float x = rng.uniform(-1, 1);
      const float y = 1 + rise * float(i) + rng.uniform(0, rise);
      b.position = statsim::Vector2((half - 0.75f) * x, y);
      float c = 0, s = 0;
      do {
        c = rng.uniform(-1, 1);
        s = rng.uniform(-1, 1);
      } while (c * c + s * s > 1 || c * c + s * s < 0.01f);
      b.orientation = statsim::detail::normalized(statsim::Rot2{c, s});
      const float vx = rng.uniform(-1, 1);
      b.linear_velocity = statsim::Vector2(vx, 0);
      b.angular_velocity = rng.uniform(-3, 3);
    }
    const statsim::Status st = world2.add_body(b).status;
    if (st != statsim::Status::ok) return st;
  }
  return statsim::Status::ok;
}

statsim::WorldCore3& core3() { return world3; }
statsim::WorldCore2& core2() { return world2; }

/// How the page colours a body: 0 moving, 1 settling, 2 settling in a chosen rest pose, 3 asleep,
/// 4 asleep in a rest pose.
template <class BodyT>
float draw_class(const BodyT& b)
{
  const bool posed = b.rest_pose != statsim::no_rest_pose;
  if (b.state == statsim::MotionState::asleep) return posed ? 4.0f : 3.0f;
  if (b.state == statsim::MotionState::settling) return posed ? 2.0f : 1.0f;
  return 0.0f;
}

}  // namespace

extern "C" {

/// Sets the scene (0 pour, 1 bin, 2 column) and the body-body model (0 the library's default,
/// 1 collision spheres) of the next `demo_reset`. Returns 0, or `invalid_parameter`.
int demo_configure(int new_scene, int new_model)
{
  if (new_scene < pour || new_scene > heap || new_model < model_default || new_model > model_spheres)
    return int(statsim::Status::invalid_parameter);
  scene = new_scene;
  model = new_model;
  return 0;
}

/// Empties the world and pours `n` bodies (at most 10,000) of `shape` (0 bunny, 1 box, 2 L-shape,
/// 3 2D square), with resting conditions on or off, every random draw from `seed`. Returns 0, or
/// the `statsim::Status` that stopped the pour (the bodies before it stay).
int demo_reset(int shape, std::uint32_t n, int rest_conditions, std::uint32_t seed)
{
  if (shape < bunny || shape > square || n > capacity) return int(statsim::Status::invalid_parameter);
  current = shape;
  current_seed = seed;
  current_rest = rest_conditions != 0;
  extra_rng = statsim::Pcg32(seed, 3);
  snapshot_bytes = 0;
  drawn = 0;
  heap_bodies = heap_released = 0;
  const statsim::Status s = shape == square ? pour2(n, rest_conditions != 0, seed) : pour3(shape, n, rest_conditions != 0, seed);
  return int(s);
}

/// Steps the world `count` times by 1/60 s. Returns 0, or the status of the first step that was
/// not ok, or -1 if a step dropped candidate pairs (the pair buffer was too small).
int demo_step(int count)
{
  constexpr float dt = 1.0f / 60;
  for (int i = 0; i < count; ++i) {
    if (current != square && heap_released < heap_bodies) {
      // The heap's next body leaves its place in the waiting lattice for the nozzle.
      const statsim::BodyId id = core3().id_of(heap_released);
      const float spot = 0.5f * heap_cell, jitter = 0.25f * heap_cell;
      const float sx = (heap_released & 1) ? spot : -spot, sy = (heap_released & 2) ? spot : -spot;
      const float jx = heap_rng.uniform(-jitter, jitter), jy = heap_rng.uniform(-jitter, jitter);
      ++heap_released;
      if (const statsim::Body3* b = core3().find_body(id)) {
        const statsim::Quaternion q = b->orientation;
        if (core3().set_transform(id, statsim::Vector3(sx + jx, sy + jy, heap_nozzle), q) == statsim::Status::ok) {
          const float vx = heap_rng.uniform(-0.2f, 0.2f), vy = heap_rng.uniform(-0.2f, 0.2f);
          const float wx = heap_rng.uniform(-2, 2), wy = heap_rng.uniform(-2, 2);
          (void)core3().set_velocity(id, statsim::Vector3(vx, vy, -2), statsim::Vector3(wx, wy, 0));
        }
      }
    }
    const statsim::StepResult r = current == square ? core2().step(dt) : core3().step(dt);
    if (r.status != statsim::Status::ok) return int(r.status);
    if (r.pairs_dropped) return -1;
  }
  return 0;
}

/// Body slots in use (removed bodies' included; the number the hash lines print).
std::uint32_t demo_body_count() { return current == square ? core2().body_count() : core3().body_count(); }
/// Heap scene: bodies still waiting (asleep) to be released.
std::uint32_t demo_waiting() { return heap_bodies - heap_released; }
/// Bodies in the world.
std::uint32_t demo_live_count() { return current == square ? core2().live_body_count() : core3().live_body_count(); }

std::uint32_t demo_asleep()
{
  return current == square ? core2().count(statsim::MotionState::asleep) : core3().count(statsim::MotionState::asleep);
}

/// Halves of `state_hash()`: JavaScript numbers hold 53 bits.
std::uint32_t demo_hash_high()
{
  return std::uint32_t((current == square ? core2().state_hash() : core3().state_hash()) >> 32);
}
std::uint32_t demo_hash_low()
{
  return std::uint32_t(current == square ? core2().state_hash() : core3().state_hash());
}

/// Bounding radius of the current shape, m.
float demo_body_size()
{
  return current == square ? core2().shape(statsim::ShapeId(0)).bounding_radius : core3().shape(statsim::ShapeId(0)).bounding_radius;
}

/// Fills the transform buffer (`stride` floats per live body, see `transforms`) and returns its
/// address; `demo_drawn` is the number of bodies in it.
const float* demo_transforms()
{
  const std::uint32_t slots = demo_body_count();
  drawn = 0;
  for (std::uint32_t i = 0; i < slots; ++i) {
    float* t = transforms + stride * drawn;
    if (current == square) {
      const statsim::BodyId id = core2().id_of(i);
      const statsim::Body2* b = core2().find_body(id);
      if (!b) continue;
      const auto m = statsim::mesh_to_world(statsim::tables::square2d.view(), *b);
      // The plane's x, y are the 3D x, z; the 3D y is the polygon's extrusion.
      const float rows[12] = {m.linear()(0, 0), 0, m.linear()(0, 1), m.translation().x(),
                              0, 1, 0, 0,
                              m.linear()(1, 0), 0, m.linear()(1, 1), m.translation().y()};
      for (int k = 0; k < 12; ++k) t[k] = rows[k];
      t[12] = draw_class(*b);
    } else {
      if (i >= heap_released && i < heap_bodies) continue;  // still waiting above the heap
      const statsim::BodyId id = core3().id_of(i);
      const statsim::Body3* b = core3().find_body(id);
      if (!b) continue;
      const auto m = statsim::mesh_to_world(signature3(current), *b);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) t[4 * r + c] = m.linear()(r, c);
        t[4 * r + 3] = m.translation()(r);
      }
      t[12] = draw_class(*b);
    }
    t[13] = float(i);
    t[14] = t[15] = 0;
    ++drawn;
  }
  return transforms;
}
std::uint32_t demo_drawn() { return drawn; }

/// The impacts of the last step into `impacts` (x, y, z, approach speed; the 2D plane as x, z);
/// returns their number.
std::uint32_t demo_impacts()
{
  const std::uint32_t n = current == square ? core2().impact_count() : core3().impact_count();
  for (std::uint32_t i = 0; i < n; ++i) {
    float* o = impacts + 4 * i;
    if (current == square) {
      const statsim::Impact<2>& e = core2().impacts()[i];
      o[0] = e.point.x();
      o[1] = 0;
      o[2] = e.point.y();
      o[3] = e.approach_speed;
    } else {
      const statsim::Impact<3>& e = core3().impacts()[i];
      o[0] = e.point.x();
      o[1] = e.point.y();
      o[2] = e.point.z();
      o[3] = e.approach_speed;
    }
  }
  return n;
}
const float* demo_impact_buffer() { return impacts; }

/// Kicks the body a ray from (ox, oy, oz) along (dx, dy, dz) meets first (3D: the nearest
/// collision sphere, `statsim::ray_cast`; 2D: the ray meets the plane y = 0 of the drawing, and
/// the body there is found with `statsim::overlap_sphere`): `apply_impulse` at the hit point of
/// `speed` m/s times the body's mass, along the ray's horizontal direction and upwards. Returns
/// 0, -1 when the ray meets no body, or -2 - status when the impulse is refused.
int demo_kick(float ox, float oy, float oz, float dx, float dy, float dz, float speed)
{
  if (current == square) {
    if (dy == 0) return -1;
    const float t = -oy / dy;
    if (!(t > 0)) return -1;
    const statsim::Vector2 p(ox + t * dx, oz + t * dz);
    statsim::BodyId hit = statsim::no_body;
    const statsim::Status q = statsim::overlap_sphere(core2(), p, 0.0f, [&](const statsim::QueryHit<2>& h) {
      if (h.body == statsim::no_body) return true;
      hit = h.body;
      return false;
    });
    if (q != statsim::Status::ok || hit == statsim::no_body) return -1;
    const statsim::Body2& b = core2().body(hit);
    const float side = dx >= 0 ? 1.0f : -1.0f;
    const float m = 1 / b.inv_mass;
    const statsim::Status s = core2().apply_impulse(hit, statsim::Vector2(0.5f * side * speed * m, speed * m), p);
    return s == statsim::Status::ok ? 0 : -2 - int(s);
  }
  statsim::QueryHit<3> hit;
  const statsim::Vector3 d(dx, dy, dz);
  if (statsim::ray_cast(core3(), statsim::Vector3(ox, oy, oz), d, 1000.0f, hit) != statsim::Status::ok ||
      hit.body == statsim::no_body)
    return -1;
  const statsim::Body3& b = core3().body(hit.body);
  const float m = 1 / b.inv_mass;
  const float h = std::sqrt(dx * dx + dy * dy);
  const float hx = h > 0 ? dx / h : 0, hy = h > 0 ? dy / h : 0;
  const statsim::Vector3 impulse(0.5f * speed * m * hx, 0.5f * speed * m * hy, speed * m);
  const statsim::Status s = core3().apply_impulse(hit.body, impulse, hit.point);
  return s == statsim::Status::ok ? 0 : -2 - int(s);
}

/// Saves the world into the page's snapshot buffer (`statsim::save`). Returns 0 or the status.
int demo_save()
{
  std::size_t written = 0;
  const statsim::Status s = current == square ? statsim::save(core2(), snapshot2, sizeof snapshot2, &written)
                                              : statsim::save(core3(), snapshot3, sizeof snapshot3, &written);
  snapshot_bytes = s == statsim::Status::ok ? written : 0;
  snapshot_shape = s == statsim::Status::ok ? current : -1;
  snapshot_released = heap_released;
  return int(s);
}
/// Bytes of the saved snapshot (0: none).
std::uint32_t demo_snapshot_bytes() { return std::uint32_t(snapshot_bytes); }

/// Restores the saved snapshot (`statsim::load`) into the world, which must hold the shape it
/// was saved with. Returns 0, `invalid_parameter` without a snapshot, or the status of `load`.
int demo_restore()
{
  if (snapshot_bytes == 0 || snapshot_shape != current) return int(statsim::Status::invalid_parameter);
  const statsim::Status s = current == square ? statsim::load(core2(), snapshot2, snapshot_bytes)
                                              : statsim::load(core3(), snapshot3, snapshot_bytes);
  if (s == statsim::Status::ok) heap_released = snapshot_released;
  return int(s);
}

/// Adds `count` bodies above the scene (3D: in a column over the pour's, 2D: across the bin),
/// from the page's second random stream. Returns how many were added.
std::uint32_t demo_spawn(std::uint32_t count)
{
  std::uint32_t added = 0;
  if (current == square) {
    float top = 1;
    for (std::uint32_t i = 0; i < core2().body_count(); ++i)
      if (const statsim::Body2* b = core2().find_body(core2().id_of(i))) top = b->position.y() > top ? b->position.y() : top;
    const float half = -core2().plane(1).offset;
    for (std::uint32_t i = 0; i < count; ++i) {
      statsim::BodyDef2 b;
      b.shape = statsim::ShapeId(0);
      b.mass = statsim::tables::square2d.mass;
      b.position = statsim::Vector2((half - 0.75f) * extra_rng.uniform(-1, 1), top + 2 + 1.2f * float(i % 8) + 0.2f * float(i / 8));
      if (!core2().add_body(b).ok()) break;
      ++added;
    }
    return added;
  }
  float top = 0.3f;
  for (std::uint32_t i = 0; i < core3().body_count(); ++i)
    if (const statsim::Body3* b = core3().find_body(core3().id_of(i))) top = b->position.z() > top ? b->position.z() : top;
  const float r = core3().shape(statsim::ShapeId(0)).bounding_radius;
  const float radius = 0.1f * std::sqrt(float(demo_live_count() + count));
  for (std::uint32_t i = 0; i < count; ++i) {
    float x = 0, y = 0;
    disc_point(extra_rng, x, y);
    const statsim::BodyDef3 b = body3(statsim::ShapeId(0), current, extra_rng, radius * x, radius * y, top + 4 * r + 0.02f * float(i));
    if (!core3().add_body(b).ok()) break;
    ++added;
  }
  return added;
}

/// Removes up to `count` bodies chosen at random from the page's second stream. Returns how
/// many were removed.
std::uint32_t demo_remove(std::uint32_t count)
{
  std::uint32_t removed = 0;
  const std::uint32_t slots = demo_body_count();
  for (std::uint32_t tries = 0; removed < count && tries < 8 * count + 64 && demo_live_count() > 0; ++tries) {
    const std::uint32_t slot = extra_rng.next_u32() % slots;
    const statsim::Status s = current == square ? core2().remove_body(core2().id_of(slot)) : core3().remove_body(core3().id_of(slot));
    if (s == statsim::Status::ok) ++removed;
  }
  return removed;
}

}  // extern "C"

#ifdef WEB_DEMO_MAIN
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

int main(int argc, char** argv)
{
  int shape = bunny;
  unsigned long n = capacity, steps = 600, seed = 1, warmup = 60;
  int rest = 1;
  const char* const names[] = {"bunny", "box", "lshape", "square"};
  for (int i = 1; i < argc; ++i) {
    const bool has = i + 1 < argc;
    if (!std::strcmp(argv[i], "--shape") && has) {
      const char* s = argv[++i];
      shape = -1;
      for (int k = 0; k < 4; ++k)
        if (!std::strcmp(s, names[k])) shape = k;
    } else if (!std::strcmp(argv[i], "--n") && has) n = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--steps") && has) steps = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--seed") && has) seed = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--warmup") && has) warmup = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--no-rest")) rest = 0;
    else shape = -1;
    if (shape < 0) {
      std::fprintf(stderr, "usage: web_demo_host [--shape bunny|box|lshape|square] [--n N<=10000] [--steps S] [--seed S] [--no-rest] "
                   "[--warmup W]\n");
      return 2;
    }
  }
  if (n > capacity || demo_reset(shape, std::uint32_t(n), rest, std::uint32_t(seed)) != 0 ||
      demo_step(int(warmup)) != 0 || demo_reset(shape, std::uint32_t(n), rest, std::uint32_t(seed)) != 0) {
    std::fprintf(stderr, "web_demo_host: could not pour %lu bodies\n", n);
    return 1;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const int status = demo_step(int(steps));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (status != 0) {
    std::fprintf(stderr, "web_demo_host: step failed (%d)\n", status);
    return 1;
  }
  std::printf("web_demo %s bodies %u steps %lu ms_per_step %.3f asleep %u hash 0x%08x%08x\n", names[shape],
              demo_body_count(), steps, steps ? ms / double(steps) : 0.0, demo_asleep(), demo_hash_high(),
              demo_hash_low());
  return 0;
}
#endif
