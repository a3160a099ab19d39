#include "ref3d/ref3d.hpp"
#include "common/commands.hpp"

#include "common/atomic_file.hpp"
#include "ref3d/cell_report.hpp"
#include "ref3d/compare.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/pairs.hpp"
#include "ref3d/signature_json.hpp"
#include "ref3d/sizing.hpp"
#include "mesh/mesh.hpp"

#include "statsim/world_def.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <ostream>
#include <sstream>
#include <utility>
#include <vector>

namespace statsim::tools {

namespace {

using namespace ref3d;

std::string quote(const std::string& s)
{
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./,+=:") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct GatherCommand {
  GatherOptions options;
  std::string layout = "scaled";
  std::string precision = "f32";
  std::string response_model = "paper";
  std::string response_spin = "auto";
  std::string mesh_shape = "gimpact";
  std::string out;
  std::string json;
  std::string units;        ///< --units NAME (m, cm, mm, in, ft)
  std::string name_space = "statsim::tables";  ///< --namespace
  std::string cell_report;  ///< markdown file; its JSON beside it (.json)
  std::vector<std::string> model_json;  ///< MODEL=FILE: the same gathering's JSON with another model
  bool quiet = false;
  bool speed_check = false;
  bool step_check = false;
  bool settings_check = false;
  bool no_body_contacts = false;
  bool no_landing = false;
  bool settle = false;
  std::vector<double> check_speeds = {0.5, 1, 2, 4, 8};
  int check_trials = 200;
  // --size-for-scene (tools/ref3d/sizing.hpp)
  bool size_for_scene = false;
  double scene_max_speed = 0.0, scene_drop_height = 0.0, scene_gravity = 9.81, scene_min_speed = 0.0;
  double scene_max_spin = 0.0;
  double error_budget = 0.05;
  bool sizing_list_all = false;
  std::ostream* out_stream = &std::cout;
  std::ostream* err_stream = &std::cerr;
};

// The options that do not change the output (threads, progress, the JSON dump) are left out of
// the recorded command, so that it is the same whatever they were; file paths are written as the
// target records them (tables of this repository as given, others as file names).
std::string recorded_command(const CLI::App& sub, const TableTarget& target)
{
  static const char* const kPaths[] = {"--mesh", "--out", "--cell-report"};
  std::string cmd = target.program() + " gather";
  for (const CLI::Option* opt : sub.get_options()) {
    const std::string name = opt->get_name(false, true);
    if (opt->count() == 0 || name.rfind("--", 0) != 0) continue;
    if (name == "--threads" || name == "--quiet" || name == "--json" || name == "--help" || name == "--sizing-list-all")
      continue;
    if (opt->get_type_size() == 0 || opt->get_expected_max() == 0) {  // a flag (CLI11 flags expect 0 values)
      cmd += " " + name;
      continue;
    }
    const bool is_path = std::find(std::begin(kPaths), std::end(kPaths), name) != std::end(kPaths);
    std::string value;
    for (std::string r : opt->results()) {
      if (is_path) r = target.path(r);
      if (name == "--model-json" && r.find('=') != std::string::npos)  // MODEL=FILE
        r = r.substr(0, r.find('=') + 1) + target.path(r.substr(r.find('=') + 1));
      value += (value.empty() ? "" : ",") + r;
    }
    cmd += " " + name + " " + quote(value);
  }
  return cmd;
}

// --size-for-scene: gathers the dense table over the scene's range, prints the candidates and
// returns the smallest within the budget, its header notes saying how it was chosen.
GatherResult gather_sized(const GatherCommand& c, const GatherOptions& o, std::ostream& out)
{
  auto f = [](const char* format, double x) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, x);
    return std::string(buf);
  };
  if ((c.scene_max_speed > 0) == (c.scene_drop_height > 0))
    throw std::runtime_error("--size-for-scene needs one of --scene-max-speed and --scene-drop-height (positive)");
  if (!(c.scene_gravity > 0)) throw std::runtime_error("--scene-gravity must be positive");
  if (!(c.error_budget > 0) || !std::isfinite(c.error_budget)) throw std::runtime_error("--error-budget must be positive");
  SceneRange scene;
  std::string speed_source;
  if (c.scene_drop_height > 0) {
    scene.max_speed = std::sqrt(2.0 * c.scene_gravity * c.scene_drop_height);
    speed_source = " (a drop of " + f("%g", c.scene_drop_height) + " m at g = " + f("%g", c.scene_gravity) + " m/s^2)";
  } else {
    scene.max_speed = c.scene_max_speed;
  }
  // One bounce at the restitution takes the largest speed to about e v_max.
  scene.min_speed = c.scene_min_speed > 0 ? c.scene_min_speed : o.reference.restitution * scene.max_speed;
  scene.max_spin = c.scene_max_spin;
  const ShapeModel model = build_model(o);
  const double L = model.bounding_radius;
  const GatherOptions dense_options = scene_dense_options(o, scene, L);
  const GatherResult dense = gather(dense_options);
  const DenseTable table = dense_table(dense);
  SizingOptions so;
  so.budget = c.error_budget;
  so.threads = o.threads;
  const SizingResult s = size_table(table, so);
  out << sizing_report(table, s, c.sizing_list_all);
  const Candidate& chosen = s.candidates[s.chosen];
  const HeightCandidate& hc = s.height_candidates[s.height_chosen];
  auto count = [](const std::vector<std::vector<double>>& axes) {
    std::string t;
    std::size_t cells = 1;
    for (const auto& a : axes) {
      t += (t.empty() ? "" : " x ") + std::to_string(a.size());
      cells *= a.size();
    }
    return t + " = " + std::to_string(cells) + " cells";
  };
  std::vector<std::string> notes;
  notes.push_back("sized for a scene (tools/ref3d/sizing.hpp): speeds " + f("%.4g", scene.min_speed) + " to " +
                  f("%.4g", scene.max_speed) + " m/s" + speed_source + ", spin up to " + f("%.4g", scene.max_spin) +
                  " rad/s: spin ratios up to " + f("%.4g", scene_max_spin_ratio(scene, L)) + " (L = " + f("%.6g", L) +
                  " m; axes cut there)");
  notes.push_back("dense gathering: response " + count(dense.axes) + ", h_coll " +
                  std::to_string(dense.options.height_ratios.size()) + " samples; " + std::to_string(s.candidates.size()) +
                  " response and " + std::to_string(s.height_candidates.size()) +
                  " h_coll candidates cut from it (the trial counts below are the dense gathering's)");
  notes.push_back("error budget " + f("%g", s.budget) +
                  " (mean 2-Wasserstein miss of the interpolated response distribution over the dense cells, in "
                  "units of each cell's spread, sampling noise removed; h_coll: the mean height's miss in units of its "
                  "spread)");
  notes.push_back("chosen: response " + std::string(chosen.i16 ? "i16" : "f32") + " error " + f("%.4f", chosen.error) +
                  " (largest " + f("%.3f", chosen.max_error) + ", with noise " + f("%.4f", chosen.raw_error) +
                  "), h_coll error " + f("%.4f", hc.error) + " (largest " +
                  f("%.3f", hc.max_error) + "); table error " + f("%.4f", s.error) + ", " + std::to_string(chosen.bytes) +
                  " bytes (the dense table at f32: " +
                  std::to_string(signature_bytes(table.height_axis.size(), [&] {
                    std::vector<std::size_t> v;
                    for (const auto& a : table.axes) v.push_back(a.size());
                    return v;
                  }(), 6, table.rest_poses, false)) +
                  ")");
  return sized_result(dense, s, notes);
}

