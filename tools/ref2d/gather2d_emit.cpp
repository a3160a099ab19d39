// See gather2d_emit.hpp.
#include "ref2d/gather2d_emit.hpp"

#include "common/body_contacts.hpp"
#include "common/format.hpp"
#include "common/table_writer.hpp"
#include "ref2d/gather2d.hpp"
#include "ref2d/gather2d_trials.hpp"
#include "statsim/signature.hpp"

#include <box2d/box2d.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace statsim::tools {

namespace {

// printf's `format` of x, a negative zero written as 0 (as every 2D table has been written).
std::string fmt_plus_zero(const char* format, double x)
{
  return fmt(format, x + 0.0);
}

std::string g6(double x)
{
  return fmt_plus_zero("%.6g", x);
}

// A table array: 6 values a line, one level deeper than the entries.
std::string hex_array(const std::vector<double>& values)
{
  return hex_float_array(values, ArrayStyle{6, 8, false});
}

}  // namespace

std::string shell_quote(const std::string& s)
{
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./,+=:") ==
                        std::string::npos) {
    return s;
  }
  std::string q = "'";
  for (char c : s) {
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return q + "'";
}

std::string gather2d_header(const Gather2dResult& r, const std::string& command)
{
  const Gather2dOptions& o = r.options;
  const Shape2& sh = r.shape;
  std::vector<RestCluster> kept;
  for (const RestCluster& c : r.clusters) {
    if (c.kept) {
      kept.push_back(c);
    }
  }
  int late = 0, missed = 0;
  for (const HeightRow& h : r.heights) {
    late += h.late;
    missed += h.missed;
  }
  const auto dt_text = [](double dt) {
    const double inv = 1.0 / dt;
    return std::fabs(inv - std::round(inv)) < 1e-9 * inv ? "1/" + fmt_plus_zero("%.0f", inv) : g6(dt);
  };
  std::string s = table_banner("gather2d", command, o.target);
  s += "// seed " + std::to_string(o.seed) + "; reference: Box2D " + std::to_string(b2_version.major) + "." +
       std::to_string(b2_version.minor) + " (Debian libbox2d 2.4.1: polygon skin b2_polygonRadius = " +
       g6(static_cast<double>(b2_polygonRadius)) + " m, b2_linearSlop = " + g6(static_cast<double>(b2_linearSlop)) +
       " m)\n";
  s += "// shape: " + sh.description + "\n";
  s += "//   body frame (centroid at the origin), counter-clockwise: " + format_polygon(sh.outline) + "\n";
  s += "//   " + std::to_string(sh.pieces.size()) + " convex Box2D fixture(s); area " + g6(sh.area) +
       " m^2, density 1 kg/m^2, mass " + g6(sh.area) + " kg, polar inertia / mass " + g6(sh.polar_inertia / sh.area) +
       " m^2; bounding radius = L = " + g6(sh.bounding_radius) + " m\n";
  s += "// material: restitution " + g6(o.restitution) + ", friction " + g6(o.friction) +
       " on the body and on the ground (Box2D mixes restitution as max(a, b) and friction as sqrt(a b),\n"
       "//   so contacts use exactly these); restitution only above " +
       g6(static_cast<double>(r.restitution_threshold)) +
       " m/s of approach (b2FixtureDef::restitutionThreshold, recorded as\n"
       "//   restitution_threshold); rolling_resistance is the runtime's default (Box2D polygons do not roll)\n";
  s += "// height table (paper 3.2.1): " + std::to_string(r.heights.size()) + " spin ratios s = |w| L / |v| x " +
       std::to_string(o.height_trials) + " drops, |v| = " + g6(o.height_speed) + " m/s straight down, dt " +
       dt_text(r.height_dt) + " s, random orientation, spin sign and step phase;\n"
       "//   centre height at the first contact of the core shape, refined exactly (Box2D skin removed; Box2D noticed " +
       std::to_string(late) + " contacts\n//   a step late and missed " + std::to_string(missed) +
       ", covered by the refinement)\n";
  s += "// response tables (paper 3.2.2): " + std::to_string(o.cos_thetas.size()) + " cos(theta) x " +
       std::to_string(o.signed_spins.size()) + " signed spin ratios x " + std::to_string(o.speeds.size()) + " speeds = " +
       std::to_string(r.cells.size()) + " cells x " + std::to_string(o.trials) + " trials = " +
       std::to_string(r.response_trials) + " trials;\n"
       "//   no gravity, dt " + dt_text(r.response_dt) +
       " s, 8 velocity / 3 position iterations, random orientation at a fixed height, until separated;\n"
       "//   " + std::to_string(r.response_time_limited) + " trials had not separated " + g6(o.response_time_limit) +
       " s after first contact (time limit; their final velocities are used)\n";
  s += "// rest poses (paper 3.2.3): " + std::to_string(r.rest_drops) + " drops with gravity " + g6(kGravity) +
       " m/s^2, dt " + dt_text(o.rest_dt) + " s, until Box2D put the body to sleep; " +
       std::to_string(r.rest_time_limited) + " were still awake after " + g6(o.rest_time_limit) +
       " s;\n//   greedy clustering of body-frame up vectors at " + g6(o.cluster_degrees) +
       " degrees, snapped to hull faces within 3 degrees; kept: families (poses equivalent under the shape's "
       "symmetry) of frequency > " + g6(o.min_frequency) + ", then rarer ones while more than " + g6(o.max_dropped) +
       " of the settled drops is dropped; h_rest on the core shape\n";
  for (std::size_t i = 0; i < r.clusters.size(); ++i) {
    const RestCluster& c = r.clusters[i];
    s += "//   " + std::string(c.kept ? "pose " + std::to_string(i) : "(not kept)") + ": up (" + fmt_plus_zero("%.6f", c.normal.x) +
         ", " + fmt_plus_zero("%.6f", c.normal.y) + ") h_rest " + fmt_plus_zero("%.6f", c.height) + " m, " + std::to_string(c.count) +
         " drops, frequency " + fmt_plus_zero("%.4f", c.frequency) + ", family " + std::to_string(c.family) + "\n";
  }
  s += "//   dropped: " + fmt_plus_zero("%.4f", r.rest_dropped) + " of the settled drops\n";
  const BodyContactData& bc = r.contact;
  if (o.body_contacts) {
    s += "// body-body data: support map S = " + std::to_string(bc.support_size) + " (" +
         std::to_string(4 * bc.support_size) + " values; at most " + fmt_plus_zero("%.3g", bc.support_bound) +
         " m above the hull's support), " + std::to_string(bc.face_count()) + " of the hull's " +
         std::to_string(bc.hull_faces) + " edges, mesh frame: the input's frame at the centroid\n";
    s += "//   pair distance: " + std::to_string(bc.pair_flights) + " pair flights (" + std::to_string(o.pair_trials) +
         " per height-table spin ratio, head-on at " + g6(o.height_speed) + " m/s relative speed, exact outlines)\n";
    s += "//   packing: " + std::to_string(bc.piles) + " Box2D piles of " + std::to_string(o.packing_count) +
         " bodies (statsim compare2d's, seeds 1..), " + std::to_string(o.packing_steps) + " steps of 1/60 s; " +
         std::to_string(bc.asleep) + " of " + std::to_string(bc.piles) + " all asleep; " +
         std::to_string(bc.total_pairs) + " touching pairs\n";
    s += "//   packing d / the runtime's hull distance (find_hull_witness on this table, ratio 1):" + packing_line(bc) +
         "\n";
  }
  s += table_prologue(o.name, o.body_contacts ? 1 : 0, o.target);
  s += "// Signature<D, height samples, response axes (cos theta, signed spin ratio, speed, unused), rest poses,\n"
       "//           spread values per cell (the paper's model: one standard deviation per component)>\n";
  s += table_definition("Signature<2, " + std::to_string(r.heights.size()) + ", " + std::to_string(o.cos_thetas.size()) +
                            ", " + std::to_string(o.signed_spins.size()) + ", " + std::to_string(o.speeds.size()) +
                            ", 1, " + std::to_string(kept.size()) + ", 3" +
                            (o.body_contacts ? ", " + contact_type(bc, false) : std::string()) + ">",
                        o.name, o.target);
  statsim::Material defaults;
  const auto array = [&s](const std::string& comment, const std::vector<double>& values) {
    s += table_comment(comment) + table_entry(hex_array(values));
  };
  s += table_entry("\"" + o.name + "\"");
  s += table_entry(hex_float(r.length), "length L (bounding radius), m");
  s += table_entry(hex_float(sh.bounding_radius), "bounding_radius, m");
  s += table_entry(hex_float(sh.area), "mass, kg");
  s += table_entry("{{" + hex_floats({sh.polar_inertia / sh.area, 0.0, 0.0}) + "}}",
                   "unit_inertia (polar moment / mass), m^2");
  s += table_entry("{" + hex_floats({o.restitution, o.friction, static_cast<double>(defaults.rolling_resistance)}) + "}",
                   "material: restitution, friction, rolling");
  s += table_entry(hex_float(static_cast<double>(r.restitution_threshold)), "restitution_threshold, m/s");
  s += table_entry("ResponseLayout::with_speed");
  s += table_entry("ResponseModel::independent_gaussian");
  s += table_entry("3", "axis_count");
  std::vector<double> hm, hsd;
  for (const HeightRow& h : r.heights) {
    hm.push_back(h.mean);
    hsd.push_back(h.std);
  }
  array("height_axis: spin ratio |w| L / |v|", o.height_ratios);
  array("height_mean, m", hm);
  array("height_stddev, m", hsd);
  array("axis0: cos(theta)", o.cos_thetas);
  array("axis1: signed spin ratio", o.signed_spins);
  array("axis2: speed |V-|, m/s", o.speeds);
  array("axis3: unused", {0.0});
  std::vector<double> rm, rs;
  for (const ResponseCell& c : r.cells) {
    for (int k = 0; k < 3; ++k) {
      rm.push_back(c.mean[static_cast<std::size_t>(k)]);
      rs.push_back(c.std[static_cast<std::size_t>(k)]);
    }
  }
  array("response_mean: per cell (cos theta slowest, then spin, then speed) w+ L/|V-|, dv_x/|V-|, dv_y/|V-|", rm);
  array("response_spread: per cell the standard deviation of each component", rs);
  std::vector<double> rn, rh, rf;
  for (const RestCluster& c : kept) {
    rn.push_back(c.normal.x);
    rn.push_back(c.normal.y);
    rh.push_back(c.height);
    rf.push_back(c.frequency);
  }
  array("rest_normals: body-frame up vectors", rn);
  array("rest_heights, m", rh);
  array("rest_frequencies", rf);
  if (o.body_contacts) s += contact_entries(bc, false);
  return s + table_epilogue(o.target);
}

