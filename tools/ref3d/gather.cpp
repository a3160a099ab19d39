#include "ref3d/gather.hpp"

#include "common/format.hpp"
#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "common/rest_families.hpp"
#include "common/support_map.hpp"
#include "common/table_writer.hpp"
#include "ref3d/pairs.hpp"
#include "ref3d/sampling.hpp"
#include "statsim/detail/hull.hpp"
#include "statsim/detail/shape_setup.hpp"
#include "statsim/detail/response.hpp"
#include "statsim/signature.hpp"
#include "statsim/statistical.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace statsim::tools::ref3d {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Rest normals within this angle of a hull face's are snapped to it.
constexpr double kSnapDegrees = 3.0;
// Packing bins are as wide as gather-pairs' `--bin 2.2`: walls 4.4 L apart, 2 x 2 bodies a layer.
constexpr double kPackingBinHalfWidth = 2.2;

// A pool of Reference objects, one per worker at most: a task borrows one and gives it back.
// Trials build a fresh Bullet world each, so which object runs a trial does not matter.
class ReferencePool {
public:
  ReferencePool(const ShapeModel& m, const ReferenceSettings& s) : model_(m), settings_(s) {}
  template <class F>
  auto with(F&& f)
  {
    std::unique_ptr<Reference> ref;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!free_.empty()) {
        ref = std::move(free_.back());
        free_.pop_back();
      }
    }
    if (!ref) ref = std::make_unique<Reference>(model_, settings_);
    struct Return {
      ReferencePool& pool;
      std::unique_ptr<Reference>& ref;
      ~Return()
      {
        std::lock_guard<std::mutex> lock(pool.mutex_);
        pool.free_.push_back(std::move(ref));
      }
    } give_back{*this, ref};
    return f(*ref);
  }

private:
  const ShapeModel& model_;
  ReferenceSettings settings_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<Reference>> free_;
};

struct Stats {
  double mean = 0.0, std = 0.0;
};
template <class Get>
Stats stats(std::size_t n, Get&& get)
{
  Stats s;
  if (n == 0) return s;
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) sum += get(i);
  s.mean = sum / static_cast<double>(n);
  if (n < 2) return s;
  double sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = get(i) - s.mean;
    sq += d * d;
  }
  s.std = std::sqrt(sq / static_cast<double>(n - 1));
  return s;
}

bool strictly_increasing(const std::vector<double>& v)
{
  for (std::size_t i = 1; i < v.size(); ++i)
    if (!(v[i] > v[i - 1])) return false;
  return true;
}

}  // namespace

// ---- axes ------------------------------------------------------------------------------------

std::vector<double> default_height_ratios()
{
  return {0, 0.25, 0.5, 1, 1.5, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64};
}
std::vector<double> default_cos_theta()
{
  return {0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1};
}
std::vector<double> default_cos_phi()
{
  std::vector<double> v;
  for (int i = 0; i < 10; ++i) v.push_back(i == 9 ? 1.0 : -1.0 + 2.0 * i / 9.0);
  return v;
}
std::vector<double> default_spin_ratios()
{
  return {0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.65, 0.8, 1, 1.25, 1.5, 2, 3, 4, 6, 8};
}
std::vector<double> default_paper_speeds()
{
  // 26 speeds, geometric from 0.25 to 12 m/s, rounded to 3 significant digits.
  std::vector<double> v;
  for (int i = 0; i < 26; ++i) {
    const double x = 0.25 * std::pow(12.0 / 0.25, i / 25.0);
    v.push_back(std::strtod(fmt("%.3g", x).c_str(), nullptr));
  }
  return v;
}
std::vector<double> default_coarse_speeds()
{
  return {0.5, 1, 2, 4, 8};
}

void validate_gather_options(const GatherOptions& o)
{
  auto fail = [](const std::string& m) { throw std::runtime_error(m); };
  if (!o.name.empty() && !cpp_identifier(o.name)) fail("--name '" + o.name + "' is not a C++ identifier");
  if (o.trials < 2) fail("--trials must be at least 2");
  if (o.height_trials < 2) fail("--height-trials must be at least 2");
  if (o.rest_drops < 1) fail("--rest-drops must be at least 1");
  if (!(o.speed > 0) || !std::isfinite(o.speed)) fail("--speed must be positive");
  if (!(o.density > 0) || !std::isfinite(o.density)) fail("--density must be positive");
  const ReferenceSettings& r = o.reference;
  if (!(r.dt > 0) || r.dt > 0.1) fail("--dt must be in (0, 0.1] s");
  if (!(r.restitution >= 0 && r.restitution <= 1)) fail("--restitution must be in [0, 1]");
  if (!(r.friction >= 0) || !std::isfinite(r.friction)) fail("--friction must be >= 0");
  if (!(r.restitution_threshold >= 0) || !std::isfinite(r.restitution_threshold))
    fail("--restitution-threshold must be >= 0");
  if (!(r.margin > 0) || !std::isfinite(r.margin)) fail("--margin must be positive");
  if (r.solver_iterations < 1) fail("--solver-iterations must be at least 1");
  if (!(o.rolling_resistance >= 0)) fail("--rolling-resistance must be >= 0");
  if (!(o.rest_tolerance_deg > 0 && o.rest_tolerance_deg < 90)) fail("--rest-tolerance must be in (0, 90) degrees");
  if (!(o.rest_min_frequency >= 0 && o.rest_min_frequency < 1)) fail("--rest-min-frequency must be in [0, 1)");
  if (o.response_model == ResponseModel::empirical &&
      (o.empirical_outcomes < 1 || o.empirical_outcomes > o.trials ||
       o.empirical_outcomes > static_cast<int>(max_empirical_outcomes)))
    fail("--empirical-outcomes must be in [1, min(--trials, " + std::to_string(max_empirical_outcomes) + ")]");
  if (!(o.rest_max_dropped >= 0 && o.rest_max_dropped <= 1)) fail("--rest-max-dropped must be in [0, 1]");
  if (!(o.max_impact_time > 0) || !(o.max_drop_time > 0) || !(o.still_time > 0) || !(o.still_speed > 0))
    fail("time limits and the stillness threshold must be positive");
  auto axis = [&](const std::vector<double>& v, const char* what, double lo, double hi) {
    if (v.empty()) fail(std::string(what) + ": needs at least one sample");
    if (!strictly_increasing(v)) fail(std::string(what) + ": samples must be strictly increasing");
    if (!(v.front() >= lo) || !(v.back() <= hi)) fail(std::string(what) + ": samples must lie in [" + num(lo) + ", " + num(hi) + "]");
  };
  if (!o.box_size.empty()) {
    if (o.box_size.size() != 3) fail("--box-size needs three values X,Y,Z");
    for (double x : o.box_size)
      if (!(x > 0) || !std::isfinite(x)) fail("--box-size: sizes must be positive");
  }
  axis(o.height_ratios, "height ratios", 0, 1e6);
  axis(o.cos_theta, "cos theta axis", 1e-3, 1);
  axis(o.cos_phi, "cos phi axis", -1, 1);
  axis(o.spin_ratios, "spin ratio axis", 0, 1e6);
  if (o.with_speed && !o.speeds.empty()) axis(o.speeds, "speed axis", 1e-3, 1e3);
  if (o.body_contacts) {
    if (o.support_size < 2 || o.support_size > static_cast<int>(max_support_size))
      fail("--support-size must be in [2, " + std::to_string(max_support_size) + "]");
    if (o.contact_faces < 0 || o.contact_faces > static_cast<int>(max_contact_faces))
      fail("--contact-faces must be in [0, " + std::to_string(max_contact_faces) + "]");
    if (o.pair_trials < 2) fail("--pair-trials must be at least 2");
    if (o.packing_piles < 0 || o.packing_bins < 0) fail("--packing-piles and --packing-bins must be >= 0");
    if (o.packing_count < 2) fail("--packing-count must be at least 2");
  }
}

