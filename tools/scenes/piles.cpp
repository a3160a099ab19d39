#include "scenes/piles.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace statsim::tools::scenes {

namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void bad(const char* scene, const char* what)
{
  throw std::invalid_argument(std::string(scene) + " scene: " + what);
}

void check_common(const char* scene, int count, double radius, double spacing, double max_speed, double max_spin)
{
  if (count < 1) bad(scene, "count must be >= 1");
  if (!(radius > 0) || !std::isfinite(radius)) bad(scene, "bounding radius must be positive");
  if (!(spacing >= 1) || !std::isfinite(spacing)) bad(scene, "spacing must be >= 1");
  if (!(max_speed >= 0) || !std::isfinite(max_speed)) bad(scene, "max speed must be >= 0");
  if (!(max_spin >= 0) || !std::isfinite(max_spin)) bad(scene, "max spin must be >= 0");
}

// A body in the cell centred on `centre`: jittered within the cell, random orientation, small
// random velocities.
BodyState3 random_body(SceneRng& rng, const Eigen::Vector3d& centre, double jitter, double max_speed, double max_spin)
{
  BodyState3 b;
  b.position = centre + Eigen::Vector3d(rng.uniform(-jitter, jitter), rng.uniform(-jitter, jitter),
                                        rng.uniform(-jitter, jitter));
  b.orientation = random_orientation(rng);
  for (int a = 0; a < 3; ++a) b.linear_velocity[a] = rng.uniform(-max_speed, max_speed);
  for (int a = 0; a < 3; ++a) b.angular_velocity[a] = rng.uniform(-max_spin, max_spin);
  return b;
}

// The first `take` of `n` indices in a random order (Fisher-Yates), sorted.
std::vector<int> shuffled(int n, int take, SceneRng& rng)
{
  std::vector<int> idx(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) idx[static_cast<std::size_t>(i)] = i;
  for (std::size_t i = idx.size(); i > 1; --i) std::swap(idx[i - 1], idx[rng.below(i)]);
  idx.resize(static_cast<std::size_t>(take));
  std::sort(idx.begin(), idx.end());
  return idx;
}

// Body i of shape i % shapes, when the scene mixes two shapes.
void assign_shapes(const char* scene, int shapes, PileScene3& sc)
{
  if (shapes < 1 || shapes > 2) bad(scene, "shapes must be 1 or 2");
  if (shapes == 1) return;
  for (std::size_t i = 0; i < sc.bodies.size(); ++i) sc.shapes.push_back(static_cast<int>(i % 2));
}

}  // namespace

DropScene3 PileScene3::as_drop_scene() const
{
  DropScene3 d;
  d.options.count = static_cast<int>(bodies.size());
  d.cell = cell;
  d.bodies = bodies;
  d.bounds_lo = bounds_lo;
  d.bounds_hi = bounds_hi;
  return d;
}

