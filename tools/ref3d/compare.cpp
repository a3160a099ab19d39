#include "ref3d/compare.hpp"

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "ref3d/signature_json.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace statsim::tools {
namespace {

// Poses and faces whose normals are this close are the same one (the gatherer clusters rest
// poses within 10 degrees).
const double match_cos = std::cos(10.0 * 3.14159265358979323846 / 180.0);

// Spreads below this are read as this, so that a cell without spread (every trial alike) gives a
// finite distance: normalised responses are of order 1, and the i16 tables' resolution is about
// 1e-4 of that.
constexpr double response_spread_floor = 1e-3;
// The same for lengths, as a fraction of the scaled bounding radius.
constexpr double length_spread_floor = 1e-3;

struct Accumulator {
  QuantityDistance q;
  void add(double d)
  {
    q.mean += d;
    q.max = std::max(q.max, d);
    ++q.count;
  }
  QuantityDistance done() const
  {
    QuantityDistance r = q;
    if (r.count > 0) r.mean /= r.count;
    return r;
  }
};

Accumulator quantity(const std::string& name, int exponent, const std::string& measure)
{
  Accumulator a;
  a.q.name = name;
  a.q.exponent = exponent;
  a.q.measure = measure;
  return a;
}

// |b / a' - 1| with a' = a s^k; 0 when both are 0.
double relative(double a_scaled, double b)
{
  if (a_scaled == b) return 0.0;
  return std::fabs(b - a_scaled) / std::max(std::fabs(a_scaled), std::fabs(b));
}

// 2-Wasserstein distance between the Gaussians (ma, sa) and (mb, sb), over their pooled spread:
// sqrt((ma - mb)^2 + (sa - sb)^2) / sqrt((sa^2 + sb^2) / 2).
double w2_over_spread(double ma, double sa, double mb, double sb, double floor)
{
  const double pooled = std::max(std::sqrt(0.5 * (sa * sa + sb * sb)), floor);
  return std::hypot(ma - mb, sa - sb) / pooled;
}

// Standard deviation of component c of a cell, from the spread values of the table's model.
double component_spread(const ResponseTableView& r, std::uint32_t cell, std::uint32_t c)
{
  const std::uint32_t o = cell * r.spread_per_cell;
  const std::uint32_t n = r.components;
  switch (r.model) {
    case ResponseModel::independent_gaussian: return double(r.spread[o + c]);
    case ResponseModel::correlated_gaussian: {
      // Row c of the Cholesky factor L: the variance is the row's squared norm (L L^T).
      double v = 0.0;
      for (std::uint32_t j = 0; j <= c; ++j) {
        const double l = double(r.spread[o + c * (c + 1) / 2 + j]);
        v += l * l;
      }
      return std::sqrt(v);
    }
    case ResponseModel::empirical: {
      // Stored outcomes are offsets from the cell's mean, outcome by outcome.
      const std::uint32_t k = r.spread_per_cell / n;
      double v = 0.0;
      for (std::uint32_t i = 0; i < k; ++i) {
        const double x = double(r.spread[o + i * n + c]);
        v += x * x;
      }
      return k > 0 ? std::sqrt(v / k) : 0.0;
    }
  }
  return 0.0;
}

bool same_axis(const AxisView& a, const AxisView& b)
{
  if (a.size != b.size) return false;
  for (std::uint32_t i = 0; i < a.size; ++i)
    if (a.values[i] != b.values[i]) return false;
  return true;
}

Eigen::Vector3d rest_normal(const SignatureView<3>& s, std::uint32_t i)
{
  return Eigen::Vector3d(s.rest.normals[3 * i], s.rest.normals[3 * i + 1], s.rest.normals[3 * i + 2]);
}

// The pose or face of A whose normal is nearest to `n`, or -1 beyond the match angle.
template <class NormalOf>
int nearest(std::uint32_t count, const Eigen::Vector3d& n, NormalOf normal_of)
{
  int best = -1;
  double best_dot = match_cos;
  for (std::uint32_t i = 0; i < count; ++i) {
    const double d = normal_of(i).dot(n);
    if (d >= best_dot) {
      best_dot = d;
      best = int(i);
    }
  }
  return best;
}

void compare_contacts(const SignatureView<3>& a, const SignatureView<3>& b, double s, TableComparison& out)
{
  const ContactView<3>& ca = a.contact;
  const ContactView<3>& cb = b.contact;
  const double radius = s * double(a.bounding_radius);
  if (ca.pair_mean != nullptr && cb.pair_mean != nullptr) {
    Accumulator pair = quantity("pair distance", 1, "W2/spread");
    for (std::uint32_t i = 0; i < a.height.spin_ratio.size; ++i)
      pair.add(w2_over_spread(s * ca.pair_mean[i], s * ca.pair_stddev[i], cb.pair_mean[i], cb.pair_stddev[i],
                              length_spread_floor * radius));
    out.quantities.push_back(pair.done());
  }
  if (ca.support_size == cb.support_size) {
    Accumulator support = quantity("support map", 1, "|difference|/bounding radius");
    for (std::uint32_t i = 0; i < ca.support_count(); ++i)
      support.add(std::fabs(double(cb.support[i]) - s * double(ca.support[i])) / radius);
    out.quantities.push_back(support.done());
  }
  const std::uint32_t fv = face_values(3);
  const auto face_normal = [fv](const ContactView<3>& c, std::uint32_t i) {
    const Scalar* f = c.faces + i * fv;
    return Eigen::Vector3d(f[0], f[1], f[2]);
  };
  Accumulator offsets = quantity("face offsets", 1, "relative difference");
  Accumulator packing = quantity("face packing ratios", 0, "|difference|");
  Accumulator unmatched = quantity("faces unmatched", 0, "fraction of B's faces");
  for (std::uint32_t j = 0; j < cb.face_count; ++j) {
    const int i = nearest(ca.face_count, face_normal(cb, j), [&](std::uint32_t k) { return face_normal(ca, k); });
    unmatched.add(i < 0 ? 1.0 : 0.0);
    if (i < 0) continue;
    const Scalar* fa = ca.faces + std::uint32_t(i) * fv;
    const Scalar* fb = cb.faces + j * fv;
    offsets.add(relative(s * double(ca.face_offset(std::uint32_t(i))), double(cb.face_offset(j))));
    packing.add(std::fabs(double(fb[4]) - double(fa[4])));
  }
  out.quantities.push_back(offsets.done());
  out.quantities.push_back(packing.done());
  out.quantities.push_back(unmatched.done());
  Accumulator by_angle = quantity("packing by angle", 0, "W2/spread");
  for (std::size_t k = 0; k < 3; ++k)
    by_angle.add(w2_over_spread(ca.packing_mean[k], ca.packing_stddev[k], cb.packing_mean[k], cb.packing_stddev[k],
                                response_spread_floor));
  out.quantities.push_back(by_angle.done());
}

}  // namespace