ShapeModel build_model(const GatherOptions& o)
{
  if (o.box_size.empty()) return load_shape_model(o.shape, o.mesh_file, o.density, o.mesh_scale, o.mesh_units_given);
  ShapeModel m = make_box_model(Eigen::Vector3d(o.box_size[0], o.box_size[1], o.box_size[2]), o.density);
  m.source = "generated " + num(o.box_size[0]) + " x " + num(o.box_size[1]) + " x " + num(o.box_size[2]) + " m box";
  return m;
}

// ---- trials ----------------------------------------------------------------------------------

double height_trial(const ShapeModel& m, double spin_ratio, std::uint64_t seed, std::uint64_t index)
{
  TrialRng rng(seed, kHeightStream, index);
  const double L = m.bounding_radius, u = 1.0;
  RigidState s;
  s.orientation = rng.rotation();
  s.spin = rng.direction() * (spin_ratio * u / L);
  s.velocity = Eigen::Vector3d(0, 0, -u);
  s.position = Eigen::Vector3d(0, 0, L * (1 + 1e-9));
  const FreeFlight flight(m.unit_inertia);
  const FirstContact fc = first_contact(m.hull, L, flight, s, 0.0, std::numeric_limits<double>::infinity(),
                                        1e-12 * L, 100000000);
  return fc.state.position.z() - lowest_point(m.hull, fc.state);
}

ResponseTrial response_trial(const Reference& ref, const GatherOptions& o, double cos_theta, double cos_phi,
                             double speed, double spin_ratio, std::uint64_t stream, std::uint64_t index)
{
  const ShapeModel& m = ref.model();
  TrialRng rng(o.seed, stream, index);
  const double L = m.bounding_radius;
  const double ct = cos_theta, st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
  const Eigen::Vector3d vhat(st, 0.0, -ct), e1(ct, 0.0, st), e2(0.0, 1.0, 0.0);
  const double azimuth = 2.0 * kPi * rng.uniform();
  const double alpha = ct >= 1.0 ? 0.0 : azimuth;
  const double sp = std::sqrt(std::max(0.0, 1.0 - cos_phi * cos_phi));
  const Eigen::Vector3d wdir = cos_phi * vhat + sp * (std::cos(alpha) * e1 + std::sin(alpha) * e2);

  RigidState s0;
  s0.orientation = rng.rotation();
  s0.velocity = speed * vhat;
  s0.spin = wdir * (spin_ratio * speed / L);
  s0.position = Eigen::Vector3d(0, 0, L * (1 + 1e-9));
  const FreeFlight flight(m.unit_inertia);
  const FirstContact fc = first_contact(m.hull, L, flight, s0, 0.0, std::numeric_limits<double>::infinity(),
                                        1e-12 * L, 100000000);
  RigidState start = fc.state;
  start.position.z() -= 1e-6 * L;  // a hair into the ground, so that Bullet's first step has the contact
  const ImpactResult ir = ref.impact(start, o.max_impact_time);

  const Material mat{static_cast<Scalar>(o.reference.restitution), static_cast<Scalar>(o.reference.friction),
                     static_cast<Scalar>(o.rolling_resistance)};
  const Vector3 vminus = s0.velocity.cast<Scalar>();
  const Vector3 vp = point_particle_velocity<3>(vminus, Vector3(0, 0, 1), mat,
                                                static_cast<Scalar>(o.reference.restitution_threshold));
  ResponseTrial out;
  const Eigen::Vector3d w = ir.after.spin * (L / speed);
  const Eigen::Vector3d dv = (ir.after.velocity - vp.cast<double>()) / speed;
  out.value = {w.x(), w.y(), w.z(), dv.x(), dv.y(), dv.z()};
  out.time_limited = ir.time_limited;
  out.max_penetration = ir.max_penetration;
  out.steps = ir.steps;
  return out;
}

