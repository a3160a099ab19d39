// See gather_emit.hpp.
#include "ref3d/gather_emit.hpp"

#include "common/body_contacts.hpp"
#include "common/format.hpp"
#include "common/table_writer.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/gather_body_contacts.hpp"
#include "ref3d/response_fit.hpp"
#include "statsim/signature.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace statsim::tools::ref3d {

std::string vec3(const Eigen::Vector3d& v, const char* f)
{
  return "(" + fmt(f, v.x()) + ", " + fmt(f, v.y()) + ", " + fmt(f, v.z()) + ")";
}

namespace {

// The mean over the landing cells that ran trials (Froude number above 0).
double mean_of(const LandingFit& l, const std::vector<double>& v)
{
  double s = 0;
  std::size_t n = 0;
  for (std::size_t c = 0; c < v.size(); ++c)
    if (l.froude[c % l.froude.size()] > 0) s += v[c], ++n;
  return n == 0 ? 0.0 : s / static_cast<double>(n);
}

std::string hex64(std::uint64_t x)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(x));
  return buf;
}

std::string shape_description(const GatherResult& r)
{
  const ShapeModel& m = r.model;
  const double margin = r.options.reference.margin;
  std::string s;
  switch (m.kind) {
    case ShapeKind::box: {
      const BodyBox& b = m.boxes.at(0);
      s = "btBoxShape, half extents " + vec3(b.rotation.cwiseAbs() * b.half_extents) + " m";
      break;
    }
    case ShapeKind::compound:
      s = "btCompoundShape of " + std::to_string(m.boxes.size()) + " btBoxShapes (tools/mesh/shapes.hpp)";
      break;
    case ShapeKind::mesh:
      if (r.options.reference.mesh_hull)
        s = "btConvexHullShape of the mesh's convex hull (" + std::to_string(m.hull.size()) + " vertices)";
      else
        s = "btGImpactMeshShape of the full mesh (" + std::to_string(m.body_mesh.vertices.size()) + " vertices, " +
            std::to_string(m.body_mesh.triangles.size()) + " triangles)";
      break;
  }
  return s + ", margin " + num(margin) + " m; ground: " +
         (r.ground == "box" ? "a static btBoxShape (top face z = 0)" : "btStaticPlaneShape z = 0");
}

std::vector<std::string> option_lines(const GatherResult& r)
{
  const GatherOptions& o = r.options;
  const ReferenceSettings& s = o.reference;
  std::vector<std::string> l;
  l.push_back("layout " + std::string(o.with_speed ? "with_speed (cos theta, cos phi, |V-|, spin ratio)"
                                                     : "scaled (cos theta, cos phi, spin ratio)") +
              (o.with_speed ? "" : ", impacts at |V-| = " + num(o.speed) + " m/s") +
              (o.response_flight ? ", each to the first flight rising " + num(o.landing_hop) + " L under gravity" : "") + "; precision " +
              (o.i16 ? "i16" : "f32") + "; seed " + std::to_string(o.seed) + "; response model " +
              response_model_name(o.response_model) +
              (o.response_model == ResponseModel::empirical
                   ? " (" + std::to_string(o.empirical_outcomes) + " outcomes a cell)"
                   : std::string()));
  l.push_back("restitution " + num(s.restitution) + ", friction " + num(s.friction) + ", restitution threshold " +
              num(s.restitution_threshold) + " m/s, rolling resistance (runtime only) " + num(o.rolling_resistance));
  l.push_back("dt " + num(s.dt) + " s, " + std::to_string(s.solver_iterations) + " solver iterations, warm starting " +
              (s.warm_starting ? "on" : "off") + ", split impulse " + (s.split_impulse ? "always" : "Bullet's default") +
              ", erp " + num(s.erp) + ", speculative contacts " + (s.speculative_contacts ? "on" : "off") +
              ", density " + num(o.density) + " kg/m^3");
  l.push_back("h_coll: " + std::to_string(o.height_trials) + " flights per ratio; responses: " +
              std::to_string(o.trials) + " impacts per cell (phi pooled at zero spin), time limit " +
              num(o.max_impact_time) + " s; rest: " + std::to_string(o.rest_drops) + " drops, still below " +
              num(o.still_speed) + " m/s for " + num(o.still_time) + " s (limit " + num(o.max_drop_time) +
              " s), clusters within " + num(o.rest_tolerance_deg) + " deg, kept above " +
              num(o.rest_min_frequency) +
              (o.rest_max_dropped == GatherOptions().rest_max_dropped
                   ? std::string()
                   : ", rare families kept while more than " + num(o.rest_max_dropped) + " is dropped"));
  return l;
}