const QuantityDistance* TableComparison::find(const std::string& name) const
{
  for (const QuantityDistance& q : quantities)
    if (q.name == name) return &q;
  return nullptr;
}

TableComparison compare_tables(const SignatureView<3>& a, const SignatureView<3>& b, double s)
{
  if (!(s > 0) || !std::isfinite(s)) throw std::invalid_argument("the scale must be positive");
  const ResponseTableView& ra = a.response;
  const ResponseTableView& rb = b.response;
  if (a.layout != b.layout || ra.model != rb.model || ra.axis_count != rb.axis_count ||
      ra.spread_per_cell != rb.spread_per_cell)
    throw std::invalid_argument("the tables differ in response layout or model: gather them with the same options");
  for (std::uint32_t k = 0; k < ra.axis_count; ++k)
    if (!same_axis(ra.axes[k], rb.axes[k]))
      throw std::invalid_argument("response axis " + std::to_string(k) + " differs between the tables");
  if (!same_axis(a.height.spin_ratio, b.height.spin_ratio))
    throw std::invalid_argument("the h_coll axes differ between the tables");

  TableComparison out;
  out.scale = s;
  const auto scalar = [&](const char* name, int k, double va, double vb) {
    Accumulator q = quantity(name, k, "relative difference");
    q.add(relative(va * std::pow(s, k), vb));
    out.quantities.push_back(q.done());
  };
  scalar("length L", 1, a.length, b.length);
  scalar("bounding radius", 1, a.bounding_radius, b.bounding_radius);
  scalar("mass", 3, a.mass, b.mass);
  {
    Accumulator q = quantity("unit inertia", 2, "relative difference");
    for (std::size_t k = 0; k < 3; ++k) q.add(relative(double(a.unit_inertia[k]) * s * s, double(b.unit_inertia[k])));
    out.quantities.push_back(q.done());
  }

  const double radius = s * double(a.bounding_radius);
  Accumulator h_mean = quantity("h_coll mean", 1, "relative difference");
  Accumulator h = quantity("h_coll", 1, "W2/spread");
  for (std::uint32_t i = 0; i < a.height.spin_ratio.size; ++i) {
    const double ma = s * double(a.height.mean[i]), sa = s * double(a.height.stddev[i]);
    h_mean.add(relative(ma, double(b.height.mean[i])));
    h.add(w2_over_spread(ma, sa, b.height.mean[i], b.height.stddev[i], length_spread_floor * radius));
  }
  out.quantities.push_back(h_mean.done());
  out.quantities.push_back(h.done());

  // Responses are stored normalised (W+ L / |V-|, dv / |V-|): scale-free, exponent 0.
  std::uint32_t cells = 1;
  for (std::uint32_t k = 0; k < ra.axis_count; ++k) cells *= ra.axes[k].size;
  static const char* const names[6] = {"w_x", "w_y", "w_z", "dv_x", "dv_y", "dv_z"};
  Accumulator all = quantity("response (all)", 0, "W2/spread");
  for (std::uint32_t c = 0; c < ra.components && c < 6; ++c) {
    Accumulator q = quantity(std::string("response ") + names[c], 0, "W2/spread");
    for (std::uint32_t cell = 0; cell < cells; ++cell) {
      const double d = w2_over_spread(ra.mean[cell * ra.components + c], component_spread(ra, cell, c),
                                      rb.mean[cell * rb.components + c], component_spread(rb, cell, c),
                                      response_spread_floor);
      q.add(d);
      all.add(d);
    }
    out.quantities.push_back(q.done());
  }
  out.quantities.push_back(all.done());

  // Rest poses: B's poses matched to A's by their normals. Frequencies: total variation distance
  // of the two pose distributions (a pose of one table missing in the other counts in full).
  std::vector<double> fb_matched(a.rest.count, 0.0);
  double unmatched_b = 0.0;
  Accumulator heights = quantity("rest heights", 1, "relative difference");
  for (std::uint32_t j = 0; j < b.rest.count; ++j) {
    const int i = nearest(a.rest.count, rest_normal(b, j), [&](std::uint32_t k) { return rest_normal(a, k); });
    if (i < 0) {
      unmatched_b += b.rest.frequencies[j];
      continue;
    }
    fb_matched[std::size_t(i)] += b.rest.frequencies[j];
    heights.add(relative(s * double(a.rest.heights[i]), double(b.rest.heights[j])));
  }
  double tvd = unmatched_b;
  for (std::uint32_t i = 0; i < a.rest.count; ++i) tvd += std::fabs(double(a.rest.frequencies[i]) - fb_matched[i]);
  Accumulator freq = quantity("rest frequencies", 0, "total variation distance");
  freq.add(0.5 * tvd);
  out.quantities.push_back(heights.done());
  out.quantities.push_back(freq.done());

  if (a.contact.present() && b.contact.present()) compare_contacts(a, b, s, out);
  return out;
}