namespace {

struct DropTrial {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double height = 0.0;
  double time = 0.0;
  bool settled = false;
};

DropTrial drop_trial(const Reference& ref, const GatherOptions& o, std::uint64_t index)
{
  const ShapeModel& m = ref.model();
  TrialRng rng(o.seed, kRestStream, index);
  const double L = m.bounding_radius;
  RigidState s;
  s.orientation = rng.rotation();
  s.velocity = Eigen::Vector3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
  s.spin = rng.direction() * rng.uniform(0, 4 * kPi);
  const double lift = L * rng.uniform(0.25, 3.0);
  s.position = Eigen::Vector3d(0, 0, -lowest_point(m.hull, s) + lift);
  const DropResult r = ref.drop(s, o.still_speed, o.still_time, o.max_drop_time);
  DropTrial d;
  d.up = r.rest.orientation.conjugate() * Eigen::Vector3d::UnitZ();
  d.height = r.height;
  d.time = r.time;
  d.settled = r.settled;
  return d;
}

// The index of the centre nearest to `dir` within the angle whose cosine is `cos_tol` (the first
// of equals), or of a new centre at `dir` when none is that near.
int nearest_or_new(std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& dir, double cos_tol)
{
  int best = -1;
  double best_c = cos_tol;
  for (std::size_t c = 0; c < centres.size(); ++c) {
    const double d = centres[c].dot(dir);
    if (d >= best_c) {
      best_c = d;
      best = static_cast<int>(c);
    }
  }
  if (best < 0) {
    best = static_cast<int>(centres.size());
    centres.push_back(dir);
  }
  return best;
}

// Clusters unit vectors: leader clustering in input order within `tol` (radians), then up to 20
// rounds of assigning each vector to the nearest cluster mean (a new cluster when none is within
// `tol`) until nothing moves. Returns the cluster of each vector; deterministic.
std::vector<int> cluster_directions(const std::vector<Eigen::Vector3d>& dirs, double tol)
{
  const double cos_tol = std::cos(tol);
  std::vector<Eigen::Vector3d> centres;
  std::vector<int> label(dirs.size(), -1);
  for (std::size_t i = 0; i < dirs.size(); ++i) label[i] = nearest_or_new(centres, dirs[i], cos_tol);
  for (int round = 0; round < 20; ++round) {
    std::vector<Eigen::Vector3d> sum(centres.size(), Eigen::Vector3d::Zero());
    for (std::size_t i = 0; i < dirs.size(); ++i) sum[label[i]] += dirs[i];
    std::vector<Eigen::Vector3d> mean;
    for (const auto& s : sum)
      if (s.norm() > 0) mean.push_back(s.normalized());
    bool moved = mean.size() != centres.size();
    std::vector<int> next(dirs.size(), -1);
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      next[i] = nearest_or_new(mean, dirs[i], cos_tol);
      moved = moved || next[i] != label[i];
    }
    label = next;
    centres = mean;
    if (!moved) break;
  }
  return label;
}

// The invariants of standing on hull face `plane` under the shape's symmetries (a symmetry fixes
// the centre of mass and maps the face onto an equivalent one), lengths in units of the bounding
// radius L: the rest height; the moment of inertia about the up axis per unit mass; the face's
// area; its vertex count and sorted edge lengths; the sorted distances of its vertices from the
// centre's projection on it; and the sorted heights of every hull vertex above the ground.
std::vector<double> face_descriptor(const ShapeModel& m, const Eigen::Vector4d& plane)
{
  const double L = m.bounding_radius;
  const Eigen::Vector3d n = plane.head<3>();
  const double w = plane.w();
  const Eigen::Vector3d foot = w * n;
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  std::vector<Eigen::Vector2d> face;
  std::vector<double> heights;
  for (const Eigen::Vector3d& p : m.hull) {
    const double d = w - n.dot(p);
    heights.push_back(d / L);
    if (d <= 1e-6 * L) face.emplace_back(a.dot(p - foot) / L, b.dot(p - foot) / L);
  }
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& q : face) centre += q;
  if (!face.empty()) centre /= static_cast<double>(face.size());
  std::sort(face.begin(), face.end(), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    return std::atan2(p.y() - centre.y(), p.x() - centre.x()) < std::atan2(q.y() - centre.y(), q.x() - centre.x());
  });
  double area = 0.0;
  std::vector<double> edges, radii;
  for (std::size_t i = 0; i < face.size(); ++i) {
    const Eigen::Vector2d& p = face[i];
    const Eigen::Vector2d& q = face[(i + 1) % face.size()];
    area += 0.5 * (p.x() * q.y() - q.x() * p.y());
    edges.push_back((q - p).norm());
    radii.push_back(p.norm());
  }
  std::sort(edges.begin(), edges.end());
  std::sort(radii.begin(), radii.end());
  std::sort(heights.begin(), heights.end());
  const Eigen::Vector3d& I = m.unit_inertia;
  std::vector<double> d = {w / L, (n.x() * n.x() * I.x() + n.y() * n.y() * I.y() + n.z() * n.z() * I.z()) / (L * L),
                           std::fabs(area), static_cast<double>(face.size()), static_cast<double>(heights.size())};
  d.insert(d.end(), edges.begin(), edges.end());
  d.insert(d.end(), radii.begin(), radii.end());
  d.insert(d.end(), heights.begin(), heights.end());
  return d;
}


// The support map as the table stores it (f32, or the i16 rule) and the view the runtime reads.
struct StoredSupport {
  std::vector<float> values;
  Quantized q;
  bool i16 = false;
  ValuesView view() const
  {
    return i16 ? ValuesView{nullptr, q.q.data(), q.scale, q.offset} : ValuesView{values.data(), nullptr, 1, 0};
  }
};

// d / (the runtime's contact distance along the line of centres) of a touching pile pair: the
// least candidate distance that `find_hull_witness` finds on the table's own data, packing 1;
// with the candidate it found.
PackingSample packing_sample(const Shape<3>& shape, const PileContact& c)
{
  Body<3> a{}, b{};
  a.orientation = c.a.orientation.cast<Scalar>().normalized();
  b.orientation = c.b.orientation.cast<Scalar>().normalized();
  const Eigen::Vector3d ab = c.b.position - c.a.position;
  const Vector3 e = ab.normalized().cast<Scalar>();
  // Distance 0 is below any positive reach, so the search always names its best candidate.
  std::uint32_t k = statsim::detail::find_hull_witness(shape, a, shape, b, e, Scalar(0), Scalar(1));
  if (k == statsim::detail::no_witness) k = 0;
  const statsim::detail::HullCandidate<3> h = statsim::detail::hull_candidate(shape, a, shape, b, e, k);
  PackingSample p;
  p.ratio = ab.norm() / (static_cast<double>(h.reach) / static_cast<double>(h.normal.dot(e)));
  p.up = ab.z() / ab.norm();
  p.witness = k;
  return p;
}