// What the body-body data is and how it was measured (deterministic: no times).
std::vector<std::string> body_contact_lines(const GatherResult& r)
{
  const GatherOptions& o = r.options;
  const BodyContactData& c = r.contact;
  std::vector<std::string> l;
  l.push_back("support map S = " + std::to_string(c.support_size) + " (" +
              std::to_string(6 * c.support_size * c.support_size) + " values, " + (o.i16 ? "i16" : "f32") +
              "; at most " + fmt("%.3g", c.support_bound) + " m above the hull's support), " +
              std::to_string(c.face_count()) + " of the hull's " + std::to_string(c.hull_faces) +
              " faces, mesh frame from the principal axes and centre of mass");
  l.push_back("pair distance: " + std::to_string(c.pair_flights) + " pair flights (" + std::to_string(o.pair_trials) +
              " per h_coll spin ratio, head-on at " + num(o.speed) + " m/s relative speed)");
  l.push_back("packing: " + std::to_string(c.piles) + " drop piles and " + std::to_string(c.bins) +
              (c.bins == 1 ? " bin" : " bins") + " (walls " + num(2 * kPackingBinHalfWidth) + " L apart) of " + std::to_string(o.packing_count) +
              " bodies in Bullet, seeds 1.., until all sleep (at most 20 s at 1/240 s; " + std::to_string(c.asleep) +
              " of " + std::to_string(c.piles + c.bins) + " all asleep; " + std::to_string(c.pile_steps) +
              " Bullet steps in all); " + std::to_string(c.total_pairs) + " touching pairs");
  const std::string p = "packing d / the runtime's hull distance (find_hull_witness on this table, ratio 1):" +
                        packing_line(c);
  l.push_back(p);
  return l;
}

}  // namespace

