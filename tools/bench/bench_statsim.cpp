// The `statistical` method: statsim worlds (World3 / World2) with the shape's generated table,
// the runtime's defaults (WorldDef), a ground plane and the scene's initial states.
#include "bench/bench_internal.hpp"
#include "common/task_pool.hpp"
#include "scenes/body_def.hpp"

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"
#include "tables/square2d.hpp"

#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace statsim::tools::bench {

namespace {

/// One WorldDef field a pile-model candidate may set: its name, what the value means, and how it
/// is written into a WorldDef of either dimension.
struct WorldSetting {
  const char* name;
  const char* meaning;
  bool integer_only;
  double low, high;
  void (*apply3)(WorldDef<3>&, double);
  void (*apply2)(WorldDef<2>&, double);
};

#define STATSIM_SETTING(field, meaning, integer_only, low, high, cast)                            \
  WorldSetting                                                                                     \
  {                                                                                                \
    #field, meaning, integer_only, low, high, [](WorldDef<3>& d, double v) { d.field = cast(v); }, \
        [](WorldDef<2>& d, double v) { d.field = cast(v); }                                        \
  }

template <class T>
T to(double v)
{
  return static_cast<T>(v);
}

const std::vector<WorldSetting>& world_settings()
{
  static const std::vector<WorldSetting> all = {
      STATSIM_SETTING(support_iterations, "support passes, 1 to 64", true, 1, 64, to<int>),
      STATSIM_SETTING(shock_propagation, "bottom-up shock pass, 0 or 1", true, 0, 1, to<bool>),
      STATSIM_SETTING(position_iterations, "position passes, 0 to 64", true, 0, 64, to<int>),
      STATSIM_SETTING(allowed_overlap, "overlap left, fraction of the touching distance", false, 0, 0.5, to<Scalar>),
      STATSIM_SETTING(overlap_correction, "share of the overlap removed per step", false, 1e-6, 1, to<Scalar>),
      STATSIM_SETTING(sleep_speed, "m/s", false, 0, 100, to<Scalar>),
      STATSIM_SETTING(sleep_time, "s", false, 0, 100, to<Scalar>),
      STATSIM_SETTING(settle_speed, "m/s", false, 0, 100, to<Scalar>),
      STATSIM_SETTING(wake_speed, "m/s", false, 0, 100, to<Scalar>),
      STATSIM_SETTING(restitution_threshold, "m/s", false, 0, 100, to<Scalar>),
      STATSIM_SETTING(linear_damping, "1/s", false, 0, 1000, to<Scalar>),
      STATSIM_SETTING(angular_damping, "1/s", false, 0, 1000, to<Scalar>),
      STATSIM_SETTING(pile_rest, "0 or 1", true, 0, 1, to<bool>),
      STATSIM_SETTING(sleep_islands, "0 or 1", true, 0, 1, to<bool>),
      STATSIM_SETTING(ground_hulls, "0 or 1 (compiles Features::slopes)", true, 0, 1, to<bool>),
  };
  return all;
}

#undef STATSIM_SETTING

const WorldSetting& find_setting(const std::string& name)
{
  for (const WorldSetting& s : world_settings())
    if (name == s.name) return s;
  std::string known;
  for (const WorldSetting& s : world_settings()) known += std::string(known.empty() ? "" : ", ") + s.name;
  throw std::invalid_argument("unknown WorldDef setting '" + name + "' (known: " + known + ")");
}

template <int D>
void apply_settings(WorldDef<D>& def, const std::vector<std::pair<std::string, double>>& settings)
{
  for (const auto& [name, value] : settings) {
    check_world_setting(name, value);
    const WorldSetting& s = find_setting(name);
    if constexpr (D == 3) s.apply3(def, value);
    else s.apply2(def, value);
  }
}

/// Sets the broad phase: "" keeps the runtime's default; "grid" or "sap" forces one.
void set_broad_phase(BroadPhase& broad_phase, const std::string& which)
{
  if (which.empty()) return;
  broad_phase = which == "grid" ? BroadPhase::grid : BroadPhase::sweep_and_prune;
}

}  // namespace