std::string gather2d_json(const Gather2dResult& r, const std::string& command)
{
  nlohmann::ordered_json j;
  j["command"] = command;
  j["name"] = r.options.name;
  j["seed"] = r.options.seed;
  j["length"] = r.length;
  j["area"] = r.shape.area;
  j["seconds"] = {{"heights", r.seconds_heights}, {"responses", r.seconds_responses}, {"rest", r.seconds_rest}};
  j["heights"] = nlohmann::ordered_json::array();
  for (const HeightRow& h : r.heights)
    j["heights"].push_back({{"ratio", h.ratio}, {"mean", h.mean}, {"std", h.std}, {"min", h.min}, {"max", h.max},
                            {"trials", h.trials}, {"late", h.late}, {"missed", h.missed}});
  if (r.options.body_contacts) {
    const BodyContactData& c = r.contact;
    j["mesh_frame"] = c.mesh_frame;
    j["body_contacts"] = {{"pair_mean", c.pair_mean},
                          {"pair_stddev", c.pair_std},
                          {"pair_flights", c.pair_flights},
                          {"support_size", c.support_size},
                          {"support", c.support},
                          {"support_bound", c.support_bound},
                          {"faces", c.faces},
                          {"hull_faces", c.hull_faces},
                          {"packing_bins_deg", {0, 30, 60, 90}},
                          {"packing_mean", c.packing_mean},
                          {"packing_stddev", c.packing_std},
                          {"packing_pairs", c.packing_pairs},
                          {"packing_pooled", c.packing_pooled},
                          {"piles", c.piles},
                          {"pile_bodies", r.options.packing_count},
                          {"piles_asleep", c.asleep},
                          {"seconds", {{"pairs", c.pair_seconds}, {"packing", c.packing_seconds}}}};
  }
  j["response_trials"] = r.response_trials;
  j["response_time_limited"] = r.response_time_limited;
  j["cells"] = nlohmann::ordered_json::array();
  for (const ResponseCell& c : r.cells)
    j["cells"].push_back({{"cos_theta", c.cos_theta},
                          {"spin", c.spin},
                          {"speed", c.speed},
                          {"mean", {c.mean[0], c.mean[1], c.mean[2]}},
                          {"std", {c.std[0], c.std[1], c.std[2]}},
                          {"time_limited", c.time_limited},
                          {"mean_steps", c.mean_steps}});
  j["rest_drops"] = r.rest_drops;
  j["rest_time_limited"] = r.rest_time_limited;
  j["rest_clusters"] = nlohmann::ordered_json::array();
  for (const RestCluster& c : r.clusters)
    j["rest_clusters"].push_back({{"normal", {c.normal.x, c.normal.y}},
                                  {"height", c.height},
                                  {"frequency", c.frequency},
                                  {"count", c.count},
                                  {"spread_degrees", c.spread_degrees},
                                  {"snap_degrees", c.snap_degrees},
                                  {"kept", c.kept},
                                  {"family", c.family},
                                  {"family_frequency", c.family_frequency}});
  j["rest_dropped"] = r.rest_dropped;
  return j.dump(2) + "\n";
}