// 4. Body-body data (statsim::ContactView): pair distance, support map, faces, packing.
void gather_body_contacts(GatherResult& r)
{
  const GatherOptions& o = r.options;
  const ShapeModel& m = r.model;
  BodyContactData& c = r.contact;
  c.dims = 3;
  // Body point = R (mesh point - com), R = the principal axes' transpose: R's rows are the axes.
  const Eigen::Matrix3d& axes = m.mass.principal_axes;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.mesh_frame.push_back(axes(j, i));
  for (int i = 0; i < 3; ++i) c.mesh_frame.push_back(m.mass.com[i]);

  const auto t0 = std::chrono::steady_clock::now();
  const PairDistances pd =
      pair_distances(m, o.height_ratios, o.pair_trials, o.speed, o.reference.margin, o.seed, o.threads, o.progress);
  c.pair_mean = pd.mean;
  c.pair_std = pd.std;
  c.pair_flights = pd.flights;
  c.pair_seconds = seconds_since(t0);

  const SupportMap3 map = SupportMap3::build(m.hull, o.support_size);
  c.support_size = o.support_size;
  c.support = map.values;
  c.support_bound = map.error_bound(m.hull);
  const std::vector<Eigen::Vector3d> normals = faces_by_area(m);
  const std::vector<double> offsets = face_offsets(m, normals);
  c.hull_faces = static_cast<int>(normals.size());
  const std::size_t k = std::min(normals.size(), static_cast<std::size_t>(o.contact_faces));
  // The packing ratio of each face (its last number) is measured below; 1 until then.
  for (std::size_t i = 0; i < k; ++i)
    c.faces.insert(c.faces.end(), {normals[i].x(), normals[i].y(), normals[i].z(), offsets[i], 1.0});

  // The table's own body-body data, as the runtime reads it from the header being written.
  StoredSupport stored;
  stored.i16 = o.i16;
  for (double v : c.support) stored.values.push_back(static_cast<float>(v) + 0.0f);
  if (o.i16) stored.q = quantize(stored.values);
  std::vector<float> faces;
  for (double v : c.faces) faces.push_back(static_cast<float>(v) + 0.0f);
  SignatureView<3> view{};
  view.contact.support_size = static_cast<std::uint32_t>(c.support_size);
  view.contact.support = stored.view();
  view.contact.faces = faces.empty() ? nullptr : faces.data();
  view.contact.face_count = static_cast<std::uint32_t>(k);
  Shape<3> shape{};
  shape.statistical = true;
  shape.signature = view;
  shape.support_floor = statsim::detail::support_bounds(view.contact).floor;

  // Packing: the reference piles and bins, then d / estimate by angle bin.
  const auto t1 = std::chrono::steady_clock::now();
  PairOptions drop;
  drop.shape = o;
  drop.pile_count = o.packing_count;
  PairOptions bin = drop;
  bin.bin = kPackingBinHalfWidth;
  c.piles = o.packing_piles;
  c.bins = o.packing_bins;
  const std::size_t runs = static_cast<std::size_t>(c.piles + c.bins);
  std::vector<ReferencePile> piles(runs);
  Progress progress("packing piles", runs, o.progress);
  parallel_for(
      runs,
      [&](std::size_t i) {
        const bool is_bin = i >= static_cast<std::size_t>(c.piles);
        const std::uint64_t seed = is_bin ? i - static_cast<std::size_t>(c.piles) + 1 : i + 1;
        piles[i] = reference_pile(m, is_bin ? bin : drop, seed);
        progress.add(1);
      },
      o.threads);
  progress.finish();
  std::vector<PackingSample> samples;
  for (const ReferencePile& p : piles) {
    c.asleep += p.asleep ? 1 : 0;
    c.pile_steps += p.steps;
    for (const PileContact& pc : p.contacts) {
      samples.push_back(packing_sample(shape, pc));
    }
  }
  packing_statistics(samples, c);
  c.packing_seconds = seconds_since(t1);
}

}  // namespace

// ---- gathering -------------------------------------------------------------------------------

