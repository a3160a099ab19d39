#include "scenes/scenes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <unordered_map>

namespace statsim::tools::scenes {

std::uint64_t SceneRng::next()
{
  std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

double SceneRng::uniform()
{
  return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0);
}

std::uint64_t SceneRng::below(std::uint64_t n)
{
  // Rejects the lowest 2^64 mod n values so that x mod n is unbiased.
  const std::uint64_t threshold = (0 - n) % n;
  for (;;) {
    const std::uint64_t x = next();
    if (x >= threshold) return x % n;
  }
}

void validate(const DropOptions& o)
{
  auto bad = [](const char* what) { throw std::invalid_argument(std::string("drop scene: ") + what); };
  if (o.count < 1) bad("count must be >= 1");
  if (!(o.bounding_radius > 0) || !std::isfinite(o.bounding_radius)) bad("bounding radius must be positive");
  if (!(o.spacing >= 1) || !std::isfinite(o.spacing)) bad("spacing must be >= 1");
  if (!(o.fill > 0 && o.fill <= 1)) bad("fill must be in (0, 1]");
  if (!(o.aspect > 0) || !std::isfinite(o.aspect)) bad("aspect must be positive");
  if (!(o.max_speed >= 0) || !std::isfinite(o.max_speed)) bad("max speed must be >= 0");
  if (!(o.max_spin >= 0) || !std::isfinite(o.max_spin)) bad("max spin must be >= 0");
}

Eigen::Quaterniond random_orientation(SceneRng& rng)
{
  for (;;) {
    const double w = rng.uniform(-1, 1), x = rng.uniform(-1, 1), y = rng.uniform(-1, 1), z = rng.uniform(-1, 1);
    const double n2 = w * w + x * x + y * y + z * z;
    if (n2 > 1e-4 && n2 <= 1) {
      const double n = std::sqrt(n2);
      return Eigen::Quaterniond(w / n, x / n, y / n, z / n);
    }
  }
}

namespace {

constexpr double kPi = 3.14159265358979323846;

// Fisher-Yates shuffle, then the first `count` indices.
template <class Cell>
std::vector<Cell> choose(std::vector<Cell> cells, std::size_t count, SceneRng& rng)
{
  for (std::size_t i = cells.size(); i > 1; --i) std::swap(cells[i - 1], cells[rng.below(i)]);
  cells.resize(count);
  return cells;
}

}  // namespace

DropScene3 drop_scene3(const DropOptions& o)
{
  validate(o);
  DropScene3 scene;
  scene.options = o;
  const double r = o.bounding_radius;
  const double s = 2 * r * o.spacing;
  const double jitter = s / 2 - r;
  const double wanted = std::ceil(static_cast<double>(o.count) / o.fill);
  const double rc = std::max(2 * s, s * std::cbrt(wanted / (kPi * o.aspect)));
  double height = o.aspect * rc;
  const double bottom = s;
  scene.cell = s;

  // Cells (i, j, k) whose body, jittered anywhere in its cell, stays inside the cylinder:
  // horizontal centre distance + sqrt(2) jitter + R <= Rc; top of the body <= bottom + H.
  const int span = static_cast<int>(std::floor(rc / s)) + 1;
  std::vector<std::array<int, 3>> cells;
  for (;;) {
    cells.clear();
    const int layers = static_cast<int>(std::floor(height / s));
    for (int k = 0; k < layers; ++k)
      for (int j = -span; j <= span; ++j)
        for (int i = -span; i <= span; ++i) {
          const double x = i * s, y = j * s;
          if (std::sqrt(x * x + y * y) + std::sqrt(2.0) * jitter + r <= rc) cells.push_back({i, j, k});
        }
    if (cells.size() >= static_cast<std::size_t>(o.count)) break;
    height += s;
  }
  scene.region = Cylinder{rc, bottom, height};

  SceneRng rng(o.seed);
  std::vector<std::array<int, 3>> chosen = choose(cells, static_cast<std::size_t>(o.count), rng);
  std::sort(chosen.begin(), chosen.end(), [](const auto& a, const auto& b) {
    if (a[2] != b[2]) return a[2] < b[2];
    if (a[1] != b[1]) return a[1] < b[1];
    return a[0] < b[0];
  });
  scene.bodies.reserve(chosen.size());
  for (const auto& c : chosen) {
    BodyState3 b;
    const Eigen::Vector3d centre(c[0] * s, c[1] * s, bottom + (c[2] + 0.5) * s);
    b.position = centre + Eigen::Vector3d(rng.uniform(-jitter, jitter), rng.uniform(-jitter, jitter),
                                          rng.uniform(-jitter, jitter));
    b.orientation = random_orientation(rng);
    for (int a = 0; a < 3; ++a) b.linear_velocity[a] = rng.uniform(-o.max_speed, o.max_speed);
    for (int a = 0; a < 3; ++a) b.angular_velocity[a] = rng.uniform(-o.max_spin, o.max_spin);
    scene.bodies.push_back(b);
  }
  const double reach = 3 * rc + 1;
  scene.bounds_lo = Eigen::Vector3d(-reach, -reach, -1);
  scene.bounds_hi = Eigen::Vector3d(reach, reach, bottom + height + 1);
  return scene;
}

DropScene2 drop_scene2(const DropOptions& o)
{
  validate(o);
  DropScene2 scene;
  scene.options = o;
  const double r = o.bounding_radius;
  const double s = 2 * r * o.spacing;
  const double jitter = s / 2 - r;
  const double wanted = std::ceil(static_cast<double>(o.count) / o.fill);
  const double w = std::max(2 * s, s * std::sqrt(wanted / (2 * o.aspect)));
  double height = o.aspect * w;
  const double bottom = s;
  scene.cell = s;

  const int span = static_cast<int>(std::floor(w / s)) + 1;
  std::vector<std::array<int, 2>> cells;
  for (;;) {
    cells.clear();
    const int layers = static_cast<int>(std::floor(height / s));
    for (int k = 0; k < layers; ++k)
      for (int i = -span; i <= span; ++i)
        if (std::fabs(i * s) + jitter + r <= w) cells.push_back({i, k});
    if (cells.size() >= static_cast<std::size_t>(o.count)) break;
    height += s;
  }
  scene.region = Rectangle{w, bottom, height};

  SceneRng rng(o.seed);
  std::vector<std::array<int, 2>> chosen = choose(cells, static_cast<std::size_t>(o.count), rng);
  std::sort(chosen.begin(), chosen.end(), [](const auto& a, const auto& b) {
    if (a[1] != b[1]) return a[1] < b[1];
    return a[0] < b[0];
  });
  scene.bodies.reserve(chosen.size());
  for (const auto& c : chosen) {
    BodyState2 b;
    b.position = Eigen::Vector2d(c[0] * s + rng.uniform(-jitter, jitter),
                                 bottom + (c[1] + 0.5) * s + rng.uniform(-jitter, jitter));
    b.angle = rng.uniform(-kPi, kPi);
    for (int a = 0; a < 2; ++a) b.linear_velocity[a] = rng.uniform(-o.max_speed, o.max_speed);
    b.angular_velocity = rng.uniform(-o.max_spin, o.max_spin);
    scene.bodies.push_back(b);
  }
  const double reach = 3 * w + 1;
  scene.bounds_lo = Eigen::Vector2d(-reach, -1);
  scene.bounds_hi = Eigen::Vector2d(reach, bottom + height + 1);
  return scene;
}

namespace {

// The description of a drop scene around its region's own words ("a cylinder of radius ...").
template <class Scene>
std::string describe(const Scene& sc, const char* what, const std::string& region, const char* ground,
                     const char* spin)
{
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s: %zu bodies of bounding radius %.4g m in %s (cell %.3g m), above the %s; velocity components in "
                "+-%.3g m/s, %s in +-%.3g rad/s; seed %llu",
                what, sc.bodies.size(), sc.options.bounding_radius, region.c_str(), sc.cell, ground,
                sc.options.max_speed, spin, sc.options.max_spin, static_cast<unsigned long long>(sc.options.seed));
  return buf;
}

}  // namespace