// The shape's mass and size become the table's, which add_shape and add_body check against the
// runtime's limits: a shape beyond them is refused here, before any trial runs.
void check_model_limits(const GatherOptions& o)
{
  const ShapeModel m = build_model(o);
  const auto g = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", x);
    return std::string(buf);
  };
  const std::string what = m.source.empty() ? m.name : m.source;
  if (!(m.mass.mass >= double(limits::min_mass) && m.mass.mass <= double(limits::max_mass)))
    throw std::runtime_error(what + ": mass " + g(m.mass.mass) + " kg (density " + g(o.density) +
                             " kg/m^3) is outside the runtime's " + g(double(limits::min_mass)) + " to " +
                             g(double(limits::max_mass)) + " kg: check the mesh's units (--units, --scale) and --density");
  if (!(m.bounding_radius >= double(limits::min_radius) && m.bounding_radius <= double(limits::max_radius)))
    throw std::runtime_error(what + ": bounding radius " + g(m.bounding_radius) + " m is outside the runtime's " +
                             g(double(limits::min_radius)) + " to " + g(double(limits::max_radius)) +
                             " m: check the mesh's units (--units, --scale)");
}

void run(const GatherCommand& c, const CLI::App& sub)
{
  std::ostream& out = *c.out_stream;
  std::ostream& err = *c.err_stream;
  try {
    GatherOptions o = c.options;
    o.progress = !c.quiet;
    o.with_speed = c.layout == "paper";
    o.i16 = c.precision == "i16";
    o.response_model = parse_response_model(c.response_model);
    o.response_spin = c.response_spin == "length"     ? SpinOption::length
                      : c.response_spin == "gyration" ? SpinOption::gyration
                      : c.response_spin == "energy"   ? SpinOption::energy
                                                      : SpinOption::automatic;
    o.reference.mesh_hull = c.mesh_shape == "hull";
    o.body_contacts = !c.no_body_contacts;
    // The landing data follows the body-body data in a table: a table of format 2.0 has neither.
    o.landing = !c.no_landing && o.body_contacts;
    // The settling data follows the landing data: a table of format 2.2 or older has none. It is
    // asked for: bodies then rock as long as the reference's, which a scene pays for in awake
    // bodies (tools/fidelity/README.md, "Where the time to rest goes").
    o.settle = c.settle && o.landing;
    if (!c.units.empty() && !units_scale(c.units, o.mesh_scale))
      throw std::runtime_error("--units '" + c.units + "': expected m, cm, mm, in or ft");
    o.mesh_units_given = !c.units.empty() || sub.get_option("--scale")->count() > 0;
    validate_gather_options(o);
    check_model_limits(o);
    if (c.speed_check || c.step_check || c.settings_check) {
      std::string report;
      if (c.settings_check) report += settings_check_report(o) + "\n";
      if (c.speed_check) report += speed_check_report(o, c.check_speeds, c.check_trials) + "\n";
      if (c.step_check) report += step_check_report(o) + "\n";
      if (!c.out.empty()) write_file_atomic(c.out, report);
      out << report;
      out.flush();
      return;
    }
    if (c.out.empty()) throw std::runtime_error("--out FILE is required");
    o.target = table_target(c.out, c.name_space);
    // Fail before the long run, not after it.
    auto parent = [](const std::string& f) {
      const std::filesystem::path p = std::filesystem::path(f).parent_path();
      return p.empty() ? std::filesystem::path(".") : p;
    };
    ensure_writable_directory(parent(c.out));
    if (!c.json.empty()) ensure_writable_directory(parent(c.json));
    std::vector<std::pair<GatherOptions, std::string>> model_json;
    for (const std::string& mj : c.model_json) {
      const std::size_t eq = mj.find('=');
      if (eq == std::string::npos || eq + 1 == mj.size())
        throw std::runtime_error("--model-json takes MODEL=FILE, not '" + mj + "'");
      // MODEL[:K][:f32|:i16]: the model, the empirical outcomes a cell, the precision.
      GatherOptions other = o;
      std::stringstream spec(mj.substr(0, eq));
      std::string part;
      std::getline(spec, part, ':');
      other.response_model = parse_response_model(part);
      while (std::getline(spec, part, ':')) {
        if (part == "i16" || part == "f32") other.i16 = part == "i16";
        else if (!part.empty() && part.find_first_not_of("0123456789") == std::string::npos && part.size() < 4)
          other.empirical_outcomes = std::stoi(part);
        else throw std::runtime_error("--model-json: '" + part + "' is neither an outcome count nor f32 / i16");
      }
      validate_gather_options(other);
      model_json.emplace_back(other, mj.substr(eq + 1));
      ensure_writable_directory(parent(model_json.back().second));
    }
    const std::string command = recorded_command(sub, o.target);
    GatherResult r;
    if (c.size_for_scene) r = gather_sized(c, o, out);
    else r = gather(o);
    r.model.source = o.target.path(r.model.source);
    const std::string header = header_text(r, command);
    // The runtime's own checks on the numbers written (its add_shape on the same table read
    // back from JSON): a table it would refuse is never written.
    parse_signature_json(json_text(r, command), c.out);
    if (!c.json.empty()) write_file_atomic(c.json, json_text(r, command));
    if (!c.cell_report.empty()) {
      const CellReport report = cell_report(r);
      write_file_atomic(c.cell_report, cell_report_text(r, report));
      write_file_atomic(std::filesystem::path(c.cell_report).replace_extension(".json").string(),
                        cell_report_json(report));
    }
    for (const auto& [options, file] : model_json) {
      // The same trials reduced by another model: what a gathering with that model would write.
      GatherResult other = r;
      other.options.response_model = options.response_model;
      other.options.empirical_outcomes = options.empirical_outcomes;
      other.options.i16 = options.i16;
      // The landing probabilities correct the draws of the gathering's own model and precision:
      // another model's draws stay otherwise, so its JSON leaves them out.
      other.landing = LandingFit{};
      // The settling data stays: it comes from the rest drops, whatever model reduces the
      // impacts (a JSON, unlike a header, may hold it without the landing data).
      write_file_atomic(file, json_text(other, command + " (JSON of --response-model " +
                                                   response_model_name(options.response_model) + ")"));
    }
    try {
      write_file_atomic(c.out, header);
    } catch (...) {
      // Both files or neither.
      if (!c.json.empty()) {
        std::error_code ec;
        std::filesystem::remove(c.json, ec);
      }
      throw;
    }
    out << summary_text(r);
    out << "wrote " << c.out << (c.json.empty() ? std::string() : " and " + c.json) << "\n";
    out.flush();
  } catch (const std::exception& e) {
    err << "statsim gather: error: " << e.what() << "\n";
    err.flush();
    throw CLI::RuntimeError(1);
  }
}