GatherResult gather(const GatherOptions& options)
{
  validate_gather_options(options);
  GatherResult r;
  r.options = options;
  GatherOptions& o = r.options;
  r.model = build_model(o);
  if (o.name.empty()) o.name = r.model.name;
  if (!cpp_identifier(o.name)) throw std::runtime_error("table name '" + o.name + "' is not a C++ identifier (use --name)");
  if (o.with_speed && o.speeds.empty()) o.speeds = default_paper_speeds();
  const ShapeModel& m = r.model;
  const unsigned threads = o.threads;

  // 1. h_coll.
  {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t nr = o.height_ratios.size(), n = static_cast<std::size_t>(o.height_trials);
    Progress progress("h_coll", nr * n, o.progress);
    std::vector<double> h(nr * n);
    const std::size_t chunk = 50;
    const std::size_t tasks = (nr * n + chunk - 1) / chunk;
    parallel_for(
        tasks,
        [&](std::size_t task) {
          const std::size_t end = std::min(nr * n, (task + 1) * chunk);
          for (std::size_t k = task * chunk; k < end; ++k) h[k] = height_trial(m, o.height_ratios[k / n], o.seed, k);
          progress.add(end - task * chunk);
        },
        threads);
    progress.finish();
    for (std::size_t i = 0; i < nr; ++i) {
      const Stats s = stats(n, [&](std::size_t k) { return h[i * n + k]; });
      r.height_mean.push_back(s.mean);
      r.height_std.push_back(s.std);
    }
    r.height_flights = static_cast<long long>(nr * n);
    r.height_seconds = seconds_since(t0);
  }

  ReferencePool pool(m, o.reference);
  {
    Reference probe(m, o.reference);
    r.ground = probe.ground() == Ground::box ? "box" : "plane";
  }

  // 2. Responses.
  {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<double> fixed_speed{o.speed};
    const std::vector<double>& speeds = o.with_speed ? o.speeds : fixed_speed;
    r.axes = {o.cos_theta, o.cos_phi};
    if (o.with_speed) r.axes.push_back(o.speeds);
    r.axes.push_back(o.spin_ratios);
    const std::size_t nt = o.cos_theta.size(), np = o.cos_phi.size(), nv = speeds.size(), ns = o.spin_ratios.size();
    const std::size_t cells = nt * np * nv * ns, trials = static_cast<std::size_t>(o.trials);
    std::vector<ResponseTrial> all(cells * trials);
    Progress progress("responses", cells * trials, o.progress);
    parallel_for(
        cells,
        [&](std::size_t cell) {
          const std::size_t is = cell % ns, iv = (cell / ns) % nv, ip = (cell / (ns * nv)) % np,
                            it = cell / (ns * nv * np);
          pool.with([&](const Reference& ref) {
            for (std::size_t t = 0; t < trials; ++t)
              all[cell * trials + t] = response_trial(ref, o, o.cos_theta[it], o.cos_phi[ip], speeds[iv],
                                                      o.spin_ratios[is], kResponseStream, cell * trials + t);
            return 0;
          });
          progress.add(trials);
        },
        threads);
    progress.finish();
    r.response_mean.assign(cells * 6, 0.0);
    r.response_std.assign(cells * 6, 0.0);
    for (std::size_t cell = 0; cell < cells; ++cell) {
      const std::size_t is = cell % ns, iv = (cell / ns) % nv, it = cell / (ns * nv * np);
      // At zero spin phi means nothing: pool the trials of every phi.
      std::vector<const ResponseTrial*> pooled;
      if (o.spin_ratios[is] == 0.0) {
        for (std::size_t jp = 0; jp < np; ++jp) {
          const std::size_t c2 = ((it * np + jp) * nv + iv) * ns + is;
          for (std::size_t t = 0; t < trials; ++t) pooled.push_back(&all[c2 * trials + t]);
        }
      } else {
        for (std::size_t t = 0; t < trials; ++t) pooled.push_back(&all[cell * trials + t]);
      }
      std::vector<Response>& outcomes = r.cell_outcomes.emplace_back();
      for (const ResponseTrial* t : pooled) outcomes.push_back(t->value);
      for (int c = 0; c < 6; ++c) {
        const Stats s = stats(pooled.size(), [&](std::size_t k) { return pooled[k]->value[c]; });
        r.response_mean[cell * 6 + c] = s.mean;
        r.response_std[cell * 6 + c] = s.std;
      }
    }
    for (const ResponseTrial& t : all) {
      r.time_limited += t.time_limited ? 1 : 0;
      r.max_penetration = std::max(r.max_penetration, t.max_penetration);
    }
    r.response_trials = static_cast<long long>(all.size());
    r.response_seconds = seconds_since(t0);
  }

  // 3. Rest poses.
  {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t n = static_cast<std::size_t>(o.rest_drops);
    std::vector<DropTrial> drops(n);
    Progress progress("rest drops", n, o.progress);
    parallel_for(
        n,
        [&](std::size_t i) {
          drops[i] = pool.with([&](const Reference& ref) { return drop_trial(ref, o, i); });
          progress.add(1);
        },
        threads);
    progress.finish();
    std::vector<Eigen::Vector3d> ups;
    std::vector<double> heights;
    for (const DropTrial& d : drops) {
      if (!d.settled) {
        ++r.unsettled;
        continue;
      }
      ++r.settled;
      r.mean_settle_time += d.time;
      ups.push_back(d.up);
      heights.push_back(d.height);
    }
    if (r.settled > 0) r.mean_settle_time /= r.settled;
    const std::vector<int> label = cluster_directions(ups, o.rest_tolerance_deg * kPi / 180.0);
    int clusters = 0;
    for (int l : label) clusters = std::max(clusters, l + 1);
    // Each cluster's members, merged when two clusters snap to the same hull face (the same pose).
    struct Group {
      std::vector<std::size_t> members;
      Eigen::Vector3d normal;
      int face = -1;  // index into m.hull_planes when snapped
    };
    std::vector<Group> groups;
    const double cos_snap = std::cos(kSnapDegrees * kPi / 180.0);
    for (int c = 0; c < clusters; ++c) {
      Group g;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (std::size_t i = 0; i < label.size(); ++i)
        if (label[i] == c) {
          g.members.push_back(i);
          sum += ups[i];
        }
      if (g.members.empty()) continue;
      g.normal = sum.normalized();
      // A body at rest stands on a face of its convex hull: the face whose inward normal is nearest.
      double best = -2.0;
      for (std::size_t f = 0; f < m.hull_planes.size(); ++f) {
        const double along = -m.hull_planes[f].head<3>().dot(g.normal);
        if (along > best) {
          best = along;
          g.face = static_cast<int>(f);
        }
      }
      if (!(best >= cos_snap)) g.face = -1;
      auto same = std::find_if(groups.begin(), groups.end(), [&](const Group& h) { return g.face >= 0 && h.face == g.face; });
      if (same != groups.end()) same->members.insert(same->members.end(), g.members.begin(), g.members.end());
      else groups.push_back(g);
    }
    std::vector<RestPose> poses;
    std::vector<int> pose_face;
    for (const Group& g : groups) {
      RestPose p;
      p.normal = g.normal;
      const Stats s = stats(g.members.size(), [&](std::size_t k) { return heights[g.members[k]]; });
      p.height = s.mean;
      if (g.face >= 0) {
        const Eigen::Vector4d& plane = m.hull_planes[static_cast<std::size_t>(g.face)];
        p.normal = -plane.head<3>() + Eigen::Vector3d::Zero();  // + 0: no negative zeros
        p.snapped = true;
        // Standing on that face, the centre is exactly the face's offset above the ground.
        p.height = plane.w();
      }
      p.measured_height = s.mean;
      p.height_std = s.std;
      p.count = static_cast<int>(g.members.size());
      p.frequency = static_cast<double>(p.count) / static_cast<double>(std::max(1, r.settled));
      poses.push_back(p);
      pose_face.push_back(g.face);
    }
    std::vector<std::size_t> order(poses.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
      const RestPose& a = poses[i];
      const RestPose& b = poses[j];
      if (a.count != b.count) return a.count > b.count;
      for (int k = 0; k < 3; ++k)
        if (a.normal[k] != b.normal[k]) return a.normal[k] < b.normal[k];
      return false;
    });
    std::vector<RestCandidate> candidates;
    for (std::size_t i : order) {
      RestCandidate c;
      c.frequency = poses[i].frequency;
      c.count = poses[i].count;
      if (pose_face[i] >= 0) c.descriptor = face_descriptor(m, m.hull_planes[static_cast<std::size_t>(pose_face[i])]);
      candidates.push_back(c);
    }
    RestSelectionOptions so;
    so.min_frequency = o.rest_min_frequency;
    so.max_dropped = o.rest_max_dropped;
    const RestSelection sel = select_rest_poses(candidates, so);
    for (std::size_t k = 0; k < order.size(); ++k) {
      RestPose p = poses[order[k]];
      p.family = sel.family[k];
      p.family_frequency = sel.family_frequency[static_cast<std::size_t>(p.family)];
      (sel.kept[k] ? r.rest : r.rest_rare).push_back(p);
    }
    r.rest_dropped = sel.dropped;
    r.rest_families = static_cast<int>(sel.family_frequency.size());
    r.rest_seconds = seconds_since(t0);
  }

  // 4. Body-body data.
  if (o.body_contacts) gather_body_contacts(r);
  return r;
}

// ---- response models ---------------------------------------------------------------------------

const char* response_model_name(ResponseModel model)
{
  switch (model) {
    case ResponseModel::independent_gaussian: return "paper";
    case ResponseModel::correlated_gaussian: return "correlated";
    case ResponseModel::empirical: return "empirical";
  }
  return "unknown";
}

ResponseModel parse_response_model(const std::string& name)
{
  for (ResponseModel m :
       {ResponseModel::independent_gaussian, ResponseModel::correlated_gaussian, ResponseModel::empirical})
    if (name == response_model_name(m)) return m;
  throw std::runtime_error("unknown response model '" + name + "' (paper, correlated or empirical)");
}