const std::vector<std::pair<std::string, std::string>>& world_setting_names()
{
  static const std::vector<std::pair<std::string, std::string>> names = [] {
    std::vector<std::pair<std::string, std::string>> n;
    for (const WorldSetting& s : world_settings()) n.emplace_back(s.name, s.meaning);
    return n;
  }();
  return names;
}

void check_world_setting(const std::string& name, double value)
{
  const WorldSetting& s = find_setting(name);
  if (!std::isfinite(value) || value < s.low || value > s.high || (s.integer_only && value != std::floor(value)))
    throw std::invalid_argument("WorldDef setting " + name + "=" + std::to_string(value) + ": out of range (" +
                                s.meaning + ")");
}

template <int D>
WorldDef<D> statsim_world_def(std::uint64_t seed, const std::string& broad_phase, const StatsimVariant& variant)
{
  WorldDef<D> def;
  def.seed = seed;
  def.rest_conditions = variant.rest_conditions;
  if (!variant.hull_contacts) def.body_contacts = BodyContacts::collision_spheres;
  if (variant.independent_pairs) def.pair_response = PairResponse::independent;
  set_broad_phase(def.broad_phase, broad_phase);
  apply_settings(def, variant.settings);
  return def;
}
template WorldDef<2> statsim_world_def<2>(std::uint64_t, const std::string&, const StatsimVariant&);
template WorldDef<3> statsim_world_def<3>(std::uint64_t, const std::string&, const StatsimVariant&);

namespace {

// Capacities: the world is sized to the scene (the smallest of these tiers that holds N), as a user
// would size it; the largest holds the 100,000-body run (its pair buffer alone is 50 MB, on the
// heap with the world). Candidate pairs up to 32 per body, room for the neighbours whose bounding
// spheres overlap in a pile (see tools/bench/README.md); an overflow is reported, never silent.
constexpr std::uint32_t kCapacity = 131072;
constexpr std::uint32_t kPairsPerBody = 32;

std::optional<SignatureView<3>> table3(const std::string& shape)
{
  if (shape == "bunny") return tables::bunny.view();
  if (shape == "box") return tables::box.view();
  if (shape == "lshape") return tables::lshape.view();
  return std::nullopt;
}

template <int D>
void fill_surface(const SignatureView<D>& sig, Surface& s)
{
  const WorldDef<D> def{};
  s.restitution = sig.material.restitution;
  s.friction = sig.material.friction;
  s.rolling_resistance = sig.material.rolling_resistance;
  s.restitution_threshold = def.restitution_threshold;
  s.sleep_speed = def.sleep_speed;
  s.sleep_time = def.sleep_time;
}

template <int D>
void add_body(WorldCore<D>& world, ShapeId shape, double mass, const scenes::BodyState3& s)
{
  BodyDef<D> b = scenes::body_def(s);
  b.shape = shape;
  b.mass = static_cast<Scalar>(mass);
  b.asleep = s.asleep;
  const Added<BodyId> added = world.add_body(b);
  if (!added.ok()) throw std::runtime_error(std::string("statsim add_body: ") + to_string(added.status));
}

template <int D>
void add_body(WorldCore<D>& world, ShapeId shape, double mass, const scenes::BodyState2& s)
{
  BodyDef<D> b = scenes::body_def(s);
  b.shape = shape;
  b.mass = static_cast<Scalar>(mass);
  const Added<BodyId> added = world.add_body(b);
  if (!added.ok()) throw std::runtime_error(std::string("statsim add_body: ") + to_string(added.status));
}

/// The shapes of a world: signature and mass of each, and the shape of each body (all the first
/// when `of_body` is empty).
template <int D>
struct ShapeSet {
  std::vector<SignatureView<D>> sigs;
  std::vector<double> masses;
  std::vector<int> of_body;
};

/// A statsim world of capacity `Cap` and features `F` with the scene's bodies and the ground.
template <int D, std::uint32_t Cap, Features F>
class StatsimSim final : public Sim {
public:
  // Planes: the ground and up to 7 more (the bin scene's four walls). Shapes: up to 2.
  using WorldT = World<D, Cap, 8, Cap * kPairsPerBody, 2, 0, BroadPhase::automatic, F>;

