// The methods of `statsim fidelity` and their worlds: the set-up of a run (bodies, tables, the
// method list), the gathering's Bullet reference as a bench::Sim, and the step-time measurement.
#include "fidelity/stages.hpp"

#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "statsim/world3.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace statsim::tools::fidelity {

std::uint64_t mix(std::uint64_t seed, std::uint64_t r)
{
  std::uint64_t z = seed * 0x9e3779b97f4a7c15ull + r + 0x632be59bd9b4e019ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

namespace {

constexpr double kStillWindow = 0.25;  // s, --reference gather's stillness windows (as the gathering's)

class GatherReferenceSim final : public bench::Sim {
public:
  GatherReferenceSim(const ref3d::ShapeModel& model, const ref3d::ReferenceSettings& settings,
                     const scenes::BodyState3& start)
      : reference_(std::make_unique<ref3d::Reference>(model, settings)),
        radius_(model.bounding_radius),
        window_(std::max(1L, static_cast<long>(std::ceil(kStillWindow / settings.dt - 1e-9)))),
        limit_(kQuietSpeed * static_cast<double>(window_) * settings.dt)
  {
    ref3d::RigidState s;
    s.position = start.position;
    s.orientation = start.orientation;
    s.velocity = start.linear_velocity;
    s.spin = start.angular_velocity;
    run_ = reference_->run(s);
    anchor_ = s;
  }
  // Asleep as the gathering's drop() decides rest: a resting GImpact body jitters by several
  // mm/s from step to step while going nowhere, so instantaneous speeds stay above 0.01 m/s
  // now and then; the average speeds of the centre and of the farthest point over each of two
  // consecutive windows of 0.25 s below kQuietSpeed count instead (like Bullet's deactivation in
  // the other methods, after 0.5 s of stillness).
  void step() override
  {
    run_->step();
    if (++steps_ % window_ != 0) return;
    const ref3d::RigidState s = run_->state();
    const double moved = (s.position - anchor_.position).norm();
    const double turned = s.orientation.angularDistance(anchor_.orientation) * radius_;
    quiet_windows_ = moved < limit_ && turned < limit_ ? quiet_windows_ + 1 : 0;
    anchor_ = s;
  }
  std::size_t asleep() const override { return 0; }
  bench::EndState end_state() const override
  {
    bench::EndState e;
    e.mean_height = run_->state().position.z();
    return e;
  }
  std::size_t body_count() const override { return 1; }
  scenes::BodyState3 body_state(std::size_t) const override
  {
    const ref3d::RigidState r = run_->state();
    scenes::BodyState3 s;
    s.position = r.position;
    s.orientation = r.orientation;
    s.linear_velocity = r.velocity;
    s.angular_velocity = r.spin;
    return s;
  }
  bool body_asleep(std::size_t) const override { return quiet_windows_ >= 2; }

private:
  std::unique_ptr<ref3d::Reference> reference_;
  std::unique_ptr<ref3d::Reference::Run> run_;
  double radius_;
  long window_;   // steps per stillness window
  double limit_;  // m of motion per window
  long steps_ = 0;
  int quiet_windows_ = 0;
  ref3d::RigidState anchor_;
};


}  // namespace

// The gathering's reference settings, one per line (as tables/NAME.hpp's header lists them).
std::vector<std::string> gather_settings_lines(const ref3d::ShapeModel& m, const ref3d::ReferenceSettings& r)
{
  char b[600];
  std::vector<std::string> out;
  out.push_back("Bullet " + ref3d::bullet_version() +
                " (double precision) with the settings of statsim gather (tools/ref3d/reference.hpp), one world "
                "per drop");
  std::snprintf(b, sizeof b,
                "dt %.6g s, %d solver iterations, warm starting %s, split impulse %s, erp %.3g, speculative contacts "
                "%s, multipoint convex-plane manifold %s",
                r.dt, r.solver_iterations, r.warm_starting ? "on" : "off", r.split_impulse ? "always" : "Bullet's",
                r.erp, r.speculative_contacts ? "on" : "off", r.multipoint_plane ? "on" : "off");
  out.push_back(b);
  std::snprintf(b, sizeof b,
                "restitution %.3g, friction %.3g (ground 1 and 1: Bullet multiplies), restitution threshold %.3g m/s, "
                "gravity %.3g m/s^2, rolling friction %.3g m, no deactivation (rest: average speeds of the centre and the farthest point below 0.01 m/s over two consecutive 0.25 s windows)",
                r.restitution, r.friction, r.restitution_threshold, r.gravity, r.rest_rolling_friction);
  out.push_back(b);
  const bool plane = r.ground_auto ? m.kind == ref3d::ShapeKind::mesh : r.ground == ref3d::Ground::plane;
  const char* body = m.kind == ref3d::ShapeKind::box        ? "btBoxShape"
                     : m.kind == ref3d::ShapeKind::compound ? "btCompoundShape of btBoxShapes"
                     : r.mesh_hull                          ? "btConvexHullShape of the mesh's hull"
                                                            : "btGImpactMeshShape of the full mesh";
  std::snprintf(b, sizeof b, "body: %s, margin %.3g m, mass %.6g kg; ground: %s", body, r.margin, m.mass.mass,
                plane ? "btStaticPlaneShape z = 0" : "static btBoxShape, top face z = 0");
  out.push_back(b);
  return out;
}

MethodSpec pile_reference_method(int solver_iterations)
{
  MethodSpec ref;
  ref.name = "reference";
  ref.description = "Bullet full";
  ref.bullet = true;
  ref.bullet_method = "full";
  ref.solver_iterations = solver_iterations;
  return ref;
}

std::unique_ptr<bench::Sim> build(const Setup& setup, const MethodSpec& m, const scenes::DropScene3& scene,
                                  std::uint64_t seed, double dt)
{
  if (m.gather_reference) {
    // make_setup() builds the model whenever a method uses it; single drops only (one body).
    ref3d::ReferenceSettings settings = setup.reference_settings;
    settings.dt = dt;
    return std::make_unique<GatherReferenceSim>(*setup.model, settings, scene.bodies[0]);
  }
  if (m.bullet) {
    // Shapes per world: GImpact shapes keep mutable lock state, so worlds on different threads
    // must not share them.
    const std::shared_ptr<bench::BulletShapes> shapes = bench::make_bullet_shapes(setup.body);
    bullet::DropSettings s = bench::bullet_drop_settings(setup.body, m.bullet_method, "sap", scene);
    s.solver_iterations = m.solver_iterations;
    return bench::make_bullet(shapes, m.bullet_method, s, scene.bodies, dt);
  }
  return bench::make_statsim3_table(m.table, setup.body.mass, scene, seed, dt, "", m.variant);
}

double measure_step_ms(const Setup& setup, const MethodSpec& m, int n, int steps)
{
  scenes::DropOptions o;
  o.count = n;
  o.bounding_radius = setup.radius;
  o.seed = 1;
  const scenes::DropScene3 scene = scenes::drop_scene3(o);
  MethodSpec many = m;
  many.gather_reference = false;  // GatherReferenceSim holds one body
  std::unique_ptr<bench::Sim> sim = build(setup, many, scene, 1, 1.0 / 60.0);
  const double t0 = bench::thread_cpu_ms();
  for (int k = 0; k < steps; ++k) sim->step();
  return (bench::thread_cpu_ms() - t0) / steps;
}

namespace {

/// The "+FIELD=VALUE" parts of a method's name, each checked (bench::check_world_setting).
std::vector<std::pair<std::string, double>> world_settings_of(const std::string& method)
{
  std::vector<std::pair<std::string, double>> out;
  std::size_t at = method.find('+');
  while (at != std::string::npos) {
    const std::size_t next = method.find('+', at + 1);
    const std::string part = method.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
    const std::size_t eq = part.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == part.size())
      throw std::invalid_argument("method " + method + ": '" + part + "' is not FIELD=VALUE");
    const std::string field = part.substr(0, eq), text = part.substr(eq + 1);
    std::size_t used = 0;
    double value = 0;
    try {
      value = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != text.size()) throw std::invalid_argument("method " + method + ": '" + text + "' is not a number");
    bench::check_world_setting(field, value);
    out.emplace_back(field, value);
    at = next;
  }
  return out;
}

std::string format_setting(double value)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", value);
  return buf;
}