PileScene3 heap_scene(const HeapOptions& o)
{
  check_common("heap", o.count, o.bounding_radius, o.spacing, o.max_speed, o.max_spin);
  if (o.spots < 1 || o.spots > 4) bad("heap", "spots must be 1 to 4");
  if (!(o.interval > 0) || !std::isfinite(o.interval)) bad("heap", "interval must be positive");
  if (!(o.pour_speed >= 0) || !std::isfinite(o.pour_speed)) bad("heap", "pour speed must be >= 0");
  PileScene3 sc;
  sc.kind = "heap";
  const double r = o.bounding_radius;
  const double s = 2 * r * o.spacing;
  const double jitter = s / 2 - r;
  sc.cell = s;
  sc.planes.push_back({Eigen::Vector3d::UnitZ(), 0.0});
  // Release points about the axis, s apart from one another: a point, a segment, an
  // equilateral triangle (circumradius s / sqrt 3) or a square.
  std::vector<Eigen::Vector2d> spot;
  switch (o.spots) {
    case 1: spot = {{0, 0}}; break;
    case 2: spot = {{-s / 2, 0}, {s / 2, 0}}; break;
    case 3: {
      const double c = s / std::sqrt(3.0);
      spot = {{c, 0}, {-c / 2, s / 2}, {-c / 2, -s / 2}};
      break;
    }
    default: spot = {{-s / 2, -s / 2}, {s / 2, s / 2}, {s / 2, -s / 2}, {-s / 2, s / 2}}; break;
  }
  const double n = static_cast<double>(o.count);
  sc.nozzle_height = (1.5 + 0.75 * std::cbrt(n)) * s;
  sc.pour_speed = o.pour_speed;
  // The waiting lattice: side g cells, g^2 >= N, layers from 10 s above the nozzle.
  int g = 1;
  while (g * g < o.count) ++g;
  const double park = sc.nozzle_height + 10 * s;
  SceneRng rng(o.seed);
  sc.bodies.reserve(static_cast<std::size_t>(o.count));
  sc.release.reserve(static_cast<std::size_t>(o.count));
  for (int k = 0; k < o.count; ++k) {
    BodyState3 wait;
    wait.position = Eigen::Vector3d((k % g - 0.5 * (g - 1)) * s, (k / g - 0.5 * (g - 1)) * s, park);
    wait.asleep = true;
    const Eigen::Vector2d p = spot[static_cast<std::size_t>(k % o.spots)];
    BodyState3 b = random_body(rng, Eigen::Vector3d(p.x(), p.y(), sc.nozzle_height), jitter, o.max_speed, o.max_spin);
    b.linear_velocity.z() -= o.pour_speed;
    wait.orientation = b.orientation;
    sc.bodies.push_back(wait);
    sc.release.push_back(b);
    sc.release_time.push_back(k * o.interval);
  }
  const double reach = 1 + 3 * s * std::cbrt(n);
  const double half = 0.5 * g * s + 1;
  sc.bounds_lo = Eigen::Vector3d(-std::max(reach, half), -std::max(reach, half), -1);
  sc.bounds_hi = Eigen::Vector3d(std::max(reach, half), std::max(reach, half), park + 1);
  assign_shapes("heap", o.shapes, sc);
  return sc;
}

PileScene3 bin_scene(const BinOptions& o)
{
  check_common("bin", o.count, o.bounding_radius, o.spacing, o.max_speed, o.max_spin);
  if (o.cells < 1) bad("bin", "cells must be >= 1");
  PileScene3 sc;
  sc.kind = "bin";
  const double r = o.bounding_radius;
  const double s = 2 * r * o.spacing;
  const double jitter = s / 2 - r;
  const double w = o.cells * s / 2;
  sc.cell = s;
  sc.bin_half_width = w;
  sc.planes.push_back({Eigen::Vector3d::UnitZ(), 0.0});
  sc.planes.push_back({Eigen::Vector3d::UnitX(), -w});
  sc.planes.push_back({-Eigen::Vector3d::UnitX(), -w});
  sc.planes.push_back({Eigen::Vector3d::UnitY(), -w});
  sc.planes.push_back({-Eigen::Vector3d::UnitY(), -w});
  SceneRng rng(o.seed);
  const int per_layer = o.cells * o.cells;
  const int full_layers = o.count / per_layer;
  const int rest = o.count - full_layers * per_layer;
  sc.bodies.reserve(static_cast<std::size_t>(o.count));
  for (int k = 0; k <= full_layers; ++k) {
    const int in_layer = k < full_layers ? per_layer : rest;
    if (in_layer == 0) break;
    for (int c : shuffled(per_layer, in_layer, rng)) {
      const double x = (c % o.cells + 0.5) * s - w, y = (c / o.cells + 0.5) * s - w;
      sc.bodies.push_back(random_body(rng, Eigen::Vector3d(x, y, (k + 1.5) * s), jitter, o.max_speed, o.max_spin));
    }
  }
  const double top = (full_layers + 2) * s;
  sc.bounds_lo = Eigen::Vector3d(-w - 1, -w - 1, -1);
  sc.bounds_hi = Eigen::Vector3d(w + 1, w + 1, top + 1);
  assign_shapes("bin", o.shapes, sc);
  return sc;
}