std::vector<double> cholesky_lower(const std::vector<double>& a, int n)
{
  std::vector<double> l(static_cast<std::size_t>(n * n), 0.0);
  double largest = 0.0;
  for (int i = 0; i < n; ++i) largest = std::max(largest, a[static_cast<std::size_t>(i * n + i)]);
  const double tiny = 1e-12 * largest;
  // Column by column: l_jj = sqrt(a_jj - sum_k l_jk^2), l_ij = (a_ij - sum_k l_ik l_jk) / l_jj.
  for (int j = 0; j < n; ++j) {
    double d = a[static_cast<std::size_t>(j * n + j)];
    for (int k = 0; k < j; ++k) d -= l[static_cast<std::size_t>(j * n + k)] * l[static_cast<std::size_t>(j * n + k)];
    if (!(d > tiny)) continue;  // no variance left in this direction: a zero column
    const double ljj = std::sqrt(d);
    l[static_cast<std::size_t>(j * n + j)] = ljj;
    for (int i = j + 1; i < n; ++i) {
      double x = a[static_cast<std::size_t>(i * n + j)];
      for (int k = 0; k < j; ++k) x -= l[static_cast<std::size_t>(i * n + k)] * l[static_cast<std::size_t>(j * n + k)];
      l[static_cast<std::size_t>(i * n + j)] = x / ljj;
    }
  }
  std::vector<double> packed;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j) packed.push_back(l[static_cast<std::size_t>(i * n + j)]);
  return packed;
}

std::vector<double> response_spread(const GatherResult& r)
{
  const GatherOptions& o = r.options;
  if (o.response_model == ResponseModel::independent_gaussian) return r.response_std;
  const std::size_t cells = r.response_mean.size() / 6;
  if (r.cell_outcomes.size() != cells)
    throw std::runtime_error(std::string("the ") + response_model_name(o.response_model) +
                             " response model needs every cell's trial outcomes");
  std::vector<double> out;
  for (std::size_t cell = 0; cell < cells; ++cell) {
    const std::vector<Response>& t = r.cell_outcomes[cell];
    if (o.response_model == ResponseModel::correlated_gaussian) {
      std::vector<double> cov(36, 0.0);
      const double* mean = &r.response_mean[cell * 6];
      for (const Response& x : t)
        for (int i = 0; i < 6; ++i)
          for (int j = 0; j < 6; ++j) cov[static_cast<std::size_t>(i * 6 + j)] += (x[i] - mean[i]) * (x[j] - mean[j]);
      const double n1 = t.size() > 1 ? static_cast<double>(t.size() - 1) : 1.0;
      for (double& c : cov) c /= n1;
      const std::vector<double> l = cholesky_lower(cov, 6);
      out.insert(out.end(), l.begin(), l.end());
    } else {
      const std::size_t k = static_cast<std::size_t>(o.empirical_outcomes);
      if (t.size() < k) throw std::runtime_error("a cell has fewer outcomes than --empirical-outcomes");
      // Ranks by the normal velocity offset (component 5), ties by trial order: a stable sort.
      std::vector<std::size_t> order(t.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::stable_sort(order.begin(), order.end(), [&t](std::size_t a, std::size_t b) { return t[a][5] < t[b][5]; });
      std::vector<Response> kept;
      for (std::size_t i = 0; i < k; ++i) kept.push_back(t[order[(2 * i + 1) * t.size() / (2 * k)]]);
      Response centre{};
      for (const Response& x : kept)
        for (int c = 0; c < 6; ++c) centre[c] += x[c] / static_cast<double>(k);
      for (const Response& x : kept)
        for (int c = 0; c < 6; ++c) out.push_back(x[c] - centre[c]);
    }
  }
  return out;
}

// ---- output ----------------------------------------------------------------------------------

Quantized quantize(const std::vector<float>& values)
{
  Quantized out;
  out.q.resize(values.size());
  statsim::quantize16(values.data(), values.size(), out.scale, out.offset, out.q.data());
  for (std::size_t i = 0; i < values.size(); ++i) {
    // As the runtime dequantises: offset + scale * Scalar(q), in float.
    const float back = out.offset + out.scale * static_cast<float>(out.q[i]);
    out.worst_error = std::max(out.worst_error, std::fabs(static_cast<double>(back) - static_cast<double>(values[i])));
  }
  return out;
}

namespace {

std::vector<float> to_float(const std::vector<double>& v)
{
  std::vector<float> f;
  f.reserve(v.size());
  for (double x : v) f.push_back(static_cast<float>(x) + 0.0f);
  return f;
}

std::string hex64(std::uint64_t x)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(x));
  return buf;
}