bench::Body3 body_from_mesh(const std::string& path, const SignatureView<3>& table)
{
  TriMesh mesh;
  MeshError error;
  if (!load_obj(path, mesh, error)) throw std::runtime_error(error.message);
  const MassProperties mp = compute_mass_properties(mesh, 1.0);
  bench::Body3 body;
  body.shape = std::filesystem::path(path).stem().string();
  for (const auto& p : mesh.vertices) {
    body.full_vertices.push_back(mp.principal_axes.transpose() * (p - mp.com));
    body.bounding_radius = std::max(body.bounding_radius, body.full_vertices.back().norm());
  }
  for (const auto& t : mesh.triangles) body.full_indices.insert(body.full_indices.end(), t.begin(), t.end());
  body.mass = double(table.mass);
  body.inertia = mp.principal_moments * (body.mass / mp.volume);
  body.sphere_radius = double(table.height.mean[0]);
  body.sphere_radius_note = "the loaded table's mean collision radius h_coll at spin ratio 0";
  const WorldDef<3> def{};
  body.surface.restitution = double(table.material.restitution);
  body.surface.friction = double(table.material.friction);
  body.surface.rolling_resistance = double(table.material.rolling_resistance);
  body.surface.restitution_threshold = double(def.restitution_threshold);
  body.surface.sleep_speed = double(def.sleep_speed);
  body.surface.sleep_time = double(def.sleep_time);
  body.has_table = true;
  body.table_name = "loaded";
  return body;
}


}  // namespace

