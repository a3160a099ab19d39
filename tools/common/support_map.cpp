#include "common/support_map.hpp"

#include "statsim/random.hpp"  // mix64

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace statsim::tools {

namespace {

// Uniform doubles in [0, 1) from a SplitMix64 stream.
class Stream {
public:
  explicit Stream(std::uint64_t seed) : state_(seed) {}
  double uniform()
  {
    state_ += 0x9e3779b97f4a7c15ull;
    return static_cast<double>(mix64(state_) >> 11) * 0x1.0p-53;
  }

private:
  std::uint64_t state_;
};

// The node coordinate a_i = -1 + 2 i / (S - 1).
double node(int i, int size)
{
  return -1.0 + 2.0 * static_cast<double>(i) / static_cast<double>(size - 1);
}

// Where a face coordinate in [-1, 1] falls between nodes: cell index and fraction.
void locate(double a, int size, int& i, double& t)
{
  const double x = (a + 1.0) * 0.5 * static_cast<double>(size - 1);
  i = std::min(size - 2, std::max(0, static_cast<int>(std::floor(x))));
  t = std::min(1.0, std::max(0.0, x - static_cast<double>(i)));
}

// The largest component's axis of u (the first of equals).
template <class V>
int major_axis(const V& u)
{
  int m = 0;
  for (int k = 1; k < static_cast<int>(u.size()); ++k)
    if (std::fabs(u[k]) > std::fabs(u[m])) m = k;
  return m;
}

Eigen::Vector3d face_point(int face, double a, double b)
{
  const int m = face / 2;
  Eigen::Vector3d p;
  p[m] = face % 2 ? -1.0 : 1.0;
  p[(m + 1) % 3] = a;
  p[(m + 2) % 3] = b;
  return p;
}

Eigen::Vector2d side_point(int side, double a)
{
  const int m = side / 2;
  Eigen::Vector2d p;
  p[m] = side % 2 ? -1.0 : 1.0;
  p[1 - m] = a;
  return p;
}

template <class V>
double radius_of(const std::vector<V>& hull)
{
  double r = 0.0;
  for (const V& p : hull) r = std::max(r, p.norm());
  return r;
}

template <class V>
double support_of(const std::vector<V>& hull, const V& u)
{
  double s = -std::numeric_limits<double>::infinity();
  for (const V& p : hull) s = std::max(s, u.dot(p));
  return s;
}

// lookup - support over the directions direction(0) .. direction(n - 1), taken in that order.
template <class Map, class V, class Direction>
SupportError error_over(const Map& map, const std::vector<V>& hull, int n, Direction&& direction)
{
  SupportError e;
  e.min = std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const V u = direction(k);
    const double d = map.lookup(u) - support_of(hull, u);
    sum += d;
    e.max = std::max(e.max, d);
    e.min = std::min(e.min, d);
  }
  e.mean = n > 0 ? sum / n : 0.0;
  return e;
}

}  // namespace

double support(const std::vector<Eigen::Vector3d>& hull, const Eigen::Vector3d& u)
{
  return support_of(hull, u);
}

double support(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& u)
{
  return support_of(hull, u);
}

// ---- 3D --------------------------------------------------------------------------------------

SupportMap3 SupportMap3::build(const std::vector<Eigen::Vector3d>& hull, int size)
{
  if (size < 2) throw std::invalid_argument("support map: at least 2 nodes per side");
  if (hull.empty()) throw std::invalid_argument("support map: empty hull");
  SupportMap3 m;
  m.size = size;
  m.values.resize(static_cast<std::size_t>(6 * size * size));
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < size; ++i)
      for (int j = 0; j < size; ++j)
        m.values[static_cast<std::size_t>((f * size + i) * size + j)] =
            support(hull, face_point(f, node(i, size), node(j, size)));
  return m;
}

double SupportMap3::lookup(const Eigen::Vector3d& u) const
{
  const int m = major_axis(u);
  const double um = std::fabs(u[m]);
  if (!(um > 0)) return 0.0;
  const int f = 2 * m + (u[m] < 0 ? 1 : 0);
  int i, j;
  double t, w;
  locate(u[(m + 1) % 3] / um, size, i, t);
  locate(u[(m + 2) % 3] / um, size, j, w);
  const double* v = &values[static_cast<std::size_t>((f * size + i) * size + j)];
  const double h = (1 - t) * ((1 - w) * v[0] + w * v[1]) + t * ((1 - w) * v[size] + w * v[size + 1]);
  return um * h;
}