  template <class Scene>
  StatsimSim(const ShapeSet<D>& set, const Scene& scene, std::uint64_t seed, double dt,
             const std::string& broad_phase, const StatsimVariant& variant = {},
             const std::vector<bullet::Plane>& walls = {})
      : dt_(static_cast<Scalar>(dt)), pool_(variant.workers > 1 ? std::make_unique<TaskPool>(variant.workers) : nullptr)
  {
    WorldDef<D> def = statsim_world_def<D>(seed, broad_phase, variant);
    if (pool_) def.workers = pool_->workers();
    world_ = std::make_unique<WorldT>(def);
    if (world_->construction_status() != Status::ok)
      throw std::runtime_error(std::string("statsim world: ") + to_string(world_->construction_status()));
    std::vector<ShapeId> ids;
    for (const SignatureView<D>& sig : set.sigs) {
      const Added<ShapeId> shape = world_->add_shape(sig);
      if (!shape.ok()) throw std::runtime_error(std::string("statsim add_shape: ") + to_string(shape.status));
      ids.push_back(shape.id);
    }
    if (!world_->add_plane(Space<D>::Vec::Unit(Space<D>::up_axis), 0).ok())
      throw std::runtime_error("statsim add_plane failed");
    if constexpr (D == 3)
      for (const bullet::Plane& p : walls)
        if (!world_->add_plane(p.normal.cast<Scalar>(), static_cast<Scalar>(p.offset)).ok())
          throw std::runtime_error("statsim add_plane (wall) failed");
    if (!set.of_body.empty() && set.of_body.size() != scene.bodies.size())
      throw std::runtime_error("statsim world: one shape index per body");
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const std::size_t k = set.of_body.empty() ? 0 : static_cast<std::size_t>(set.of_body[i]);
      if (k >= ids.size()) throw std::runtime_error("statsim world: shape index out of range");
      add_body<D>(*world_, ids[k], set.masses[k], scene.bodies[i]);
    }
  }
  void step() override
  {
    last_ = world_->step(dt_);
    if (last_.pairs_dropped > worst_dropped_) worst_dropped_ = last_.pairs_dropped;
  }
  std::size_t asleep() const override { return world_->count(MotionState::asleep); }
  EndState end_state() const override
  {
    EndState e;
    e.asleep = asleep();
    double h = 0;
    for (std::uint32_t i = 0; i < world_->body_count(); ++i)
      h += double(world_->body(i).position[Space<D>::up_axis]);
    e.mean_height = world_->body_count() ? h / world_->body_count() : 0.0;
    e.contacts = last_.contacts;
    return e;
  }
  std::size_t body_count() const override { return world_->body_count(); }
  scenes::BodyState3 body_state(std::size_t i) const override
  {
    scenes::BodyState3 s;
    if constexpr (D == 3) {
      const Body<3>& b = world_->body(static_cast<BodyId>(i));
      s.position = b.position.template cast<double>();
      s.orientation = b.orientation.template cast<double>();
      s.linear_velocity = b.linear_velocity.template cast<double>();
      s.angular_velocity = b.angular_velocity.template cast<double>();
    } else {
      (void)i;
    }
    return s;
  }
  bool body_asleep(std::size_t i) const override
  {
    return world_->body(static_cast<BodyId>(i)).state == MotionState::asleep;
  }
  void place_body(std::size_t i, const scenes::BodyState3& s) override
  {
    if constexpr (D == 3) {
      const BodyId id = static_cast<BodyId>(i);
      const Status a = world_->set_transform(id, s.position.cast<Scalar>(), s.orientation.cast<Scalar>().normalized());
      const Status b = world_->set_velocity(id, s.linear_velocity.cast<Scalar>(), s.angular_velocity.cast<Scalar>());
      if (a != Status::ok || b != Status::ok) throw std::runtime_error("statsim place_body failed");
    } else {
      Sim::place_body(i, s);
    }
  }
  std::uint64_t statistical_responses() const override { return world_->statistical_response_count(); }
  std::uint64_t energy_clamps() const override { return world_->energy_clamp_count(); }
  std::string warning() const override
  {
    if (worst_dropped_ == 0) return {};
    return "statsim pair buffer full: up to " + std::to_string(worst_dropped_) + " candidate pairs dropped in a step";
  }

private:
  Scalar dt_;
  std::unique_ptr<TaskPool> pool_;  // declared before the world, which calls it, so that it outlives it
  std::unique_ptr<WorldT> world_;
  StepResult last_{};
  std::uint32_t worst_dropped_ = 0;
};

