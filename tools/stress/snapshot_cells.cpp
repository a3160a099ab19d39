// `statsim stress`, scene "snapshot": statsim's snapshots (statsim/snapshot.hpp) taken and
// restored mid-pile. A pile is stepped in world A; at each save point one world's snapshot is
// loaded into the other (A to B, then B to A, ...), so that each snapshot is taken from a world
// that was itself loaded from one; the two step on side by side. The cell passes when every load
// is accepted, every loaded world saves the bytes it was loaded from, and the state hashes of
// the two worlds agree after every step from the first load to the end.
#include "stress/snapshot_cells.hpp"
#include "common/format.hpp"

#include "scenes/body_def.hpp"
#include "scenes/scenes.hpp"
#include "statsim/snapshot.hpp"
#include "tables/bunny.hpp"
#include "tables/square2d.hpp"

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

namespace statsim::tools {
namespace {

/// Steps `steps` times, loading at each of `saves`; adds the cell.
template <int D, class World>
void run_pile(World& a, World& b, const std::string& scene, const std::string& method, const AddCell& add)
{
  const int steps = 600;
  const int saves[] = {30, 90, 180, 360};
  const Scalar dt = Scalar(1) / 60;
  World* from = &a;
  World* to = &b;
  std::vector<unsigned char> bytes, again;
  int loads = 0, round_trips = 0, differ = 0, compared = 0;
  std::size_t largest = 0;
  std::string asleep;
  bool loaded = false;
  for (int s = 1; s <= steps; ++s) {
    if (!a.step(dt).ok() || (loaded && !b.step(dt).ok())) break;
    if (loaded) {
      ++compared;
      differ += a.state_hash() != b.state_hash();
    }
    for (int at : saves) {
      if (s != at) continue;
      bytes.assign(snapshot_size(*from), 0);
      std::size_t n = 0;
      if (save(*from, bytes.data(), bytes.size(), &n) != Status::ok) continue;
      largest = n > largest ? n : largest;
      if (load(*to, bytes.data(), n) != Status::ok) continue;
      ++loads;
      again.assign(n, 0);
      round_trips += save(*to, again.data(), n, &n) == Status::ok && again == bytes;
      asleep += printf_string("%s%u", asleep.empty() ? "" : "/", from->count(MotionState::asleep));
      loaded = true;
      std::swap(from, to);
    }
  }
  const int wanted = int(sizeof saves / sizeof saves[0]);
  const bool pass = loads == wanted && round_trips == wanted && differ == 0 && compared == steps - saves[0];
  add(scene, method, pass,
      printf_string("%d/%d loads, %d round trips byte-identical, hashes differ at %d of %d steps; asleep at the saves %s of "
             "%u; largest snapshot %zu bytes (%.1f per body)",
             loads, wanted, round_trips, differ, compared, asleep.c_str(), a.live_body_count(), largest,
             double(largest) / double(a.body_count())),
      "saved at steps 30, 90, 180 and 360 of 600 and loaded into the other world (A to B, B to A, ...): every load "
      "accepted, save after load gives the same bytes, equal state hashes after every step");
}

}  // namespace

void snapshot_cells(bool want3, bool want2, bool hull_contacts, const AddCell& add)
{
  if (want3) {
    using W = World3<320, 8, 320 * 32, 2>;
    const SignatureView<3> sig = tables::bunny.view();
    scenes::DropOptions o;
    o.count = 300;
    o.bounding_radius = double(sig.bounding_radius);
    const scenes::DropScene3 scene = scenes::drop_scene3(o);
    const Scalar wall = Scalar(scene.region.radius + o.bounding_radius);
    WorldDef3 def;
    def.body_contacts = hull_contacts ? BodyContacts::automatic : BodyContacts::collision_spheres;
    auto a = std::make_unique<W>(def);
    auto b = std::make_unique<W>(def);
    for (W* w : {a.get(), b.get()}) {
      const bool ok = w->add_shape(sig).ok() && w->add_plane(Vector3(0, 0, 1), 0).ok() &&
                      w->add_plane(Vector3(1, 0, 0), -wall).ok() && w->add_plane(Vector3(-1, 0, 0), -wall).ok() &&
                      w->add_plane(Vector3(0, 1, 0), -wall).ok() && w->add_plane(Vector3(0, -1, 0), -wall).ok();
      if (!ok) throw std::runtime_error("stress snapshot: set-up");
    }
    for (const scenes::BodyState3& s : scene.bodies) {
      if (!a->add_body(scenes::body_def(s)).ok()) throw std::runtime_error("stress snapshot: add_body");
    }
    run_pile<3>(*a, *b, "snapshot, pile of 300 bunnies", "statistical", add);
  }
  if (want2) {
    using W = World2<256, 4, 256 * 16, 2>;
    const SignatureView<2> sig = tables::square2d.view();
    scenes::DropOptions o;
    o.count = 200;
    o.bounding_radius = double(sig.bounding_radius);
    const scenes::DropScene2 scene = scenes::drop_scene2(o);
    const Scalar wall = Scalar(scene.region.half_width + o.bounding_radius);
    WorldDef2 def;
    def.body_contacts = hull_contacts ? BodyContacts::automatic : BodyContacts::collision_spheres;
    auto a = std::make_unique<W>(def);
    auto b = std::make_unique<W>(def);
    for (W* w : {a.get(), b.get()}) {
      const bool ok = w->add_shape(sig).ok() && w->add_plane(Vector2(0, 1), 0).ok() &&
                      w->add_plane(Vector2(1, 0), -wall).ok() && w->add_plane(Vector2(-1, 0), -wall).ok();
      if (!ok) throw std::runtime_error("stress snapshot: set-up");
    }
    for (const scenes::BodyState2& s : scene.bodies) {
      BodyDef2 d;
      d.position = s.position.cast<Scalar>();
      d.orientation = detail::normalized(Rot2{Scalar(std::cos(s.angle)), Scalar(std::sin(s.angle))});
      d.linear_velocity = s.linear_velocity.cast<Scalar>();
      d.angular_velocity = Scalar(s.angular_velocity);
      if (!a->add_body(d).ok()) throw std::runtime_error("stress snapshot: add_body");
    }
    run_pile<2>(*a, *b, "snapshot, pile of 200 squares (2D)", "statistical2d", add);
  }
}

}  // namespace statsim::tools