void add_gather(CLI::App& app, std::ostream* out, std::ostream* err)
{
  auto c = std::make_shared<GatherCommand>();
  c->out_stream = out;
  c->err_stream = err;
  GatherOptions& o = c->options;
  ReferenceSettings& s = o.reference;
  CLI::App* sub = app.add_subcommand(
      "gather",
      "Gather a 3D shape's statistical signature with Bullet (paper 3.2: h_coll, response tables, rest poses) "
      "and write it as a C++ table");
  auto* shape = sub->add_option("--shape", o.shape, "Built-in shape: box, lshape or bunny (tools/meshes/NAME.obj)")
                    ->check(CLI::IsMember({"box", "lshape", "bunny"}))
                    ->capture_default_str();
  auto* mesh = sub->add_option("--mesh", o.mesh_file,
                               "Any closed, outward-wound mesh in metres: OBJ, STL, PLY, glTF/GLB or another format "
                               "assimp reads (btGImpactMeshShape)")
                   ->excludes(shape);
  auto* units = sub->add_option("--units", c->units, "Unit of the mesh's coordinates: m, cm, mm, in or ft")
                    ->check(CLI::IsMember({"m", "cm", "mm", "in", "ft"}))
                    ->needs(mesh);
  sub->add_option("--scale", o.mesh_scale, "Metres per unit of the mesh's coordinates (instead of --units)")
      ->excludes(units)
      ->needs(mesh);
  sub->add_option("--box-size", o.box_size, "A box of this size X,Y,Z in m instead (btBoxShape)")
      ->delimiter(',')
      ->expected(3)
      ->excludes(shape)
      ->excludes(mesh);
  sub->add_option("--layout", c->layout,
                  "Response axes: scaled = (cos theta, cos phi, spin ratio), impacts at --speed; "
                  "paper = with the speed |V-| as a fourth axis (26 speeds)")
      ->check(CLI::IsMember({"scaled", "paper"}))
      ->capture_default_str();
  sub->add_option("--trials", o.trials, "Impacts per response cell (>= 2)")->capture_default_str();
  sub->add_option("--height-trials", o.height_trials, "Flights per h_coll sample (>= 2)")->capture_default_str();
  sub->add_option("--rest-drops", o.rest_drops, "Drops for the rest poses")->capture_default_str();
  sub->add_option("--rest-min-frequency", o.rest_min_frequency,
                  "Rest poses: keep every pose of a family (poses equivalent under the shape's symmetry) seen in more "
                  "than this fraction of the settled drops together, in [0, 1)")
      ->capture_default_str();
  sub->add_option("--rest-max-dropped", o.rest_max_dropped,
                  "Rest poses: then keep rarer families, most frequent first, while more than this fraction of the "
                  "settled drops is in poses not kept, in [0, 1] (1: never)")
      ->capture_default_str();
  sub->add_option("--seed", o.seed, "Random seed (same seed, same bytes, any --threads)")->capture_default_str();
  sub->add_option("--precision", c->precision, "Response tables as f32 or as i16 with per-table scale and offset")
      ->check(CLI::IsMember({"f32", "i16"}))
      ->capture_default_str();
  sub->add_option("--response-model", c->response_model,
                  "How a cell's spread is stored: paper = a standard deviation per component (independent "
                  "Gaussians, paper 3.2.2); correlated = a Cholesky factor of the 6x6 covariance; empirical = "
                  "--empirical-outcomes stored trial outcomes")
      ->check(CLI::IsMember({"paper", "correlated", "empirical"}))
      ->capture_default_str();
  sub->add_option("--response-spin", c->response_spin,
                  "What the response table's spin measures: length = W+ L / |V-| (the paper's); gyration = K W+ / "
                  "|V-|, K the radii of gyration at the body's orientation, so a draw's rotational energy does not "
                  "depend on how the body is turned (needs the landing data); energy = gyration, and the trials "
                  "and the table's spin-ratio coordinate measure the incoming spin by its energy too, |K W-| L / "
                  "(k |V-|); auto = energy only when the runtime's draws by gyration match the trials' spins "
                  "measurably better, else length (statsim/signature.hpp, ResponseSpin)")
      ->check(CLI::IsMember({"auto", "length", "gyration", "energy"}))
      ->capture_default_str();
  sub->add_option("--empirical-outcomes", o.empirical_outcomes,
                  "Outcomes stored per cell by --response-model empirical (1 to --trials, at most 64)")
      ->capture_default_str();
  sub->add_option("--out", c->out, "Output header (tables/NAME.hpp); with a check, the report");
  sub->add_option("--json", c->json, "Also dump the signature as JSON to this file");
  sub->add_option("--cell-report", c->cell_report,
                  "Also write how far the paper's model is from the trials, per cell (markdown FILE.md and FILE.json: "
                  "KS from the fitted Gaussian, correlations, bimodality)");
  sub->add_option("--model-json", c->model_json,
                  "MODEL[:K][:f32|:i16]=FILE: also write the JSON of the same gathering with response model MODEL "
                  "(K: its --empirical-outcomes; the precision) (repeatable; for comparing models on the same trials)");
  sub->add_option("--threads", o.threads, "Worker threads (0 = all hardware threads)")->capture_default_str();
  sub->add_option("--name", o.name, "Table name (default: the shape's name)");
  sub->add_option("--namespace", c->name_space, "C++ namespace of the table")->capture_default_str();
  sub->add_option("--speed", o.speed, "|V-| of the impacts of the scaled layout, m/s")->capture_default_str();
  sub->add_option("--speeds", o.speeds, "Speed axis of --layout paper, m/s (comma-separated)")->delimiter(',');
  // A table axis: comma-separated samples, the default shown in --help.
  const auto axis_option = [sub](const char* flag, std::vector<double>& axis, const char* help) {
    sub->add_option(flag, axis, help)->delimiter(',')->capture_default_str();
  };
  axis_option("--cos-theta", o.cos_theta, "Response axis: cos theta samples, increasing, in (0, 1]");
  axis_option("--cos-phi", o.cos_phi, "Response axis: cos phi samples, increasing, in [-1, 1]");
  axis_option("--spin-ratios", o.spin_ratios, "Response axis: spin ratios |W-| L / |V-|, increasing, >= 0");
  axis_option("--height-ratios", o.height_ratios, "h_coll axis: spin ratios, increasing, >= 0");
  sub->add_option("--restitution", s.restitution, "Coefficient of restitution (reference and V_particle+)")
      ->capture_default_str();
  sub->add_option("--friction", s.friction, "Coulomb friction coefficient (reference and V_particle+)")
      ->capture_default_str();
  sub->add_option("--restitution-threshold", s.restitution_threshold,
                  "Approach speed below which contacts do not bounce, m/s (reference and V_particle+)")
      ->capture_default_str();
  sub->add_option("--rolling-resistance", o.rolling_resistance,
                  "Rolling resistance written to the signature's material (used by the runtime's spheres only)")
      ->capture_default_str();
  sub->add_option("--dt", s.dt, "Bullet time step, s")->capture_default_str();
  sub->add_option("--solver-iterations", s.solver_iterations, "Bullet solver iterations")->capture_default_str();
  sub->add_option("--margin", s.margin, "Collision margin of the body's Bullet shape, m")->capture_default_str();
  sub->add_option("--mesh-shape", c->mesh_shape,
                  "Bullet shape of a mesh: gimpact (the full mesh) or hull (its convex hull; the same against a plane)")
      ->check(CLI::IsMember({"gimpact", "hull"}))
      ->capture_default_str();
  sub->add_option("--density", o.density, "Density, kg/m^3 (sets the recorded mass only)")->capture_default_str();
  sub->add_flag("--no-landing", c->no_landing,
                "Leave out the landing data (a table of format 2.1): how often a body striking the ground under "
                "gravity stays on it, against the response tables' draws (statsim/signature_landing.hpp); "
                "--no-body-contacts leaves it out too");
  sub->add_option("--landing-trials", o.landing_trials, "Landing: impacts with gravity per cell (>= 1)")
      ->capture_default_str();
  axis_option("--landing-froude", o.landing_froude, "Landing axis: Froude numbers |V-|^2 / (g L), increasing, >= 0 (0: no trials, p = 0)");
  sub->add_option("--landing-hop", o.landing_hop, "Landing: rise over L below which an impact counts as a stay")
      ->capture_default_str();
  sub->add_option("--landing-time", o.landing_time, "Landing: s after which an impact not flown off counts as a stay")
      ->capture_default_str();
  sub->add_flag("--response-flight", o.response_flight,
                "Response trials under gravity, each to the first flight that rises --landing-hop L (the chain of "
                "contacts a drop's first flight ends); a trial not flown off within --landing-time keeps the "
                "gravity-free outcome");
  sub->add_flag("--settle", c->settle,
                "Add the settling data (a table of format 2.3; needs the landing data): per rest pose, quantiles "
                "of the time a rest drop took from its last moment at --settle-speed to staying below "
                "--quiet-speed (statsim/signature_settle.hpp)");
  sub->add_option("--settle-quantiles", o.settle_quantiles,
                  "Settling: quantiles of the settling time per rest pose (1 to " +
                      std::to_string(max_settle_quantiles) + ")")
      ->capture_default_str();
  sub->add_option("--settle-speed", o.settle_speed,
                  "Settling: m/s; the settling time starts at the last step this fast (centre, or farthest point by "
                  "spin); the default is the runtime's WorldDef::settle_speed")
      ->capture_default_str();
  sub->add_option("--quiet-speed", o.quiet_speed,
                  "Settling: m/s, below --settle-speed; the settling time ends when the body stays slower for good")
      ->capture_default_str();
  sub->add_flag("--no-body-contacts", c->no_body_contacts,
                "Leave out the body-body data (a table of format 2.0, as written before it existed)");
  sub->add_option("--support-size", o.support_size, "Body-body: support map nodes a side, S (6 S^2 values)")
      ->capture_default_str();
  sub->add_option("--contact-faces", o.contact_faces, "Body-body: largest hull faces stored (fewer if the hull has fewer)")
      ->capture_default_str();
  sub->add_option("--pair-trials", o.pair_trials, "Body-body: pair flights per h_coll spin ratio")->capture_default_str();
  sub->add_option("--packing-piles", o.packing_piles, "Body-body: Bullet drop piles for the packing ratios")
      ->capture_default_str();
  sub->add_option("--packing-bins", o.packing_bins, "Body-body: Bullet bins of stacked bodies for the packing ratios")
      ->capture_default_str();
  sub->add_option("--packing-count", o.packing_count, "Body-body: bodies per pile and per bin")->capture_default_str();
  sub->add_flag("--quiet", c->quiet, "No progress on stderr");
  sub->add_flag("--size-for-scene", c->size_for_scene,
                "Size the table for a scene (tools/ref3d/sizing.hpp): gather densely over the scene's range (the axes "
                "given, spin ratios cut at s_max = max spin x L / min speed, paper layout: speeds cut to the range), "
                "then write the smallest subset table (per-axis sample counts, f32 or i16) whose mean error against "
                "the dense table, in units of each cell's spread, is within --error-budget; prints the candidates");
  sub->add_option("--scene-max-speed", c->scene_max_speed, "Scene: largest impact speed, m/s (e.g. 4.4)");
  sub->add_option("--scene-drop-height", c->scene_drop_height,
                  "Scene: drop height H, m, instead of --scene-max-speed (largest speed sqrt(2 g H))");
  sub->add_option("--scene-gravity", c->scene_gravity, "Scene: g for --scene-drop-height, m/s^2")->capture_default_str();
  sub->add_option("--scene-min-speed", c->scene_min_speed,
                  "Scene: smallest impact speed that matters, m/s (default: restitution x largest speed, one bounce)");
  sub->add_option("--scene-max-spin", c->scene_max_spin,
                  "Scene: largest spin |w|, rad/s, counting the spin impacts give (of the order of |V-| / L), e.g. 20")
      ->capture_default_str();
  sub->add_option("--error-budget", c->error_budget,
                  "Sizing: largest mean error accepted: the miss of the candidate's response distribution against the "
                  "dense table's, in units of the response's own spread, the gathering's sampling noise removed")
      ->capture_default_str();
  sub->add_flag("--sizing-list-all", c->sizing_list_all, "Sizing: print every candidate, not only the improving ones");
  sub->add_flag("--settings-check", c->settings_check,
                "Print the reference-settings check (a face-down cube at normal incidence) instead of gathering");
  sub->add_flag("--speed-check", c->speed_check,
                "Print normalised response means at several |V-| for a few cells instead of gathering");
  sub->add_flag("--step-check", c->step_check,
                "Print the statistics of a small gathering at --dt and --dt/2 instead of gathering");
  sub->add_option("--check-speeds", c->check_speeds, "Speeds of --speed-check, m/s")->delimiter(',')->capture_default_str();
  sub->add_option("--check-trials", c->check_trials, "Impacts per cell and speed of --speed-check")->capture_default_str();
  sub->callback([c, sub]() { run(*c, *sub); });
}