std::string header_text(const GatherResult& r, const std::string& command)
{
  const GatherOptions& o = r.options;
  const ShapeModel& m = r.model;
  std::ostringstream h;
  h << table_banner("gather", command, o.target);
  for (const std::string& line : option_lines(r)) h << "// Options: " << line << "\n";
  for (const std::string& line : r.notes) h << "// Sized: " << line << "\n";
  h << "// Input: " << m.source;
  if (m.source_hash != 0) h << " (FNV-1a 64 " << hex64(m.source_hash) << ")";
  h << ", " << m.body_mesh.vertices.size() << " vertices, " << m.body_mesh.triangles.size() << " triangles\n";
  h << "// Reference: Bullet " << bullet_version() << " (double precision); " << shape_description(r) << "\n";
  h << "// Mass properties: volume " << fmt("%.9g", m.mass.volume) << " m^3, mass " << fmt("%.9g", m.mass.mass)
    << " kg, principal moments " << vec3(m.mass.principal_moments, "%.9g") << " kg m^2, bounding radius "
    << fmt("%.9g", m.bounding_radius) << " m (= L of the spin ratios)\n";
  const long long flights = r.height_flights > 0 ? r.height_flights
                                                 : static_cast<long long>(r.height_mean.size()) * o.height_trials;
  h << "// Trials: " << flights << " flights, "
    << r.response_trials << " impacts (" << r.time_limited << " hit the time limit"
    << (o.response_flight ? ", " + std::to_string(r.no_flight) + " not flown off: gravity-free outcome" : std::string())
    << "), " << o.rest_drops
    << " rest drops (" << r.unsettled << " did not settle)\n";
  h << "// Rest poses (body-frame up, height, frequency, family):";
  for (const RestPose& p : r.rest)
    h << " " << vec3(p.normal, "%.4f") << " " << fmt("%.5f", p.height) << " m " << fmt("%.3f", p.frequency)
      << " family " << p.family << ";";
  h << "\n";
  h << "// Rest poses dropped: " << fmt("%.3f", r.rest_dropped) << " of the settled drops (" << r.rest_rare.size()
    << " poses; families of poses equivalent under the shape's symmetry kept together)\n";
  const std::vector<double> spread = response_spread(r);
  const std::size_t spread_size = spread.size() / std::max<std::size_t>(1, r.response_mean.size() / 6);
  Quantized qm, qs;
  if (o.i16) {
    qm = quantize(to_float(r.response_mean));
    qs = quantize(to_float(spread));
    h << "// i16 dequantization error: mean table " << fmt("%.3g", qm.worst_error) << ", spread table "
      << fmt("%.3g", qs.worst_error) << " (worst " << fmt("%.3g", std::max(qm.worst_error, qs.worst_error)) << ")\n";
  }
  const BodyContactData& c = r.contact;
  // A result without body-body data (made by hand, or with --no-body-contacts) writes a table of format 2.0.
  const bool contact = o.body_contacts && !r.contact.support.empty();
  if (contact) {
    for (const std::string& line : body_contact_lines(r)) h << "// Body-body: " << line << "\n";
    double error = 0.0;
    contact_entries(c, o.i16, &error);
    if (o.i16) h << "// Body-body: support map i16 dequantization error " << fmt("%.3g", error) << " m\n";
  }
  // Landing data (format 2.2) follows the body-body data in the initialiser, so it needs it.
  const bool landing = contact && r.landing.present();
  if (landing) {
    const LandingFit& l = r.landing;
    h << "// Landing: " << l.trials << " impacts with gravity (" << o.landing_trials
      << " per cell of cos theta x spin ratio x Froude number |V-|^2 / (g L)), a stay when the centre never rises "
      << num(l.hop) << " L before rest or " << num(o.landing_time) << " s; trials' stays "
      << fmt("%.3f", mean_of(l, l.stays)) << ", the response draws' " << fmt("%.3f", mean_of(l, l.draw_stays))
      << ", landing probability " << fmt("%.3f", mean_of(l, l.probability)) << " (means over the cells above F = 0)\n";
  }
  // Settling data (format 2.3) follows the landing data in the initialiser, so it needs it.
  const bool settle = landing && r.settle.present();
  if (settle) {
    const SettleFit& t = r.settle;
    h << "// Settling: the " << o.rest_drops << " rest drops (" << t.time_limited
      << " at the time limit, counted with the time they had), each from its last step at " << num(t.settle_speed)
      << " m/s or faster (centre, or farthest point by spin) to staying below " << num(t.quiet_speed) << " m/s; "
      << t.quantiles << " quantiles per rest pose; drops and mean settling time per pose:";
    for (std::size_t i = 0; i < t.drops.size(); ++i) h << " " << t.drops[i] << " " << fmt("%.3f", t.mean[i]) << " s;";
    h << "\n";
  }
  // The spin measure (format 2.4) comes last in the initialiser, after the landing data it needs
  // (gather_spin.hpp never takes gyration without it) and the settling data or its `{}`.
  const bool gyration = r.spin != ResponseSpin::length, energy = r.spin == ResponseSpin::energy;
  if (gyration && !landing) throw std::runtime_error("a table with the spin by gyration needs the landing data");
  if (gyration) {
    const SpinTest& t = r.spin_test;
    if (energy)
      h << "// Response spin: by energy, K W+ / |V-|, looked up at |K W-| L / (k |V-|) (statsim::ResponseSpin::energy)";
    else
      h << "// Response spin: by gyration, K W+ / |V-| (statsim::ResponseSpin::gyration)";
    if (t.run)
      h << "; test: KS of |V+| and |W+| against the trials by gyration " << fmt("%.4f", t.ks_gyration)
        << ", by length " << fmt("%.4f", t.ks_length) << " (auto takes gyration below length - "
        << fmt("%.4f", t.critical) << "; " << t.trials << " draws); energy guard " << fmt("%.4f", t.clamp_gyration)
        << ", by length " << fmt("%.4f", t.clamp_length);
    h << "\n";
  }
  h << table_prologue(o.name, energy ? 5 : gyration ? 4 : settle ? 3 : landing ? 2 : contact ? 1 : 0, o.target);
  const std::size_t a0 = r.axes[0].size(), a1 = r.axes[1].size(), a2 = r.axes[2].size(),
                    a3 = r.axes.size() > 3 ? r.axes[3].size() : 1;
  h << table_definition(std::string(o.i16 ? "SignatureQ16" : "Signature") + "<3, " +
                            std::to_string(r.height_mean.size()) + ", " + std::to_string(a0) + ", " +
                            std::to_string(a1) + ", " + std::to_string(a2) + ", " + std::to_string(a3) + ", " +
                            std::to_string(r.rest.size()) + ", " + std::to_string(spread_size) +
                            (contact ? ", " + contact_type(c, o.i16) : std::string()) +
                            (landing ? ", LandingData<" + std::to_string(r.landing.cos_theta.size()) + ", " +
                                           std::to_string(r.landing.spin_ratio.size()) + ", " +
                                           std::to_string(r.landing.froude.size()) + ">"
                                     : std::string()) +
                            (settle ? ", SettleData<" + std::to_string(r.rest.size()) + ", " +
                                          std::to_string(r.settle.quantiles) + ">"
                                    : std::string()) +
                            ">",
                        o.name, o.target);
  // Short arrays on one line, long ones 8 values a line (response tables 6, one cell; normals 3).
  const auto array = [](const std::vector<double>& v, std::size_t per_line = 8) {
    return hex_float_array(v, ArrayStyle{per_line, 6, true});
  };
  h << table_entry("\"" + o.name + "\"");
  h << table_entry(hex_float(m.bounding_radius), "length L, m");
  h << table_entry(hex_float(m.bounding_radius), "bounding radius, m");
  h << table_entry(hex_float(m.mass.mass), "mass, kg");
  h << table_entry(array({m.unit_inertia.x(), m.unit_inertia.y(), m.unit_inertia.z()}), "principal moments / mass, m^2");
  h << table_entry("{" + hex_floats({o.reference.restitution, o.reference.friction, o.rolling_resistance}) + "}",
                   "material");
  h << table_entry(hex_float(o.reference.restitution_threshold), "restitution threshold, m/s");
  h << table_entry(std::string("statsim::ResponseLayout::") + (o.with_speed ? "with_speed" : "scaled"));
  const char* model_enum[] = {"independent_gaussian", "correlated_gaussian", "empirical"};
  h << table_entry(std::string("statsim::ResponseModel::") + model_enum[static_cast<int>(o.response_model)]);
  h << table_entry(std::to_string(r.axes.size()) + "u", "response axes");
  h << table_comment("h_coll: spin ratio, mean, std (m)");
  h << table_entry(array(o.height_ratios));
  h << table_entry(array(r.height_mean));
  h << table_entry(array(r.height_std));
  h << table_comment(std::string("response axes: cos theta, cos phi, ") + (o.with_speed ? "speed (m/s), " : "") +
                     "spin ratio" + (o.with_speed ? "" : ", (unused)"));
  for (std::size_t a = 0; a < 4; ++a) h << table_entry(array(a < r.axes.size() ? r.axes[a] : std::vector<double>{0.0}));
  const char* spread_text[] = {"std per component",
                               "Cholesky factor of the covariance, lower triangle row by row",
                               "stored outcomes minus their mean, one after another"};
  h << table_comment(std::string("response mean per cell: w_x, w_y, w_z (") + (gyration ? "K W+ / |V-|" : "W+ L/|V-|") +
                     "), dv_x, dv_y, dv_z ((V+ - V_particle+)/|V-|)");
  h << table_comment(std::string("then the spread per cell: ") + spread_text[static_cast<int>(o.response_model)]);
  if (o.i16) {
    // statsim::Quantized16: {scale, offset, {{values}}}.
    for (const Quantized* q : {&qm, &qs})
      h << table_entry("{" + hex_floats({q->scale, q->offset}) + ", " + int_array(q->q, ArrayStyle{6, 6, false}) + "}",
                       q == &qm ? "mean: scale, offset, values" : "spread: scale, offset, values");
  } else {
    h << table_entry(array(r.response_mean, 6));
    h << table_entry(array(spread, 6));
  }
  std::vector<double> normals, heights, freqs;
  for (const RestPose& p : r.rest) {
    normals.insert(normals.end(), {p.normal.x(), p.normal.y(), p.normal.z()});
    heights.push_back(p.height);
    freqs.push_back(p.frequency);
  }
  h << table_comment("rest poses: body-frame up vectors, centre heights (m), frequencies");
  h << table_entry(array(normals, 3));
  h << table_entry(array(heights));
  h << table_entry(array(freqs));
  if (contact) h << contact_entries(c, o.i16);
  if (landing) {
    const LandingFit& l = r.landing;
    h << table_comment("landing data (statsim::LandingView): hop (over L); axes cos theta, spin ratio, Froude number; "
                       "landing probability per cell (above 0: extra stays; below 0: stays drawn again)");
    h << "    {\n";
    h << "      " << hex_float(l.hop) << ",\n";
    for (const std::vector<double>* a : {&l.cos_theta, &l.spin_ratio, &l.froude, &l.probability})
      h << "      " << hex_float_array(*a, ArrayStyle{a == &l.probability ? l.froude.size() : 8, 8, true, 6}) << ",\n";
    h << "    },\n";
  }
  if (settle) {
    const SettleFit& t = r.settle;
    h << table_comment("settling data (statsim::SettleView): per rest pose, in their order, the settling time (s) "
                       "at the probabilities (k + 1/2) / " + std::to_string(t.quantiles));
    h << "    {\n";
    h << "      " << hex_float_array(t.time, ArrayStyle{static_cast<std::size_t>(t.quantiles), 8, true, 6}) << ",\n";
    h << "    },\n";
  }
  if (gyration) {
    if (!settle) h << table_entry("{}", "no settling data");
    if (energy)
      h << table_entry("statsim::ResponseSpin::energy", "spin components: K W+ / |V-|; spin ratio |K W-| L / (k |V-|)");
    else
      h << table_entry("statsim::ResponseSpin::gyration", "spin components: K W+ / |V-|");
  }
  h << table_epilogue(o.target);
  return h.str();
}