std::string gather2d_summary(const Gather2dResult& r)
{
  std::string s = "gather2d " + r.options.name + ": " + r.shape.description + "\n";
  s += "  L = " + g6(r.length) + " m, area " + g6(r.shape.area) + " m^2, " + std::to_string(r.shape.pieces.size()) +
       " convex piece(s)\n";
  s += "  height table (" + fmt_plus_zero("%.1f", r.seconds_heights) + " s):\n    s      mean      std       min       max\n";
  for (const HeightRow& h : r.heights) {
    s += "    " + fmt_plus_zero("%-5g", h.ratio) + "  " + fmt_plus_zero("%.5f", h.mean) + "  " + fmt_plus_zero("%.5f", h.std) + "  " +
         fmt_plus_zero("%.5f", h.min) + "  " + fmt_plus_zero("%.5f", h.max) + "\n";
  }
  // Response: a digest over cells.
  double max_abs_mean[3] = {0, 0, 0}, mean_std[3] = {0, 0, 0};
  for (const ResponseCell& c : r.cells) {
    for (int k = 0; k < 3; ++k) {
      max_abs_mean[k] = std::max(max_abs_mean[k], std::fabs(c.mean[static_cast<std::size_t>(k)]));
      mean_std[k] += c.std[static_cast<std::size_t>(k)] / static_cast<double>(r.cells.size());
    }
  }
  s += "  response tables (" + fmt_plus_zero("%.1f", r.seconds_responses) + " s): " + std::to_string(r.cells.size()) +
       " cells, " + std::to_string(r.response_trials) + " trials, " + std::to_string(r.response_time_limited) +
       " hit the time limit\n";
  s += "    max |mean| (w L/|V|, dv_x/|V|, dv_y/|V|) = (" + fmt_plus_zero("%.3f", max_abs_mean[0]) + ", " +
       fmt_plus_zero("%.3f", max_abs_mean[1]) + ", " + fmt_plus_zero("%.3f", max_abs_mean[2]) + "), average std = (" +
       fmt_plus_zero("%.3f", mean_std[0]) + ", " + fmt_plus_zero("%.3f", mean_std[1]) + ", " + fmt_plus_zero("%.3f", mean_std[2]) + ")\n";
  s += "  rest poses (" + fmt_plus_zero("%.1f", r.seconds_rest) + " s): " + std::to_string(r.rest_drops) + " drops, " +
       std::to_string(r.rest_time_limited) + " still awake at the time limit\n";
  for (const RestCluster& c : r.clusters) {
    s += std::string("    ") + (c.kept ? "kept " : "     ") + " up (" + fmt_plus_zero("%+.4f", c.normal.x) + ", " +
         fmt_plus_zero("%+.4f", c.normal.y) + ")  h_rest " + fmt_plus_zero("%.5f", c.height) + " m  frequency " +
         fmt_plus_zero("%.3f", c.frequency) + "  (" + std::to_string(c.count) + " drops, spread " +
         fmt_plus_zero("%.2f", c.spread_degrees) + " deg" +
         (c.snap_degrees >= 0 ? ", snapped " + fmt_plus_zero("%.3f", c.snap_degrees) + " deg" : std::string(", not snapped")) +
         ", family " + std::to_string(c.family) + ")\n";
  }
  s += "    dropped: " + fmt_plus_zero("%.3f", r.rest_dropped) + " of the settled drops\n";
  if (r.options.body_contacts) {
    const BodyContactData& c = r.contact;
    s += "  body-body: pair distance " + fmt_plus_zero("%.5f", c.pair_mean.front()) + " m at s = 0 (" +
         std::to_string(c.pair_flights) + " flights, " + fmt_plus_zero("%.1f", c.pair_seconds) + " s); packing" +
         packing_line(c) + " (" + std::to_string(c.piles) + " piles, " + fmt_plus_zero("%.1f", c.packing_seconds) + " s)\n";
  }
  return s;
}

}  // namespace statsim::tools