PileScene3 stack_scene(const StackOptions& o)
{
  if (o.height < 1) bad("stack", "height must be >= 1");
  if (o.columns < 1) bad("stack", "columns must be >= 1");
  for (int a = 0; a < 3; ++a)
    if (!(o.lo[a] < 0 && o.hi[a] > 0) || !std::isfinite(o.lo[a]) || !std::isfinite(o.hi[a]))
      bad("stack", "the body's box must hold its centre of mass (lo < 0 < hi)");
  if (!(std::fabs(o.orientation.norm() - 1) < 1e-9)) bad("stack", "orientation must be a unit quaternion");
  PileScene3 sc;
  sc.kind = o.columns == 1 ? "column" : "wall";
  sc.columns = o.columns;
  sc.height = o.height;
  sc.pitch = o.hi.z() - o.lo.z();
  sc.width = o.hi.x() - o.lo.x();
  sc.planes.push_back({Eigen::Vector3d::UnitZ(), 0.0});
  // Column j's boxes span x from x0 + j width to x0 + (j + 1) width, the wall centred on x = 0;
  // body k's box spans z from k pitch to (k + 1) pitch.
  const double x0 = -0.5 * o.columns * sc.width;
  const double y = -0.5 * (o.lo.y() + o.hi.y());
  sc.bodies.reserve(static_cast<std::size_t>(o.columns * o.height));
  for (int j = 0; j < o.columns; ++j)
    for (int k = 0; k < o.height; ++k) {
      BodyState3 b;
      b.position = Eigen::Vector3d(x0 + j * sc.width - o.lo.x(), y, k * sc.pitch - o.lo.z());
      b.orientation = o.orientation;
      sc.bodies.push_back(b);
    }
  const double reach = 1 + o.height * sc.pitch + o.columns * sc.width;
  sc.bounds_lo = Eigen::Vector3d(-reach, -reach, -1);
  sc.bounds_hi = Eigen::Vector3d(reach, reach, o.height * sc.pitch + 1);
  return sc;
}

void rotated_extent(const std::vector<Eigen::Vector3d>& points, const Eigen::Quaterniond& q, Eigen::Vector3d& lo,
                    Eigen::Vector3d& hi)
{
  lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  const Eigen::Matrix3d m = q.normalized().toRotationMatrix();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d w = m * p;
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
}

HeapProfile heap_profile(const std::vector<Eigen::Vector3d>& centres, double bin, double toe, int sectors)
{
  HeapProfile out;
  if (centres.empty() || !(bin > 0) || sectors < 1) return out;
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();
  double low = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& c : centres) {
    axis += c.head<2>();
    low = std::min(low, c.z());
    out.height = std::max(out.height, c.z());
  }
  axis /= static_cast<double>(centres.size());
  // top[sector][bin]: the highest centre of the cell as (r, z); r < 0 marks an empty cell.
  const std::array<double, 2> empty{-1.0, -std::numeric_limits<double>::infinity()};
  std::vector<std::vector<std::array<double, 2>>> top(static_cast<std::size_t>(sectors));
  for (const Eigen::Vector3d& c : centres) {
    const Eigen::Vector2d d = c.head<2>() - axis;
    const double r = d.norm();
    const double turn = std::atan2(d.y(), d.x()) / (2 * kPi) + 0.5;  // in [0, 1]
    const std::size_t s = std::min(static_cast<std::size_t>(turn * sectors), static_cast<std::size_t>(sectors - 1));
    const std::size_t k = static_cast<std::size_t>(std::floor(r / bin));
    std::vector<std::array<double, 2>>& t = top[s];
    if (t.size() <= k) t.resize(k + 1, empty);
    if (c.z() > t[k][1]) t[k] = {r, c.z()};
  }
  double n = 0, sr = 0, sz = 0, srr = 0, srz = 0;
  for (const std::vector<std::array<double, 2>>& t : top) {
    std::size_t peak = 0;
    for (std::size_t k = 1; k < t.size(); ++k)
      if (t[k][1] > t[peak][1]) peak = k;
    for (std::size_t k = peak; k < t.size(); ++k) {
      if (t[k][0] < 0 || t[k][1] < low + toe) break;
      n += 1, sr += t[k][0], sz += t[k][1], srr += t[k][0] * t[k][0], srz += t[k][0] * t[k][1];
    }
  }
  out.flank_bins = static_cast<int>(n);
  const double denom = n * srr - sr * sr;
  if (n < 2 || !(denom > 0)) return out;
  const double slope = (n * srz - sr * sz) / denom;
  out.angle_deg = std::atan(-slope) * 180.0 / kPi;
  return out;
}