std::string json_text(const GatherResult& r, const std::string& command)
{
  using json = nlohmann::ordered_json;
  const GatherOptions& o = r.options;
  const ShapeModel& m = r.model;
  auto fl = [](const std::vector<double>& v) {
    json a = json::array();
    for (double x : v) a.push_back(static_cast<double>(static_cast<float>(x)) + 0.0);
    return a;
  };
  json j;
  j["generator"] = "statsim gather";
  j["command"] = command;
  j["name"] = o.name;
  j["source"] = m.source;
  j["source_fnv1a64"] = hex64(m.source_hash);
  j["bullet"] = bullet_version();
  j["seed"] = o.seed;
  if (!r.notes.empty()) j["sizing"] = r.notes;
  j["reference"] = {{"shape", shape_description(r)},
                    {"restitution", o.reference.restitution},
                    {"friction", o.reference.friction},
                    {"restitution_threshold", o.reference.restitution_threshold},
                    {"dt", o.reference.dt},
                    {"solver_iterations", o.reference.solver_iterations},
                    {"warm_starting", o.reference.warm_starting},
                    {"split_impulse", o.reference.split_impulse},
                    {"erp", o.reference.erp},
                    {"speculative_contacts", o.reference.speculative_contacts},
                    {"margin", o.reference.margin},
                    {"ground", r.ground}};
  j["density"] = o.density;
  j["volume"] = m.mass.volume;
  j["mass"] = static_cast<double>(static_cast<float>(m.mass.mass));
  j["inertia"] = {m.mass.principal_moments.x(), m.mass.principal_moments.y(), m.mass.principal_moments.z()};
  j["unit_inertia"] = fl({m.unit_inertia.x(), m.unit_inertia.y(), m.unit_inertia.z()});
  j["bounding_radius"] = static_cast<double>(static_cast<float>(m.bounding_radius));
  j["length"] = static_cast<double>(static_cast<float>(m.bounding_radius));
  j["material"] = {{"restitution", static_cast<double>(static_cast<float>(o.reference.restitution))},
                   {"friction", static_cast<double>(static_cast<float>(o.reference.friction))},
                   {"rolling_resistance", static_cast<double>(static_cast<float>(o.rolling_resistance))}};
  j["restitution_threshold"] = static_cast<double>(static_cast<float>(o.reference.restitution_threshold));
  j["h_coll"] = {{"ratio", fl(o.height_ratios)},
                 {"mean", fl(r.height_mean)},
                 {"std", fl(r.height_std)},
                 {"trials", o.height_trials}};
  json axes = json::array();
  const char* names4[] = {"cos_theta", "cos_phi", "speed", "spin_ratio"};
  const char* names3[] = {"cos_theta", "cos_phi", "spin_ratio"};
  for (std::size_t a = 0; a < r.axes.size(); ++a)
    axes.push_back({{"name", r.axes.size() == 4 ? names4[a] : names3[a]}, {"values", fl(r.axes[a])}});
  const std::vector<double> spread = response_spread(r);
  json resp = {{"layout", o.with_speed ? "with_speed" : "scaled"},
               {"model", response_model_name(o.response_model)},
               {"speed", o.with_speed ? json(nullptr) : json(o.speed)},
               {"axes", axes},
               {"components", {"w_x", "w_y", "w_z", "dv_x", "dv_y", "dv_z"}},
               {"mean", fl(r.response_mean)},
               {"std", fl(r.response_std)},
               {"spread", fl(spread)},
               {"trials_per_cell", o.trials},
               {"trials", r.response_trials},
               {"time_limited", r.time_limited},
               {"max_penetration", r.max_penetration}};
  if (o.response_flight) resp["to_first_flight"] = {{"hop", o.landing_hop}, {"no_flight", r.no_flight}};
  if (o.i16) {
    const Quantized qm = quantize(to_float(r.response_mean)), qs = quantize(to_float(spread));
    resp["i16"] = {{"mean_scale", static_cast<double>(qm.scale)},
                   {"mean_offset", static_cast<double>(qm.offset)},
                   {"spread_scale", static_cast<double>(qs.scale)},
                   {"spread_offset", static_cast<double>(qs.offset)},
                   {"worst_error", std::max(qm.worst_error, qs.worst_error)}};
  }
  // Only a table by gyration names its spin measure: a JSON without "spin" is by length.
  if (r.spin != ResponseSpin::length) resp["spin"] = r.spin == ResponseSpin::energy ? "energy" : "gyration";
  if (r.spin_test.run) {
    const SpinTest& t = r.spin_test;
    resp["spin_test"] = {{"draws", t.trials},          {"ks_length", t.ks_length},
                         {"ks_gyration", t.ks_gyration}, {"critical", t.critical},
                         {"clamp_length", t.clamp_length}, {"clamp_gyration", t.clamp_gyration}};
  }
  j["response"] = resp;
  json rest = json::array();
  for (const RestPose& p : r.rest)
    rest.push_back({{"normal", fl({p.normal.x(), p.normal.y(), p.normal.z()})},
                    {"height", static_cast<double>(static_cast<float>(p.height))},
                    {"frequency", static_cast<double>(static_cast<float>(p.frequency))},
                    {"measured_height", p.measured_height},
                    {"height_std", p.height_std},
                    {"snapped", p.snapped},
                    {"count", p.count},
                    {"family", p.family},
                    {"family_frequency", p.family_frequency}});
  j["rest"] = rest;
  json rare = json::array();
  for (const RestPose& p : r.rest_rare)
    rare.push_back({{"normal", {p.normal.x(), p.normal.y(), p.normal.z()}},
                    {"height", p.height},
                    {"frequency", p.frequency},
                    {"count", p.count},
                    {"family", p.family},
                    {"family_frequency", p.family_frequency}});
  j["rest_rare"] = rare;
  j["rest_dropped"] = r.rest_dropped;
  j["rest_families"] = r.rest_families;
  j["rest_min_frequency"] = o.rest_min_frequency;
  j["rest_max_dropped"] = o.rest_max_dropped;
  j["rest_drops"] = o.rest_drops;
  j["settled"] = r.settled;
  j["unsettled"] = r.unsettled;
  if (o.body_contacts && !r.contact.support.empty()) {
    const BodyContactData& c = r.contact;
    j["mesh_frame"] = fl(c.mesh_frame);
    j["body_contacts"] = {{"pair_mean", fl(c.pair_mean)},
                          {"pair_stddev", fl(c.pair_std)},
                          {"pair_flights", c.pair_flights},
                          {"support_size", c.support_size},
                          {"support", fl(c.support)},
                          {"support_bound", c.support_bound},
                          {"faces", fl(c.faces)},
                          {"hull_faces", c.hull_faces},
                          {"packing_bins_deg", {0, 30, 60, 90}},
                          {"packing_mean", fl({c.packing_mean[0], c.packing_mean[1], c.packing_mean[2]})},
                          {"packing_stddev", fl({c.packing_std[0], c.packing_std[1], c.packing_std[2]})},
                          {"packing_pairs", {c.packing_pairs[0], c.packing_pairs[1], c.packing_pairs[2]}},
                          {"packing_pooled", {c.packing_pooled[0], c.packing_pooled[1], c.packing_pooled[2]}},
                          {"piles", c.piles},
                          {"bins", c.bins},
                          {"pile_bodies", o.packing_count},
                          {"piles_asleep", c.asleep},
                          {"pile_steps", c.pile_steps}};
  }
  if (r.landing.present()) {
    const LandingFit& l = r.landing;
    j["landing"] = {{"hop", static_cast<double>(static_cast<float>(l.hop))},
                    {"cos_theta", fl(l.cos_theta)},
                    {"spin_ratio", fl(l.spin_ratio)},
                    {"froude", fl(l.froude)},
                    {"probability", fl(l.probability)},
                    {"stays", l.stays},
                    {"draw_stays", l.draw_stays},
                    {"trials_per_cell", o.landing_trials},
                    {"time", o.landing_time},
                    {"trials", l.trials}};
  }
  if (r.settle.present()) {
    const SettleFit& t = r.settle;
    j["settle"] = {{"quantiles", t.quantiles},
                   {"time", fl(t.time)},
                   {"settle_speed", t.settle_speed},
                   {"quiet_speed", t.quiet_speed},
                   {"drops", t.drops},
                   {"mean", t.mean},
                   {"time_limited", t.time_limited}};
  }
  return j.dump(2) + "\n";
}