void add_gather_pairs(CLI::App& app)
{
  struct Command {
    PairOptions o;
    std::string json, report;
    bool quiet = false;
  };
  auto c = std::make_shared<Command>();
  PairOptions& o = c->o;
  CLI::App* sub = app.add_subcommand(
      "gather-pairs",
      "Body-body statistics of a 3D shape with Bullet: centre distance at first contact of two bodies against spin, "
      "the hull's support cube map and its error, packing of touching pairs in reference piles, pair responses "
      "(tools/ref3d/pairs.hpp)");
  auto* shape = sub->add_option("--shape", o.shape.shape, "Built-in shape: box, lshape or bunny")
                    ->check(CLI::IsMember({"box", "lshape", "bunny"}))
                    ->capture_default_str();
  auto* mesh = sub->add_option("--mesh", o.shape.mesh_file, "Any closed OBJ mesh (GImpact)")->excludes(shape);
  sub->add_option("--box-size", o.shape.box_size, "A box of this size X,Y,Z in m instead")
      ->delimiter(',')
      ->expected(3)
      ->excludes(shape)
      ->excludes(mesh);
  sub->add_option("--name", o.shape.name, "Name in the outputs (default: the shape's)");
  sub->add_option("--spin-ratios", o.spin_ratios, "Spin ratios |w| L / |v| of the pair flights")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--trials", o.trials, "Pair flights per spin ratio")->capture_default_str();
  sub->add_option("--height-trials", o.height_trials, "Plane flights for h_coll at spin ratio 0")->capture_default_str();
  sub->add_option("--support-sizes", o.support_sizes, "Cube-map sizes S whose error is measured")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--support-size", o.support_size, "S of the stored cube map (6 S^2 values)")->capture_default_str();
  sub->add_option("--piles", o.piles, "Reference piles (drop_scene3 seeds 1..N; 0: none)")->capture_default_str();
  sub->add_option("--pile-count", o.pile_count, "Bodies per pile")->capture_default_str();
  sub->add_option("--pile-dt", o.pile_dt, "Bullet step of the piles, s")->capture_default_str();
  sub->add_option("--pile-time", o.pile_time, "Longest pile run, s")->capture_default_str();
  sub->add_option("--bin", o.bin,
                  "Piles in a bin instead: walls at +-BIN L, bodies stacked on a lattice at random orientations (0: "
                  "drop_scene3)")
      ->capture_default_str();
  sub->add_option("--touch-distance", o.touch_distance, "Manifold points this close are contacts, m")
      ->capture_default_str();
  sub->add_option("--response-trials", o.response_trials, "Pair impacts compared with the runtime (0: none)")
      ->capture_default_str();
  sub->add_option("--speed", o.speed, "Relative approach speed of the pair flights and impacts, m/s")
      ->capture_default_str();
  sub->add_option("--seed", o.shape.seed, "Random seed")->capture_default_str();
  sub->add_option("--threads", o.shape.threads, "Worker threads (0 = all hardware threads)")->capture_default_str();
  sub->add_option("--json", c->json, "Write the statistics as JSON to this file");
  sub->add_option("--report", c->report, "Write the markdown report to this file");
  sub->add_flag("--quiet", c->quiet, "No progress on stderr");
  sub->callback([c, sub]() {
    try {
      PairOptions opts = c->o;
      opts.shape.progress = !c->quiet;
      std::string cmd = "build/bin/statsim gather-pairs";  // as run from the repository root
      for (const CLI::Option* opt : sub->get_options()) {
        const std::string name = opt->get_name(false, true);
        if (opt->count() == 0 || name.rfind("--", 0) != 0 || name == "--threads" || name == "--quiet" ||
            name == "--json" || name == "--report")
          continue;
        std::string value;
        for (const std::string& r : opt->results()) value += (value.empty() ? "" : ",") + r;
        cmd += " " + name + " " + quote(value);
      }
      const PairResult r = gather_pairs(opts);
      const std::string md = pairs_markdown(r, cmd);
      if (!c->json.empty()) write_file_atomic(c->json, pairs_json(r, cmd));
      if (!c->report.empty()) write_file_atomic(c->report, md);
      std::cout << md;
    } catch (const std::exception& e) {
      std::cerr << "statsim gather-pairs: error: " << e.what() << "\n";
      throw CLI::RuntimeError(1);
    }
  });
}

}  // namespace

void register_ref3d_commands(CLI::App& app)
{
  add_gather(app, &std::cout, &std::cerr);
  add_gather_pairs(app);
  add_compare_command(app);
}

int run_gather_command(const std::vector<std::string>& args, std::ostream& out, std::ostream& err)
{
  CLI::App app{"statsim"};
  app.require_subcommand(1);
  add_gather(app, &out, &err);
  std::vector<std::string> argv = {"gather"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::reverse(argv.begin(), argv.end());  // CLI11's vector form takes the arguments in reverse
  try {
    app.parse(argv);
  } catch (const CLI::ParseError& e) {
    std::ostringstream o, x;
    const int rc = app.exit(e, o, x);
    out << o.str();
    err << x.str();
    return rc;
  }
  return 0;
}

}  // namespace statsim::tools