BinFill bin_fill(const std::vector<double>& heights, double body_volume, double floor_area)
{
  BinFill out;
  if (heights.empty()) return out;
  double sum = 0;
  for (double z : heights) sum += z;
  out.fill_height = 2 * sum / static_cast<double>(heights.size());
  if (out.fill_height > 0 && floor_area > 0)
    out.packing = static_cast<double>(heights.size()) * body_volume / (floor_area * out.fill_height);
  return out;
}

double box_penetration(const SceneBox& a, const SceneBox& b)
{
  const Eigen::Vector3d d = b.centre - a.centre;
  auto overlap_along = [&](Eigen::Vector3d axis) {
    const double len = axis.norm();
    // Parallel edges give no axis of their own (a face axis covers them).
    if (len < 1e-9) return std::numeric_limits<double>::infinity();
    axis /= len;
    double ra = 0, rb = 0;
    for (int i = 0; i < 3; ++i) {
      ra += a.half_extents[i] * std::fabs(a.rotation.col(i).dot(axis));
      rb += b.half_extents[i] * std::fabs(b.rotation.col(i).dot(axis));
    }
    return ra + rb - std::fabs(d.dot(axis));
  };
  double depth = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    depth = std::min(depth, overlap_along(a.rotation.col(i)));
    depth = std::min(depth, overlap_along(b.rotation.col(i)));
    for (int j = 0; j < 3; ++j) depth = std::min(depth, overlap_along(a.rotation.col(i).cross(b.rotation.col(j))));
  }
  return depth > 0 ? depth : 0.0;
}

double deepest_overlap(const std::vector<SceneBox>& boxes, const std::vector<Eigen::Vector3d>& centres,
                       const std::vector<Eigen::Quaterniond>& orientations)
{
  const std::size_t n = std::min(centres.size(), orientations.size());
  std::vector<SceneBox> world;  // body i's boxes at [i nb, (i + 1) nb)
  const std::size_t nb = boxes.size();
  world.reserve(n * nb);
  double deepest = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Matrix3d m = orientations[i].normalized().toRotationMatrix();
    for (const SceneBox& b : boxes) {
      SceneBox w{centres[i] + m * b.centre, m * b.rotation, b.half_extents};
      // Lowest corner: the centre's height less the half extents along each axis's z.
      double low = w.centre.z();
      for (int a = 0; a < 3; ++a) low -= w.half_extents[a] * std::fabs(w.rotation(2, a));
      deepest = std::max(deepest, -low);
      world.push_back(w);
    }
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      for (std::size_t p = 0; p < nb; ++p)
        for (std::size_t q = 0; q < nb; ++q)
          deepest = std::max(deepest, box_penetration(world[i * nb + p], world[j * nb + q]));
  return deepest;
}

StackHold stack_hold(const PileScene3& sc, const std::vector<SceneBox>& boxes,
                     const std::vector<Eigen::Vector3d>& centres, const std::vector<Eigen::Quaterniond>& orientations)
{
  StackHold out;
  if (centres.empty() || centres.size() != sc.bodies.size()) return out;
  double top = -std::numeric_limits<double>::infinity(), placed = top;
  for (const Eigen::Vector3d& c : centres) top = std::max(top, c.z());
  for (const BodyState3& b : sc.bodies) placed = std::max(placed, b.position.z());
  out.held = top / placed;
  out.overlap = deepest_overlap(boxes, centres, orientations);
  return out;
}

}  // namespace statsim::tools::scenes