std::string summary_text(const GatherResult& r)
{
  std::ostringstream s;
  const ShapeModel& m = r.model;
  s << "shape " << r.options.name << ": mass " << fmt("%.6g", m.mass.mass) << " kg, bounding radius "
    << fmt("%.6g", m.bounding_radius) << " m, unit inertia " << vec3(m.unit_inertia) << " m^2\n";
  s << "h_coll: " << fmt("%.5f", r.height_mean.front()) << " m at s = " << num(r.options.height_ratios.front()) << " to "
    << fmt("%.5f", r.height_mean.back()) << " m at s = " << num(r.options.height_ratios.back()) << " ("
    << fmt("%.1f", r.height_seconds) << " s)\n";
  s << "responses: " << r.response_trials << " impacts, " << r.time_limited << " time-limited, "
    << (r.options.response_flight ? std::to_string(r.no_flight) + " not flown off, " : std::string()) << "deepest penetration "
    << fmt("%.3g", r.max_penetration) << " m (" << fmt("%.1f", r.response_seconds) << " s)\n";
  s << "rest: " << r.settled << " settled (mean " << fmt("%.2f", r.mean_settle_time) << " s), " << r.unsettled << " unsettled; " << r.rest.size() << " poses kept, "
    << r.rest_rare.size() << " dropped (" << fmt("%.3f", r.rest_dropped) << " of the settled drops); "
    << r.rest_families << " families (" << fmt("%.1f", r.rest_seconds) << " s)\n";
  for (const RestPose& p : r.rest)
    s << "  up " << vec3(p.normal, "%+.4f") << "  h_rest " << fmt("%.5f", p.height) << " m (measured "
      << fmt("%.5f", p.measured_height) << ", std " << fmt("%.2g", p.height_std) << ")  frequency "
      << fmt("%.3f", p.frequency) << "  family " << p.family << " (" << fmt("%.3f", p.family_frequency) << ")\n";
  for (const RestPose& p : r.rest_rare)
    s << "  (dropped) up " << vec3(p.normal, "%+.4f") << "  h_rest " << fmt("%.5f", p.height) << " m  frequency "
      << fmt("%.3f", p.frequency) << "  family " << p.family << " (" << fmt("%.3f", p.family_frequency) << ")\n";
  if (r.options.body_contacts && !r.contact.pair_mean.empty()) {
    const BodyContactData& c = r.contact;
    s << "body-body: pair distance " << fmt("%.5f", c.pair_mean.front()) << " m at s = 0 (" << c.pair_flights
      << " flights, " << fmt("%.1f", c.pair_seconds) << " s); packing " << fmt("%.4f", c.packing_mean[0]) << ", "
      << fmt("%.4f", c.packing_mean[1]) << ", " << fmt("%.4f", c.packing_mean[2]) << " (" << c.packing_pairs[0] << ", "
      << c.packing_pairs[1] << ", " << c.packing_pairs[2] << " pairs; " << c.piles << " piles, " << c.bins << " bins, "
      << fmt("%.1f", c.packing_seconds) << " s)\n";
  }
  if (r.spin_test.run || r.spin != ResponseSpin::length) {
    const SpinTest& t = r.spin_test;
    s << "response spin: by "
      << (r.spin == ResponseSpin::energy ? "energy" : r.spin == ResponseSpin::gyration ? "gyration" : "length");
    if (t.run)
      s << "; KS of |V+| and |W+| of " << t.trials << " draws against the trials: by length " << fmt("%.4f", t.ks_length)
        << ", by gyration " << fmt("%.4f", t.ks_gyration) << " (gyration taken below length - " << fmt("%.4f", t.critical)
        << "); energy guard " << fmt("%.4f", t.clamp_length) << " / " << fmt("%.4f", t.clamp_gyration) << " ("
        << fmt("%.1f", t.seconds) << " s)";
    s << "\n";
  }
  if (r.landing.present()) {
    const LandingFit& l = r.landing;
    s << "landing: " << l.trials << " impacts with gravity; stays " << fmt("%.3f", mean_of(l, l.stays))
      << ", the response draws' " << fmt("%.3f", mean_of(l, l.draw_stays)) << ", landing probability "
      << fmt("%.3f", mean_of(l, l.probability)) << " (means over the cells above F = 0; " << fmt("%.1f", l.seconds) << " s)\n";
  }
  if (r.settle.present()) {
    const SettleFit& t = r.settle;
    s << "settling: " << r.options.rest_drops << " rest drops (" << t.time_limited << " at the time limit), "
      << t.quantiles << " quantiles per pose; mean settling time per pose";
    for (std::size_t i = 0; i < t.mean.size(); ++i) s << (i == 0 ? " " : ", ") << fmt("%.3f", t.mean[i]);
    s << " s (" << fmt("%.1f", t.seconds) << " s)\n";
  }
  if (r.options.i16) {
    const Quantized qm = quantize(to_float(r.response_mean)), qs = quantize(to_float(r.response_std));
    s << "i16: worst dequantization error " << fmt("%.3g", std::max(qm.worst_error, qs.worst_error)) << "\n";
  }
  return s.str();
}

}  // namespace statsim::tools::ref3d