std::string vec3(const Eigen::Vector3d& v, const char* f = "%.6g")
{
  return "(" + fmt(f, v.x()) + ", " + fmt(f, v.y()) + ", " + fmt(f, v.z()) + ")";
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
              (o.with_speed ? "" : ", impacts at |V-| = " + num(o.speed) + " m/s") + "; precision " +
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
    << r.response_trials << " impacts (" << r.time_limited << " hit the time limit), " << o.rest_drops
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
  h << table_prologue(o.name, contact ? 1 : 0, o.target);
  const std::size_t a0 = r.axes[0].size(), a1 = r.axes[1].size(), a2 = r.axes[2].size(),
                    a3 = r.axes.size() > 3 ? r.axes[3].size() : 1;
  h << table_definition(std::string(o.i16 ? "SignatureQ16" : "Signature") + "<3, " +
                            std::to_string(r.height_mean.size()) + ", " + std::to_string(a0) + ", " +
                            std::to_string(a1) + ", " + std::to_string(a2) + ", " + std::to_string(a3) + ", " +
                            std::to_string(r.rest.size()) + ", " + std::to_string(spread_size) +
                            (contact ? ", " + contact_type(c, o.i16) : std::string()) +
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
  h << table_comment("response mean per cell: w_x, w_y, w_z (W+ L/|V-|), dv_x, dv_y, dv_z ((V+ - V_particle+)/|V-|)");
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
  if (o.i16) {
    const Quantized qm = quantize(to_float(r.response_mean)), qs = quantize(to_float(spread));
    resp["i16"] = {{"mean_scale", static_cast<double>(qm.scale)},
                   {"mean_offset", static_cast<double>(qm.offset)},
                   {"spread_scale", static_cast<double>(qs.scale)},
                   {"spread_offset", static_cast<double>(qs.offset)},
                   {"worst_error", std::max(qm.worst_error, qs.worst_error)}};
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
  s << "responses: " << r.response_trials << " impacts, " << r.time_limited << " time-limited, deepest penetration "
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
  if (r.options.i16) {
    const Quantized qm = quantize(to_float(r.response_mean)), qs = quantize(to_float(r.response_std));
    s << "i16: worst dequantization error " << fmt("%.3g", std::max(qm.worst_error, qs.worst_error)) << "\n";
  }
  return s.str();
}

// ---- checks ----------------------------------------------------------------------------------

namespace {

struct CheckCell {
  double cos_theta, cos_phi, spin_ratio;
};

}  // namespace

std::string speed_check_report(const GatherOptions& options, const std::vector<double>& speeds, int trials)
{
  GatherOptions o = options;
  validate_gather_options(o);
  const ShapeModel m = build_model(o);
  ReferencePool pool(m, o.reference);
  const std::vector<CheckCell> cells = {{1.0, 0.0, 0.0}, {1.0, 0.0, 0.5}, {0.7, 0.0, 0.0},  {0.7, 0.5, 1.0},
                                        {0.4, 0.0, 0.3}, {0.4, -0.5, 2.0}, {0.1, 0.0, 0.0}, {0.1, 0.5, 1.0}};
  const std::size_t nc = cells.size(), nv = speeds.size(), n = static_cast<std::size_t>(trials);
  std::vector<ResponseTrial> all(nc * nv * n);
  Progress progress("speed check", nc * nv * n, o.progress);
  parallel_for(
      nc * nv,
      [&](std::size_t task) {
        const std::size_t c = task / nv, v = task % nv;
        pool.with([&](const Reference& ref) {
          // The same orientations at every speed (index independent of the speed): paired samples.
          for (std::size_t t = 0; t < n; ++t)
            all[task * n + t] = response_trial(ref, o, cells[c].cos_theta, cells[c].cos_phi, speeds[v],
                                               cells[c].spin_ratio, kCheckStream, c * n + t);
          return 0;
        });
        progress.add(n);
      },
      o.threads);
  progress.finish();
  std::ostringstream s;
  s << "Speed invariance of the reference (" << m.name << ", " << trials
    << " impacts per cell and speed, the same orientations at every speed): normalised means\n";
  s << "(W+ L/|V-| and (V+ - V_particle+)/|V-|; restitution " << num(o.reference.restitution) << ", friction "
    << num(o.reference.friction) << ", threshold " << num(o.reference.restitution_threshold) << " m/s, dt "
    << num(o.reference.dt) << " s). Last column: the largest standard error of the means in the row.\n\n";
  s << "| cos theta | cos phi | s | quantity |";
  for (double v : speeds) s << " " << num(v) << " m/s |";
  s << " s.e. |\n|---|---|---|---|";
  for (std::size_t v = 0; v < nv; ++v) s << "---|";
  s << "---|\n";
  const char* names[] = {"w_x", "w_y", "w_z", "dv_x", "dv_y", "dv_z"};
  int time_limited = 0;
  for (const ResponseTrial& t : all) time_limited += t.time_limited ? 1 : 0;
  for (std::size_t c = 0; c < nc; ++c) {
    for (int comp : {1, 3, 5, 6}) {
      s << "| " << num(cells[c].cos_theta) << " | " << num(cells[c].cos_phi) << " | " << num(cells[c].spin_ratio) << " | "
        << (comp == 6 ? "|W+| L/|V-|" : names[comp]) << " |";
      double se = 0.0;
      for (std::size_t v = 0; v < nv; ++v) {
        const ResponseTrial* base = &all[(c * nv + v) * n];
        const Stats st = stats(n, [&](std::size_t k) {
          const Response& x = base[k].value;
          return comp == 6 ? std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) : x[comp];
        });
        se = std::max(se, st.std / std::sqrt(static_cast<double>(n)));
        s << " " << fmt("%+.3f", st.mean) << " |";
      }
      s << " " << fmt("%.3f", se) << " |\n";
    }
  }
  s << "\n" << time_limited << " of " << all.size() << " impacts hit the time limit.\n";
  return s.str();
}

namespace {
// A time step for humans: "1/60" when 1/dt is a whole number, else the decimal.
std::string step_name(double dt)
{
  const double inv = 1.0 / dt;
  if (std::fabs(inv - std::nearbyint(inv)) < 1e-9 * inv) return "1/" + num(std::nearbyint(inv));
  return num(dt);
}
}  // namespace

std::string step_check_report(const GatherOptions& options)
{
  GatherOptions base = options;
  base.cos_theta = {0.25, 0.7, 1.0};
  base.cos_phi = {-1.0, 0.0, 1.0};
  base.spin_ratios = {0.0, 1.0, 4.0, 8.0};
  base.height_ratios = {0.0};
  base.height_trials = 2;
  base.with_speed = false;
  const double dt = options.reference.dt;
  std::vector<double> steps;
  for (double d : {1.0 / 60.0, 1.0 / 240.0})
    if (d > 1.5 * dt) steps.push_back(d);
  steps.push_back(dt);
  steps.push_back(dt / 2);
  std::vector<GatherResult> runs;
  for (double d : steps) {
    GatherOptions o = base;
    o.reference.dt = d;
    runs.push_back(gather(o));
  }
  const GatherResult& fine = runs.back();
  std::ostringstream s;
  s << "Time step (" << fine.model.name << "): a small gathering at each dt, the same random trials: "
    << fine.response_mean.size() / 6 << " response cells (cos theta 0.25, 0.7, 1; cos phi -1, 0, 1; s 0, 1, 4, 8) x "
    << options.trials << " impacts at " << num(options.speed) << " m/s, and " << options.rest_drops
    << " rest drops. Response change: the largest |difference| of a normalised mean from the dt = " << step_name(steps.back())
    << " s run, and that difference over its standard error (unpaired). h_coll does not depend on dt (exact free flight).\n\n";
  s << "| dt (s) | drops settled | mean time to settle (s) | impacts time-limited | largest response change | in standard errors |\n";
  s << "|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const GatherResult& a = runs[k];
    double worst = 0.0, worst_z = 0.0;
    for (std::size_t i = 0; i < a.response_mean.size(); ++i) {
      const double d = std::fabs(a.response_mean[i] - fine.response_mean[i]);
      const double se = std::sqrt((a.response_std[i] * a.response_std[i] + fine.response_std[i] * fine.response_std[i]) /
                                  static_cast<double>(options.trials));
      worst = std::max(worst, d);
      if (se > 0) worst_z = std::max(worst_z, d / se);
    }
    s << "| " << step_name(steps[k]) << " | " << a.settled << " / " << (a.settled + a.unsettled) << " | "
      << fmt("%.2f", a.mean_settle_time) << " | " << a.time_limited << " | "
      << (k + 1 == runs.size() ? std::string("-") : fmt("%.4f", worst)) << " | "
      << (k + 1 == runs.size() ? std::string("-") : fmt("%.2f", worst_z)) << " |\n";
  }
  // Rest poses: those of the finest run, with their frequency at every dt (matched by normal).
  std::vector<RestPose> poses = fine.rest;
  poses.insert(poses.end(), fine.rest_rare.begin(), fine.rest_rare.end());
  s << "\n| rest pose (body-frame up) | h_rest (m) |";
  for (double d : steps) s << " frequency at dt " << step_name(d) << " |";
  s << "\n|---|---|";
  for (std::size_t k = 0; k < steps.size(); ++k) s << "---|";
  s << "\n";
  const double cos_tol = std::cos(options.rest_tolerance_deg * kPi / 180.0);
  for (const RestPose& p : poses) {
    s << "| " << vec3(p.normal, "%.3f") << " | " << fmt("%.4f", p.height) << " |";
    for (const GatherResult& a : runs) {
      double f = 0.0;
      for (const auto* list : {&a.rest, &a.rest_rare})
        for (const RestPose& q : *list)
          if (q.normal.dot(p.normal) >= cos_tol) f += q.frequency;
      s << " " << fmt("%.3f", f) << " |";
    }
    s << "\n";
  }
  return s.str();
}

