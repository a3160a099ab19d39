#include "ref2d/pairs2d.hpp"

#include "common/pi.hpp"
#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "common/support_map.hpp"
#include "ref2d/box2d_util.hpp"
#include "ref2d/compare2d.hpp"
#include "tables/lshape2d.hpp"
#include "tables/square2d.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace statsim::tools {

namespace {

Shape2 shape_of(const std::string& name)
{
  if (name == "square") return square_shape();
  if (name == "lshape") return lshape_shape();
  throw std::invalid_argument("gather-pairs2d: unknown shape '" + name + "' (square or lshape)");
}

statsim::SignatureView<2> table_of(const std::string& name)
{
  return name == "lshape" ? statsim::tables::lshape2d.view() : statsim::tables::square2d.view();
}

std::vector<Eigen::Vector2d> to_eigen(const std::vector<Point2>& v)
{
  std::vector<Eigen::Vector2d> out;
  for (const Point2& p : v) out.emplace_back(p.x, p.y);
  return out;
}

Eigen::Matrix2d rotation(double angle)
{
  Eigen::Matrix2d r;
  r << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  return r;
}

struct Pose {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  double angle = 0.0;
};

std::vector<Eigen::Vector2d> placed(const std::vector<Eigen::Vector2d>& poly, const Pose& p)
{
  const Eigen::Matrix2d r = rotation(p.angle);
  std::vector<Eigen::Vector2d> out;
  for (const auto& v : poly) out.push_back(p.c + r * v);
  return out;
}

double point_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// Distance of two disjoint polygons (closed outlines): the least vertex-to-edge distance.
double polygon_distance(const std::vector<Eigen::Vector2d>& p, const std::vector<Eigen::Vector2d>& q)
{
  double d = std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < 2; ++pass) {
    const auto& a = pass ? q : p;
    const auto& b = pass ? p : q;
    for (const auto& v : a)
      for (std::size_t k = 0; k < b.size(); ++k) d = std::min(d, point_segment(v, b[k], b[(k + 1) % b.size()]));
  }
  return d;
}

// One pair flight of `poly` (outline or hull) with bounding radius L.
double flight(const std::vector<Eigen::Vector2d>& poly, double L, double spin_ratio, double u, std::uint64_t seed,
              std::uint64_t index)
{
  std::mt19937_64 rng = trial_rng(seed, 21, index, 0);
  Pose a, b;
  a.angle = 2 * kPi * uniform01(rng);
  b.angle = 2 * kPi * uniform01(rng);
  const double wa = (uniform01(rng) < 0.5 ? -1.0 : 1.0) * spin_ratio * u / L;
  const double wb = (uniform01(rng) < 0.5 ? -1.0 : 1.0) * spin_ratio * u / L;
  b.c = Eigen::Vector2d(2 * L * (1 + 1e-9), 0);
  const double rate = u + (std::fabs(wa) + std::fabs(wb)) * L;
  const Pose a0 = a, b0 = b;
  double t = 0.0;
  for (int it = 0; it < 1000000; ++it) {
    a.angle = a0.angle + wa * t;
    b.angle = b0.angle + wb * t;
    b.c = b0.c - Eigen::Vector2d(u * t, 0);
    const double d = polygon_distance(placed(poly, a), placed(poly, b));
    if (d <= 1e-9 * L || b.c.x() <= 0) break;
    t += d / rate;
  }
  return (b.c - a.c).norm();
}