template <int D, Features F, class Scene>
std::unique_ptr<Sim> make_capacity(const ShapeSet<D>& sig, const Scene& scene, std::uint64_t seed, double dt,
                                   const std::string& broad_phase, const StatsimVariant& v,
                                   const std::vector<bullet::Plane>& w)
{
  const std::size_t n = scene.bodies.size();
  if (n <= 16) return std::make_unique<StatsimSim<D, 16, F>>(sig, scene, seed, dt, broad_phase, v, w);
  if (n <= 128) return std::make_unique<StatsimSim<D, 128, F>>(sig, scene, seed, dt, broad_phase, v, w);
  if (n <= 1024) return std::make_unique<StatsimSim<D, 1024, F>>(sig, scene, seed, dt, broad_phase, v, w);
  if (n <= 4096) return std::make_unique<StatsimSim<D, 4096, F>>(sig, scene, seed, dt, broad_phase, v, w);
  if (n <= 16384) return std::make_unique<StatsimSim<D, 16384, F>>(sig, scene, seed, dt, broad_phase, v, w);
  if (n <= 32768) return std::make_unique<StatsimSim<D, 32768, F>>(sig, scene, seed, dt, broad_phase, v, w);
  if (n <= kCapacity) return std::make_unique<StatsimSim<D, kCapacity, F>>(sig, scene, seed, dt, broad_phase, v, w);
  throw std::runtime_error("statsim bench worlds hold at most " + std::to_string(kCapacity) + " bodies");
}

/// A world of the features the scene uses, as a user would compile it (statsim/features.hpp):
/// statistical shapes, hull contacts where the variant asks for them, slopes where a wall is
/// tilted or the variant sets `ground_hulls`; every feature with `StatsimVariant::all_features`.
/// 3D only: the 2D bench keeps every feature, so that the tool compiles a third as many steps.
template <int D, class Scene>
std::unique_ptr<Sim> make_sized(const ShapeSet<D>& sig, const Scene& scene, std::uint64_t seed, double dt,
                                const std::string& broad_phase, const StatsimVariant& v = {},
                                const std::vector<bullet::Plane>& w = {})
{
  if constexpr (D == 3) {
    bool slopes = false;
    for (const bullet::Plane& p : w) {
      Scalar gn;
      slopes = slopes || detail::is_tilted_plane(WorldDef3{}.gravity, Vector3(p.normal.cast<Scalar>().normalized()), gn);
    }
    for (const auto& [name, value] : v.settings) slopes = slopes || (name == "ground_hulls" && value != 0);
    if (!v.all_features && !slopes) {
      if (v.hull_contacts) return make_capacity<D, Features::piles>(sig, scene, seed, dt, broad_phase, v, w);
      return make_capacity<D, Features::paper>(sig, scene, seed, dt, broad_phase, v, w);
    }
  }
  return make_capacity<D, Features::all>(sig, scene, seed, dt, broad_phase, v, w);
}

}  // namespace