Setup make_setup(const FidelityOptions& o)
{
  Setup s;
  // No reallocation after a view is taken: views point into the tables' strings and vectors.
  s.loaded.reserve(o.tables.size());
  for (const auto& t : o.tables) {
    s.loaded.push_back(load_signature_json(t.second));
    s.loaded.back().name() = t.first;
  }
  SignatureView<3> compiled{};
  bool have_compiled = false;
  if (o.mesh.empty()) {
    s.body = bench::load_body3(o.shape, o.meshes_dir);
    have_compiled = bench::statsim_table3(o.shape, compiled);
    if (!have_compiled && s.loaded.empty())
      throw std::runtime_error("no statistical table for " + o.shape + " (generate tables/" + o.shape +
                               ".hpp or pass --table NAME=FILE.json)");
  } else {
    s.body = body_from_mesh(o.mesh, s.loaded.front().view());
  }
  s.radius = s.body.bounding_radius;
  if (!o.mix.empty()) {
    s.mixed = true;
    s.mix_body = bench::load_body3(o.mix, o.meshes_dir);
    if (!bench::statsim_table3(o.mix, s.mix_table)) throw std::runtime_error("no statistical table for " + o.mix);
  }
  const std::vector<std::string> names = o.methods.empty() ? default_methods() : o.methods;
  if (o.reference == "gather" || std::find(names.begin(), names.end(), "full-gather") != names.end()) {
    // The gathering's defaults (tables/NAME.hpp's header lists them) at the body's density.
    const std::string shape = o.mesh.empty() ? o.shape : std::string();
    s.model = std::make_unique<ref3d::ShapeModel>(ref3d::load_shape_model(shape, o.mesh, 1000.0));
    if (std::abs(s.model->mass.mass - s.body.mass) > 1e-9 * s.body.mass)
      *s.model = ref3d::load_shape_model(shape, o.mesh, 1000.0 * s.body.mass / s.model->mass.mass);
  }
  s.poses = have_compiled ? compiled : s.loaded.front().view();
  const SignatureView<3> base = have_compiled ? compiled : s.loaded.front().view();
  const long long base_bytes =
      have_compiled ? static_cast<long long>(signature_bytes(compiled)) : static_cast<long long>(s.loaded.front().bytes());
  const std::string base_name = have_compiled ? s.body.table_name : s.loaded.front().path;

  auto shapes = bench::make_bullet_shapes(s.body);
  auto mix_shapes = s.mixed ? bench::make_bullet_shapes(s.mix_body) : nullptr;
  for (const std::string& full_name : names) {
    MethodSpec m;
    m.name = full_name;
    // "statistical+FIELD=VALUE+...": a statistical method with WorldDef fields set by name.
    const std::string name = full_name.substr(0, full_name.find('+'));
    const std::vector<std::pair<std::string, double>> settings = world_settings_of(full_name);
    if (!settings.empty() && name != "statistical" && name != "statistical-norest" &&
        name != "statistical-independent" && name != "statistical-spheres" && name.rfind("statistical:", 0) != 0)
      throw std::invalid_argument("method " + full_name + ": WorldDef settings (+FIELD=VALUE) go after statistical, "
                                  "statistical-norest, statistical-independent, statistical-spheres or statistical:NAME");
    if (s.mixed && name.rfind("statistical:", 0) == 0) {
      if (o.methods.empty()) continue;
      throw std::invalid_argument("method " + name + ": --mix takes the compiled tables only");
    }
    if (name == "full" || name == "low" || name == "hull" || name == "spheres7" || name == "sphere") {
      std::string why;
      if (!bench::bullet_supports(*shapes, name, why) || (mix_shapes && !bench::bullet_supports(*mix_shapes, name, why))) {
        if (o.methods.empty()) continue;  // the default list keeps what the shape supports
        throw std::invalid_argument("method " + name + ": " + why);
      }
      m.bullet = true;
      m.bullet_method = name;
      m.description = "Bullet " + name;
    } else if (name == "full-gather") {
      m.bullet = true;
      m.gather_reference = true;
      m.bullet_method = "full";
      m.description = "Bullet full, statsim gather's settings (piles and step time: statsim bench's)";
    } else if (name == "statistical" || name == "statistical-norest" || name == "statistical-independent" ||
               name == "statistical-spheres") {
      m.table = base;
      m.table_bytes = base_bytes;
      m.variant.rest_conditions = name != "statistical-norest";
      m.variant.independent_pairs = name == "statistical-independent";
      // The library's default model (hull contacts where the table has body-body data, sleep by
      // islands), as statsim bench runs it; "-spheres": the paper's collision spheres between bodies.
      m.variant.hull_contacts = name != "statistical-spheres";
      m.description = "statsim, " + base_name +
                      (name == "statistical-norest" ? ", resting conditions off"
                       : name == "statistical-independent" ? ", independent pair response"
                       : name == "statistical-spheres"     ? ", collision spheres between bodies (the paper's rule)"
                                                           : ", momentum pair response, resting conditions on");
      m.variant.settings = settings;
      for (const auto& [field, value] : settings) m.description += ", " + field + " = " + format_setting(value);
    } else if (name.rfind("statistical:", 0) == 0) {
      const std::string t = name.substr(12);
      auto it = std::find_if(s.loaded.begin(), s.loaded.end(), [&](const LoadedSignature3& l) { return l.name() == t; });
      if (it == s.loaded.end()) throw std::invalid_argument("method " + name + ": no --table " + t + "=FILE.json");
      m.table = it->view();
      m.table_bytes = static_cast<long long>(it->bytes());
      m.description = "statsim, " + it->path + (it->i16() ? " (i16)" : " (f32)");
      m.variant.settings = settings;
      for (const auto& [field, value] : settings) m.description += ", " + field + " = " + format_setting(value);
    } else {
      throw std::invalid_argument("unknown method '" + name +
                                  "' (full, full-gather, low, hull, spheres7, sphere, statistical, statistical-norest, "
                                  "statistical-independent, statistical-spheres, statistical:NAME)");
    }
    s.methods.push_back(m);
  }
  // Every loaded table is compared even when not named in --methods.
  for (const LoadedSignature3& l : s.loaded) {
    const std::string name = "statistical:" + l.name();
    if (std::none_of(s.methods.begin(), s.methods.end(), [&](const MethodSpec& m) { return m.name == name; })) {
      MethodSpec m;
      m.name = name;
      m.table = l.view();
      m.table_bytes = static_cast<long long>(l.bytes());
      m.description = "statsim, " + l.path + (l.i16() ? " (i16)" : " (f32)");
      s.methods.push_back(m);
    }
  }
  return s;
}

}  // namespace statsim::tools::fidelity