double mean_of(const std::vector<double>& v)
{
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

double std_of(const std::vector<double>& v)
{
  if (v.size() < 2) return 0.0;
  const double m = mean_of(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

// Outward unit normals of the hull's edges (counter-clockwise hull).
std::vector<Eigen::Vector2d> edge_normals(const std::vector<Eigen::Vector2d>& hull)
{
  std::vector<Eigen::Vector2d> n;
  for (std::size_t k = 0; k < hull.size(); ++k) {
    const Eigen::Vector2d e = hull[(k + 1) % hull.size()] - hull[k];
    n.push_back(Eigen::Vector2d(e.y(), -e.x()).normalized());
  }
  return n;
}

// min over n in {e} and the edge normals of either body of support sum / (n.e) (see
// ref3d/pairs.hpp radial_estimate); along its own edge a body's support is the edge's offset.
template <class Support>
double radial2(const Support& s, const Eigen::Matrix2d& ra, const Eigen::Matrix2d& rb, const Eigen::Vector2d& e,
               const std::vector<Eigen::Vector2d>& normals, const std::vector<double>& offsets)
{
  const auto along = [&](const Eigen::Vector2d& n, double sa, double sb) {
    const double c = n.dot(e);
    if (!(c > 1e-6)) return std::numeric_limits<double>::infinity();
    return (sa + sb) / c;
  };
  double best = along(e, s(ra.transpose() * e), s(-(rb.transpose() * e)));
  for (std::size_t k = 0; k < normals.size(); ++k) {
    const Eigen::Vector2d na = ra * normals[k], nb = -(rb * normals[k]);
    best = std::min({best, along(na, offsets[k], s(-(rb.transpose() * na))),
                     along(nb, s(ra.transpose() * nb), offsets[k])});
  }
  return best;
}

std::vector<Pairs2dPile> run_pile(const Pairs2dOptions& o, const Shape2& shape, const SupportMap2& map,
                                  std::uint64_t seed, bool& asleep)
{
  const std::vector<Pile2dContact> contacts = box2d_pile_contacts(shape, table_of(o.shape), o.n, o.steps, seed, asleep);
  const std::vector<Eigen::Vector2d> hull = to_eigen(shape.hull);
  const std::vector<Eigen::Vector2d> edges = edge_normals(hull);
  std::vector<double> offsets;
  for (const Eigen::Vector2d& n : edges) offsets.push_back(support(hull, n));
  const auto exact = [&](const Eigen::Vector2d& u) { return support(hull, u); };
  const auto table = [&](const Eigen::Vector2d& u) { return map.lookup(u); };
  std::vector<Pairs2dPile> out;
  for (const Pile2dContact& c : contacts) {
    const Eigen::Matrix2d ra = rotation(c.angle_a), rb = rotation(c.angle_b);
    const Eigen::Vector2d ab = c.cb - c.ca, e = ab.normalized();
    const Eigen::Vector2d& n = c.normal;
    Pairs2dPile p;
    p.distance = ab.norm();
    p.angle_deg = std::acos(std::min(1.0, std::fabs(e.y()))) * 180.0 / kPi;
    p.along_normal = ab.dot(n);
    p.support_e = exact(ra.transpose() * e) + exact(-(rb.transpose() * e));
    p.support_e_map = table(ra.transpose() * e) + table(-(rb.transpose() * e));
    p.support_n = exact(ra.transpose() * n) + exact(-(rb.transpose() * n));
    p.radial = radial2(exact, ra, rb, e, edges, offsets);
    p.radial_map = radial2(table, ra, rb, e, edges, offsets);
    out.push_back(p);
  }
  return out;
}

}  // namespace

std::vector<Pile2dContact> box2d_pile_contacts(const Shape2& shape, const statsim::SignatureView<2>& sig, int n,
                                               int steps, std::uint64_t seed, bool& asleep)
{
  Compare2dOptions co;
  co.n = n;
  co.seed = seed;
  const std::vector<Body2State> init = compare2d_initial_states(co, shape.bounding_radius);
  // As `statsim compare2d`'s Box2D run.
  b2World world(b2Vec2(0.0f, -9.81f));
  world.SetAllowSleeping(true);
  const std::vector<b2Body*> bodies = add_box2d_pile(world, shape, sig, init);
  std::map<const b2Body*, std::size_t> index;
  for (std::size_t i = 0; i < bodies.size(); ++i) index[bodies[i]] = i;
  for (int step = 0; step < steps; ++step) world.Step(1.0f / 60.0f, 8, 3);
  asleep = true;
  for (b2Body* b : bodies) asleep = asleep && !b->IsAwake();
  std::map<std::pair<std::size_t, std::size_t>, Eigen::Vector2d> normals, first_normal;
  for (b2Contact* c = world.GetContactList(); c; c = c->GetNext()) {
    if (!c->IsTouching()) continue;
    const b2Body* ba = c->GetFixtureA()->GetBody();
    const b2Body* bb = c->GetFixtureB()->GetBody();
    if (ba->GetType() != b2_dynamicBody || bb->GetType() != b2_dynamicBody) continue;
    b2WorldManifold wm;
    c->GetWorldManifold(&wm);
    std::size_t ia = index.at(ba), ib = index.at(bb);
    Eigen::Vector2d nrm(wm.normal.x, wm.normal.y);  // from A to B
    if (ia > ib) {
      std::swap(ia, ib);
      nrm = -nrm;
    }
    auto it = normals.find({ia, ib});
    if (it == normals.end()) {
      normals[{ia, ib}] = nrm;
      first_normal[{ia, ib}] = nrm;
    } else {
      it->second += nrm;
    }
  }
  std::vector<Pile2dContact> out;
  for (const auto& [key, nsum] : normals) {
    const b2Body* ba = bodies[key.first];
    const b2Body* bb = bodies[key.second];
    Pile2dContact c;
    c.ca = Eigen::Vector2d(ba->GetPosition().x, ba->GetPosition().y);
    c.cb = Eigen::Vector2d(bb->GetPosition().x, bb->GetPosition().y);
    c.angle_a = ba->GetAngle();
    c.angle_b = bb->GetAngle();
    // Contacts of two pieces can point opposite ways (nested L-shapes): then the first stands.
    c.normal = nsum.norm() > 0.5 ? Eigen::Vector2d(nsum.normalized()) : first_normal.at(key);
    out.push_back(c);
  }
  return out;
}

PairDistances2d pair_distances2d(const Shape2& shape, const std::vector<double>& spin_ratios, int trials, double speed,
                                 std::uint64_t seed, unsigned threads)
{
  const std::vector<Eigen::Vector2d> outline = to_eigen(shape.outline), hull = to_eigen(shape.hull);
  const double L = shape.bounding_radius;
  const std::size_t ns = spin_ratios.size(), nt = static_cast<std::size_t>(trials);
  std::vector<double> d(ns * nt), h(ns * nt);
  parallel_for(
      ns * nt,
      [&](std::size_t k) {
        const double s = spin_ratios[k / nt];
        d[k] = flight(outline, L, s, speed, seed, k);
        h[k] = flight(hull, L, s, speed, seed, k);
      },
      threads);
  PairDistances2d r;
  for (std::size_t si = 0; si < ns; ++si) {
    const std::vector<double> ds(d.begin() + si * nt, d.begin() + (si + 1) * nt);
    const std::vector<double> hs(h.begin() + si * nt, h.begin() + (si + 1) * nt);
    r.mean.push_back(mean_of(ds));
    r.std.push_back(std_of(ds));
    r.hull_mean.push_back(mean_of(hs));
  }
  r.flights = static_cast<long long>(ns * nt);
  return r;
}

double pair_trial2d(const std::string& shape, double spin_ratio, std::uint64_t seed, std::uint64_t index,
                    bool hull_only)
{
  const Shape2 s = shape_of(shape);
  return flight(to_eigen(hull_only ? s.hull : s.outline), s.bounding_radius, spin_ratio, 1.0, seed, index);
}

Pairs2dResult gather_pairs2d(const Pairs2dOptions& o)
{
  const Shape2 shape = shape_of(o.shape);
  if (o.trials < 2) throw std::invalid_argument("gather-pairs2d: --trials must be at least 2");
  if (o.support_size < 2) throw std::invalid_argument("gather-pairs2d: --support-size must be at least 2");
  Pairs2dResult r;
  r.options = o;
  r.bounding_radius = shape.bounding_radius;
  r.h_coll = static_cast<double>(table_of(o.shape).height.mean_at(0));
  const std::vector<Eigen::Vector2d> hull = to_eigen(shape.hull);
  const auto t0 = std::chrono::steady_clock::now();
  {
    const PairDistances2d pd = pair_distances2d(shape, o.spin_ratios, o.trials, o.speed, o.seed, o.threads);
    r.pair_mean = pd.mean;
    r.pair_std = pd.std;
    r.hull_mean = pd.hull_mean;
  }
  r.pair_seconds = seconds_since(t0);
  for (int size : o.support_sizes) {
    const SupportMap2 m = SupportMap2::build(hull, size);
    const SupportError e = measure_support_error(m, hull, 100000);
    r.support.push_back({size, m.error_bound(hull), e.mean, e.max});
  }
  const SupportMap2 map = SupportMap2::build(hull, o.support_size);
  r.support_map = map.values;
  r.support_bound = map.error_bound(hull);
  const auto t1 = std::chrono::steady_clock::now();
  std::vector<std::vector<Pairs2dPile>> piles(static_cast<std::size_t>(o.drops));
  std::vector<char> asleep(piles.size(), 0);
  parallel_for(
      piles.size(),
      [&](std::size_t i) {
        bool a = false;
        piles[i] = run_pile(o, shape, map, o.seed + i, a);
        asleep[i] = a;
      },
      o.threads);
  for (std::size_t i = 0; i < piles.size(); ++i) {
    r.pile_pairs.insert(r.pile_pairs.end(), piles[i].begin(), piles[i].end());
    r.asleep += asleep[i];
    r.bodies += o.n;
  }
  r.pile_seconds = seconds_since(t1);
  return r;
}

namespace {

struct Stat {
  int n = 0;
  double mean = 0.0, std = 0.0, p10 = 0.0, p90 = 0.0;
};

Stat stat(std::vector<double> v)
{
  Stat s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.mean = mean_of(v);
  s.std = std_of(v);
  s.p10 = v[static_cast<std::size_t>(0.1 * static_cast<double>(v.size() - 1))];
  s.p90 = v[static_cast<std::size_t>(0.9 * static_cast<double>(v.size() - 1))];
  return s;
}

const std::vector<std::pair<double, double>> kBins = {{0, 30}, {30, 60}, {60, 90.001}, {0, 90.001}};

std::string bin_name(const std::pair<double, double>& b)
{
  return b.first == 0 && b.second > 90 ? std::string("all") : num(b.first) + "-" + num(std::floor(b.second)) + " deg";
}

// The ratio columns: name and value of a pile pair.
struct Column {
  const char* name;
  double (*value)(const Pairs2dPile&, const Pairs2dResult&);
};
const Column kColumns[] = {
    {"d / 2 h_coll", [](const Pairs2dPile& p, const Pairs2dResult& r) { return p.distance / (2 * r.h_coll); }},
    {"d / pair distance", [](const Pairs2dPile& p, const Pairs2dResult& r) { return p.distance / r.pair_mean.front(); }},
    {"d / support(e)", [](const Pairs2dPile& p, const Pairs2dResult&) { return p.distance / p.support_e; }},
    {"(d.n) / support(n)", [](const Pairs2dPile& p, const Pairs2dResult&) { return p.along_normal / p.support_n; }},
    {"d / radial (edges)", [](const Pairs2dPile& p, const Pairs2dResult&) { return p.distance / p.radial; }},
    {"d / radial (map)", [](const Pairs2dPile& p, const Pairs2dResult&) { return p.distance / p.radial_map; }},
    {"d - radial (map), mm", [](const Pairs2dPile& p, const Pairs2dResult&) { return 1000 * (p.distance - p.radial_map); }},
};

Stat column_stat(const Pairs2dResult& r, const Column& c, const std::pair<double, double>& bin)
{
  std::vector<double> v;
  for (const Pairs2dPile& p : r.pile_pairs)
    if (p.angle_deg >= bin.first && p.angle_deg < bin.second) v.push_back(c.value(p, r));
  return stat(v);
}

}  // namespace

std::string pairs2d_json(const Pairs2dResult& r, const std::string& command)
{
  using json = nlohmann::ordered_json;
  json j;
  j["generated_by"] = command;
  j["shape"] = r.options.shape;
  j["bounding_radius"] = r.bounding_radius;
  j["h_coll"] = r.h_coll;
  j["pair_distance"] = {{"spin_ratios", r.options.spin_ratios}, {"mean", r.pair_mean},     {"std", r.pair_std},
                        {"hull_mean", r.hull_mean},            {"flights_per_ratio", r.options.trials},
                        {"speed", r.options.speed}};
  json sup = json::array();
  for (const auto& s : r.support)
    sup.push_back({{"size", s.size}, {"bound", s.bound}, {"mean_error", s.mean}, {"max_error", s.max}});
  j["support_errors"] = sup;
  std::vector<double> as_float;
  for (double v : r.support_map) as_float.push_back(static_cast<double>(static_cast<float>(v)));
  j["support_map"] = {{"size", r.options.support_size},
                      {"values", "table.support"},
                      {"layout", "4 sides (+x,-x,+y,-y) x S, index f S + i, i along the other axis, node -1 + 2 i / "
                                 "(S - 1); s(u) = |u_m| linear(h)"},
                      {"bound", r.support_bound}};
  json bins = json::array();
  for (const auto& bin : kBins) {
    json b;
    b["bin"] = bin_name(bin);
    for (const Column& c : kColumns) {
      const Stat s = column_stat(r, c, bin);
      b[c.name] = {{"n", s.n}, {"mean", s.mean}, {"std", s.std}, {"p10", s.p10}, {"p90", s.p90}};
    }
    bins.push_back(b);
  }
  {
    const Shape2 shape = shape_of(r.options.shape);
    const std::vector<Eigen::Vector2d> hull = to_eigen(shape.hull);
    json normals = json::array(), offsets = json::array();
    for (const Eigen::Vector2d& n : edge_normals(hull)) {
      normals.push_back({static_cast<double>(static_cast<float>(n.x())), static_cast<double>(static_cast<float>(n.y()))});
      offsets.push_back(static_cast<double>(static_cast<float>(support(hull, n))));
    }
    json mean = json::array(), sd = json::array(), count = json::array();
    for (std::size_t b = 0; b < 3; ++b) {
      const Stat x = column_stat(r, kColumns[5], kBins[b]);
      mean.push_back(x.n > 0 ? x.mean : 1.0);
      sd.push_back(x.std);
      count.push_back(x.n);
    }
    // The proposed table fields in one place (tools/ref3d/README.md, "Body-body statistics").
    j["table"] = {{"pair_spin_ratios", r.options.spin_ratios}, {"pair_mean", r.pair_mean},
                  {"pair_stddev", r.pair_std},                 {"support_size", r.options.support_size},
                  {"support", as_float},                       {"edge_normals", normals},
                  {"edge_offsets", offsets},                   {"packing_bins_deg", {0, 30, 60, 90}},
                  {"packing_mean", mean},                      {"packing_stddev", sd},
                  {"packing_pairs", count}};
  }
  j["packing"] = {{"drops", r.options.drops}, {"bodies", r.bodies},     {"drops_asleep", r.asleep},
                  {"pairs", r.pile_pairs.size()}, {"by_angle", bins}};
  return j.dump(2) + "\n";
}

std::string pairs2d_markdown(const Pairs2dResult& r, const std::string& command)
{
  std::ostringstream s;
  const double L = r.bounding_radius;
  s << "### " << r.options.shape << " (2D)\n\n`" << command << "`\n\n";
  s << "L = " << fmt("%.4f", L) << " m; h_coll (s = 0, committed table) = " << fmt("%.4f", r.h_coll)
    << " m, 2 h_coll = " << fmt("%.4f", 2 * r.h_coll) << " m.\n\n";
  s << "Pair distance at first contact (" << r.options.trials << " flights per spin ratio, "
    << fmt("%.1f", r.pair_seconds) << " s):\n\n| spin ratio | mean (m) | std (m) | mean / 2 h_coll | hulls' mean (m) |\n"
    << "|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < r.pair_mean.size(); ++i)
    s << "| " << num(r.options.spin_ratios[i]) << " | " << fmt("%.4f", r.pair_mean[i]) << " | "
      << fmt("%.4f", r.pair_std[i]) << " | " << fmt("%.3f", r.pair_mean[i] / (2 * r.h_coll)) << " | "
      << fmt("%.4f", r.hull_mean[i]) << " |\n";
  s << "\nSupport square map against the exact hull support (100000 directions), errors in units of L:\n\n"
       "| S | bytes (f32) | bound | mean | max |\n|---|---|---|---|---|\n";
  for (const auto& x : r.support)
    s << "| " << x.size << " | " << 16 * x.size << " | " << fmt("%.4f", x.bound / L) << " | " << fmt("%.5f", x.mean / L)
      << " | " << fmt("%.4f", x.max / L) << " |\n";
  s << "\nPacking in " << r.options.drops << " Box2D piles of " << r.options.n << " (" << r.asleep << " all asleep, "
    << r.pile_pairs.size() << " touching pairs, " << fmt("%.1f", r.pile_seconds)
    << " s): mean +- std [p10, p90].\n\n| angle of e to vertical | pairs |";
  for (const Column& c : kColumns) s << " " << c.name << " |";
  s << "\n|---|---|";
  for (std::size_t k = 0; k < std::size(kColumns); ++k) s << "---|";
  s << "\n";
  for (const auto& bin : kBins) {
    s << "| " << bin_name(bin) << " | " << column_stat(r, kColumns[0], bin).n << " |";
    for (const Column& c : kColumns) {
      const Stat x = column_stat(r, c, bin);
      const char* f = c.name[std::string(c.name).size() - 1] == 'm' ? "%.1f" : "%.3f";
      s << " " << fmt(f, x.mean) << " +- " << fmt(f, x.std) << " [" << fmt(f, x.p10) << ", " << fmt(f, x.p90) << "] |";
    }
    s << "\n";
  }
  return s.str();
}

void register_pairs2d_command(CLI::App& app)
{
  struct Command {
    Pairs2dOptions o;
    std::string json, report;
  };
  auto c = std::make_shared<Command>();
  Pairs2dOptions& o = c->o;
  CLI::App* sub = app.add_subcommand(
      "gather-pairs2d",
      "Body-body statistics of a 2D shape with Box2D: pair distance at first contact against spin, the hull's support "
      "square map and its error, packing of touching pairs in compare2d's piles (tools/ref2d/pairs2d.hpp)");
  sub->add_option("--shape", o.shape, "square or lshape")->check(CLI::IsMember({"square", "lshape"}))->capture_default_str();
  sub->add_option("--spin-ratios", o.spin_ratios, "Spin ratios of the pair flights")->delimiter(',')->capture_default_str();
  sub->add_option("--trials", o.trials, "Pair flights per spin ratio")->capture_default_str();
  sub->add_option("--support-sizes", o.support_sizes, "Square-map sizes S whose error is measured")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--support-size", o.support_size, "S of the stored square map (4 S values)")->capture_default_str();
  sub->add_option("--drops", o.drops, "Box2D piles (seeds seed..)")->capture_default_str();
  sub->add_option("--n", o.n, "Bodies per pile")->capture_default_str();
  sub->add_option("--steps", o.steps, "Steps of 1/60 s per pile")->capture_default_str();
  sub->add_option("--speed", o.speed, "Relative approach speed of the pair flights, m/s")->capture_default_str();
  sub->add_option("--seed", o.seed, "Random seed")->capture_default_str();
  sub->add_option("--threads", o.threads, "Worker threads (0 = all)")->capture_default_str();
  sub->add_option("--json", c->json, "Write the statistics as JSON to this file");
  sub->add_option("--report", c->report, "Write the markdown report to this file");
  sub->callback([c, sub]() {
    try {
      std::string cmd = "build/bin/statsim gather-pairs2d";
      for (const CLI::Option* opt : sub->get_options()) {
        const std::string name = opt->get_name(false, true);
        if (opt->count() == 0 || name.rfind("--", 0) != 0 || name == "--threads" || name == "--json" ||
            name == "--report")
          continue;
        std::string value;
        for (const std::string& x : opt->results()) value += (value.empty() ? "" : ",") + x;
        cmd += " " + name + " " + value;
      }
      const Pairs2dResult r = gather_pairs2d(c->o);
      const std::string md = pairs2d_markdown(r, cmd);
      if (!c->json.empty()) write_file_atomic(c->json, pairs2d_json(r, cmd));
      if (!c->report.empty()) write_file_atomic(c->report, md);
      std::cout << md;
    } catch (const std::exception& e) {
      std::cerr << "statsim gather-pairs2d: error: " << e.what() << "\n";
      throw CLI::RuntimeError(1);
    }
  });
}

}  // namespace statsim::tools