std::uint32_t statsim_capacity()
{
  return kCapacity;
}

void describe_table3(const std::string& shape, Body3& body)
{
  const std::optional<SignatureView<3>> t = table3(shape);
  body.has_table = t.has_value();
  if (!t) {
    body.table_name = "tables/" + shape + ".hpp (missing)";
    return;
  }
  body.table_name = "tables/" + shape + ".hpp";
  fill_surface<3>(*t, body.surface);
  body.mass = static_cast<double>(t->mass);
  body.sphere_radius = static_cast<double>(t->height.mean[0]);
  body.sphere_radius_note = "the table's mean collision radius h_coll at spin ratio 0";
}

void describe_table2(Body2& body)
{
  const SignatureView<2> v = tables::square2d.view();
  body.has_table = true;
  body.table_name = "tables/square2d.hpp";
  fill_surface<2>(v, body.surface);
  body.mass = static_cast<double>(v.mass);
  body.circle_radius = static_cast<double>(v.height.mean[0]);
  body.circle_radius_note = "the table's mean collision radius h_coll at spin ratio 0";
}

std::string statsim_default_broad_phase()
{
  const BroadPhase k = WorldDef3{}.broad_phase;
  return k == BroadPhase::grid ? "grid" : (k == BroadPhase::sweep_and_prune ? "sap" : "auto");
}

std::unique_ptr<Sim> make_statsim3(const Body3& body, const scenes::DropScene3& scene, std::uint64_t seed, double dt,
                                   const std::string& broad_phase, const StatsimVariant& variant)
{
  const std::optional<SignatureView<3>> t = table3(body.shape);
  if (!t) throw std::runtime_error("no statistical table for " + body.shape);
  return make_sized<3>(ShapeSet<3>{{*t}, {body.mass}, {}}, scene, seed, dt, broad_phase, variant);
}

bool statsim_table3(const std::string& shape, SignatureView<3>& out)
{
  const std::optional<SignatureView<3>> t = table3(shape);
  if (!t) return false;
  out = *t;
  return true;
}

std::unique_ptr<Sim> make_statsim3_table(const SignatureView<3>& sig, double mass, const scenes::DropScene3& scene,
                                         std::uint64_t seed, double dt, const std::string& broad_phase,
                                         const StatsimVariant& variant, const std::vector<bullet::Plane>& walls)
{
  return make_sized<3>(ShapeSet<3>{{sig}, {mass}, {}}, scene, seed, dt, broad_phase, variant, walls);
}

std::unique_ptr<Sim> make_statsim3_mixed(const std::vector<SignatureView<3>>& sigs, const std::vector<double>& masses,
                                          const std::vector<int>& of_body, const scenes::DropScene3& scene,
                                          std::uint64_t seed, double dt, const StatsimVariant& variant,
                                          const std::vector<bullet::Plane>& walls)
{
  if (sigs.empty() || sigs.size() > 2 || masses.size() != sigs.size())
    throw std::runtime_error("statsim world: one or two shapes, one mass each");
  return make_sized<3>(ShapeSet<3>{sigs, masses, of_body}, scene, seed, dt, "", variant, walls);
}

std::unique_ptr<Sim> make_statsim2(const Body2& body, const scenes::DropScene2& scene, std::uint64_t seed, double dt,
                                   const std::string& broad_phase, const StatsimVariant& variant)
{
  return make_sized<2>(ShapeSet<2>{{tables::square2d.view()}, {body.mass}, {}}, scene, seed, dt, broad_phase, variant);
}

}  // namespace statsim::tools::bench