double SupportMap3::error_bound(const std::vector<Eigen::Vector3d>& hull, int sub) const
{
  const double delta = 2.0 / static_cast<double>(size - 1);
  double worst = 0.0;
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i + 1 < size; ++i)
      for (int j = 0; j + 1 < size; ++j) {
        const double* v = &values[static_cast<std::size_t>((f * size + i) * size + j)];
        for (int x = 0; x <= sub; ++x)
          for (int y = 0; y <= sub; ++y) {
            const double t = static_cast<double>(x) / sub, w = static_cast<double>(y) / sub;
            const double h = (1 - t) * ((1 - w) * v[0] + w * v[1]) + t * ((1 - w) * v[size] + w * v[size + 1]);
            const Eigen::Vector3d p = face_point(f, node(i, size) + t * delta, node(j, size) + w * delta);
            worst = std::max(worst, h - support(hull, p));
          }
      }
  const double half_diagonal = delta / static_cast<double>(sub) * std::sqrt(0.5);
  return worst + (1.0 + std::sqrt(2.0)) * radius_of(hull) * half_diagonal;
}

SupportError measure_support_error(const SupportMap3& map, const std::vector<Eigen::Vector3d>& hull, int n)
{
  Stream rng(0x5eed5a99ull);
  return error_over(map, hull, n, [&rng](int) {
    const double z = 2.0 * rng.uniform() - 1.0, phi = 6.283185307179586 * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
  });
}

// ---- 2D --------------------------------------------------------------------------------------

SupportMap2 SupportMap2::build(const std::vector<Eigen::Vector2d>& hull, int size)
{
  if (size < 2) throw std::invalid_argument("support map: at least 2 nodes per side");
  if (hull.empty()) throw std::invalid_argument("support map: empty hull");
  SupportMap2 m;
  m.size = size;
  m.values.resize(static_cast<std::size_t>(4 * size));
  for (int f = 0; f < 4; ++f)
    for (int i = 0; i < size; ++i)
      m.values[static_cast<std::size_t>(f * size + i)] = support(hull, side_point(f, node(i, size)));
  return m;
}

double SupportMap2::lookup(const Eigen::Vector2d& u) const
{
  const int m = major_axis(u);
  const double um = std::fabs(u[m]);
  if (!(um > 0)) return 0.0;
  const int f = 2 * m + (u[m] < 0 ? 1 : 0);
  int i;
  double t;
  locate(u[1 - m] / um, size, i, t);
  const double* v = &values[static_cast<std::size_t>(f * size + i)];
  return um * ((1 - t) * v[0] + t * v[1]);
}

double SupportMap2::error_bound(const std::vector<Eigen::Vector2d>& hull, int sub) const
{
  const double delta = 2.0 / static_cast<double>(size - 1);
  double worst = 0.0;
  for (int f = 0; f < 4; ++f)
    for (int i = 0; i + 1 < size; ++i) {
      const double* v = &values[static_cast<std::size_t>(f * size + i)];
      for (int x = 0; x <= sub; ++x) {
        const double t = static_cast<double>(x) / sub;
        const double h = (1 - t) * v[0] + t * v[1];
        worst = std::max(worst, h - support(hull, side_point(f, node(i, size) + t * delta)));
      }
    }
  // |dh/da| <= r for both h and its interpolant; half a sub-step away at most.
  return worst + 2.0 * radius_of(hull) * 0.5 * delta / static_cast<double>(sub);
}

SupportError measure_support_error(const SupportMap2& map, const std::vector<Eigen::Vector2d>& hull, int n)
{
  return error_over(map, hull, n, [n](int k) {
    // Evenly spaced angles, offset by half a step: the circle covered without a generator.
    const double phi = 6.283185307179586 * (static_cast<double>(k) + 0.5) / n;
    return Eigen::Vector2d(std::cos(phi), std::sin(phi));
  });
}

}  // namespace statsim::tools