std::string comparison_text(const TableComparison& c)
{
  std::ostringstream o;
  o << "B against A scaled by s = " << fmt("%.6g", c.scale) << " (each quantity of A times s^k)\n";
  o << "quantity              k  measure                         n      mean       max\n";
  for (const QuantityDistance& q : c.quantities) {
    char line[160];
    std::snprintf(line, sizeof line, "%-21s %2d  %-30s %3d %9.4g %9.4g\n", q.name.c_str(), q.exponent,
                  q.measure.c_str(), q.count, q.mean, q.max);
    o << line;
  }
  return o.str();
}

std::string comparison_json(const TableComparison& c, const std::string& command)
{
  nlohmann::ordered_json j;
  j["command"] = command;
  j["scale"] = c.scale;
  j["quantities"] = nlohmann::ordered_json::array();
  for (const QuantityDistance& q : c.quantities)
    j["quantities"].push_back({{"name", q.name},
                               {"exponent", q.exponent},
                               {"measure", q.measure},
                               {"count", q.count},
                               {"mean", q.mean},
                               {"max", q.max}});
  return j.dump(2) + "\n";
}

namespace {

// A table named on the command line: a committed one (box, lshape, bunny) or a gatherer's JSON.
struct TableSource {
  std::unique_ptr<LoadedSignature3> loaded;
  SignatureView<3> view;
};

TableSource table_source(const std::string& name)
{
  TableSource t;
  if (name == "box") t.view = tables::box.view();
  else if (name == "lshape") t.view = tables::lshape.view();
  else if (name == "bunny") t.view = tables::bunny.view();
  else {
    t.loaded = std::make_unique<LoadedSignature3>(load_signature_json(name));
    t.view = t.loaded->view();
  }
  return t;
}

}  // namespace

void add_compare_command(CLI::App& app)
{
  struct Command {
    std::string reference, table, json;
    double scale = 1.0;
  };
  auto c = std::make_shared<Command>();
  CLI::App* sub = app.add_subcommand(
      "compare-tables",
      "Compare a 3D signature B with a reference A scaled by a size factor s: each quantity of A times s^k (k its "
      "power of length), distances per quantity in units of its spread (tools/ref3d/README.md, \"One table at any "
      "size\")");
  sub->add_option("--reference", c->reference, "Table A: box, lshape, bunny (committed) or FILE.json (gather --json)")
      ->required();
  sub->add_option("--table", c->table, "Table B: the same kinds")->required();
  sub->add_option("--scale", c->scale, "Size of B over the size of A")->capture_default_str();
  sub->add_option("--json", c->json, "Also write the distances as JSON to this file");
  sub->callback([c]() {
    try {
      const TableSource a = table_source(c->reference);
      const TableSource b = table_source(c->table);
      const TableComparison r = compare_tables(a.view, b.view, c->scale);
      std::cout << "A: " << c->reference << "\nB: " << c->table << "\n" << comparison_text(r);
      if (!c->json.empty()) {
        const std::string cmd = "build/bin/statsim compare-tables --reference " + c->reference + " --table " +
                                c->table + " --scale " + fmt("%.9g", c->scale);
        write_file_atomic(c->json, comparison_json(r, cmd));
      }
    } catch (const std::exception& e) {
      std::cerr << "statsim compare-tables: error: " << e.what() << "\n";
      throw CLI::RuntimeError(1);
    }
  });
}

}  // namespace statsim::tools