std::string describe(const DropScene3& sc)
{
  char region[128];
  std::snprintf(region, sizeof region, "a cylinder of radius %.3g m, z from %.3g to %.3g m", sc.region.radius,
                sc.region.bottom, sc.region.bottom + sc.region.height);
  return describe(sc, "bunny drop", region, "ground plane z = 0", "spin components");
}

std::string describe(const DropScene2& sc)
{
  char region[128];
  std::snprintf(region, sizeof region, "x within +-%.3g m, y from %.3g to %.3g m", sc.region.half_width,
                sc.region.bottom, sc.region.bottom + sc.region.height);
  return describe(sc, "2D drop", region, "ground line y = 0", "spin");
}

namespace {

template <int D, class Bodies>
double min_distance(const Bodies& bodies, double cell)
{
  double best = std::numeric_limits<double>::infinity();
  if (bodies.size() < 2 || !(cell > 0)) return best;
  auto key = [](const std::array<long long, 3>& c) {
    return static_cast<std::uint64_t>(c[0] * 73856093LL ^ c[1] * 19349663LL ^ c[2] * 83492791LL);
  };
  auto cell_of = [cell](const auto& p) {
    std::array<long long, 3> c{0, 0, 0};
    for (int a = 0; a < D; ++a) c[a] = static_cast<long long>(std::floor(p[a] / cell));
    return c;
  };
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < bodies.size(); ++i) grid[key(cell_of(bodies[i].position))].push_back(i);
  // Bodies closer than one cell are in neighbouring cells; farther pairs cannot beat `cell`.
  best = cell;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const auto c = cell_of(bodies[i].position);
    for (long long dz = (D == 3 ? -1 : 0); dz <= (D == 3 ? 1 : 0); ++dz)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dx = -1; dx <= 1; ++dx) {
          const auto it = grid.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == grid.end()) continue;
          for (std::size_t j : it->second)
            if (j > i) best = std::min(best, (bodies[i].position - bodies[j].position).norm());
        }
  }
  return best;
}

}  // namespace

double min_centre_distance(const std::vector<BodyState3>& bodies, double cell)
{
  return min_distance<3>(bodies, cell);
}

double min_centre_distance(const std::vector<BodyState2>& bodies, double cell)
{
  return min_distance<2>(bodies, cell);
}

}  // namespace statsim::tools::scenes