std::string settings_check_report(const GatherOptions& options)
{
  // A face-down cube (the committed box) at normal incidence: it should leave at e |V-| with no
  // spin. Bullet's defaults vs the reference's settings, one fix at a time.
  const ShapeModel box = load_shape_model("box", "", options.density);
  struct Row {
    std::string name;
    ReferenceSettings s;
    bool start_gap;  // start a random fraction of a step above the ground (as a drop would)
  };
  ReferenceSettings defaults;
  defaults.dt = 1.0 / 60;
  defaults.solver_iterations = 10;
  defaults.warm_starting = true;
  defaults.split_impulse = false;
  defaults.margin = 0.04;
  defaults.ground_auto = false;
  defaults.ground = Ground::plane;
  defaults.multipoint_plane = false;
  defaults.speculative_contacts = true;
  defaults.restitution = options.reference.restitution;
  defaults.friction = options.reference.friction;
  defaults.restitution_threshold = 0.2;
  std::vector<Row> rows;
  rows.push_back({"Bullet defaults (dt 1/60, plane: one new contact point per step, margin 0.04, split impulse only "
                  "below 4 cm of penetration, warm starting, 10 iterations, speculative contacts)",
                  defaults, true});
  ReferenceSettings s1 = defaults;
  s1.split_impulse = true;
  s1.warm_starting = false;
  s1.solver_iterations = options.reference.solver_iterations;
  rows.push_back({"+ split impulse always, no warm starting, " + std::to_string(s1.solver_iterations) + " iterations",
                  s1, true});
  ReferenceSettings s2 = s1;
  s2.multipoint_plane = true;
  rows.push_back({"+ plane manifold of 4 points (setPlaneConvexMultipointIterations)", s2, true});
  ReferenceSettings s3 = s2;
  s3.speculative_contacts = false;
  rows.push_back({"+ no speculative contacts (contact processing threshold 0)", s3, true});
  ReferenceSettings s4 = s3;
  s4.dt = options.reference.dt;
  s4.margin = options.reference.margin;
  rows.push_back({"+ dt " + num(s4.dt) + " s, margin " + num(s4.margin) + " m", s4, true});
  ReferenceSettings s5 = s4;
  s5.ground_auto = true;
  rows.push_back({"+ box ground (btBoxBoxDetector: the whole contact face at once)", s5, true});
  ReferenceSettings s6 = s5;
  s6.restitution_threshold = options.reference.restitution_threshold;
  rows.push_back({"+ restitution threshold " + num(s6.restitution_threshold) + " m/s (Bullet: 0.2)", s6, true});
  rows.push_back({"reference settings, each impact starting at its exact first contact", options.reference, false});
  const std::vector<double> speeds = {0.25, 0.5, 1, 2, 4, 8};
  const std::vector<double> random_speeds = {0.5, 2, 8};
  std::ostringstream s;
  s << "Face-down cube (" << box.source << "), normal incidence, no gravity: rebound V+_z / |V-| and spin |W+| L / |V-|"
    << " (restitution " << num(options.reference.restitution) << "); the last columns: the mean V+_z/|V-| over 200"
    << " random orientations (the same at every speed) at normal incidence.\n\n| settings |";
  for (double v : speeds) s << " " << num(v) << " m/s |";
  for (double v : random_speeds) s << " random, " << num(v) << " m/s |";
  s << "\n|---|";
  for (std::size_t i = 0; i < speeds.size() + random_speeds.size(); ++i) s << "---|";
  s << "\n";
  for (const Row& row : rows) {
    Reference ref(box, row.s);
    s << "| " << row.name << " |";
    for (double u : speeds) {
      RigidState st;
      st.velocity = Eigen::Vector3d(0, 0, -u);
      const double gap = row.start_gap ? 0.5 * u * row.s.dt : -1e-7;
      st.position = Eigen::Vector3d(0, 0, 0.1 + gap);
      const ImpactResult ir = ref.impact(st, 2.0);
      s << " " << fmt("%.3f", ir.after.velocity.z() / u) << " / " << fmt("%.3f", ir.after.spin.norm() * box.bounding_radius / u)
        << " |";
    }
    for (double u : random_speeds) {
      double mean = 0.0;
      const int n = 200;
      for (int k = 0; k < n; ++k) {
        TrialRng rng(options.seed, kCheckStream + 1, static_cast<std::uint64_t>(k));
        RigidState st;
        st.orientation = rng.rotation();
        st.velocity = Eigen::Vector3d(0, 0, -u);
        const double gap = row.start_gap ? u * row.s.dt * rng.uniform() : -1e-7;
        st.position = Eigen::Vector3d(0, 0, -lowest_point(box.hull, st) + gap);
        mean += ref.impact(st, 2.0).after.velocity.z() / u;
      }
      s << " " << fmt("%.3f", mean / n) << " |";
    }
    s << "\n";
  }
  return s.str();
}

}  // namespace statsim::tools::ref3d
