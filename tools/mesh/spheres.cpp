#include "mesh/spheres.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <utility>

// The hot loops use plain doubles rather than Eigen so that unoptimized (sanitizer) builds stay fast.
namespace statsim::tools {

namespace {

struct P3 {
  double x, y, z;
};

inline double dist(const P3& p, const P3& c)
{
  const double dx = p.x - c.x, dy = p.y - c.y, dz = p.z - c.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

inline double dist2(const P3& p, const P3& c)
{
  const double dx = p.x - c.x, dy = p.y - c.y, dz = p.z - c.z;
  return dx * dx + dy * dy + dz * dz;
}

P3 p3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

struct Ball {
  P3 c;
  double r;
};

struct Grid {
  double origin[3] = {0, 0, 0};  // corner of cell (0, 0, 0)
  double h = 0.0;
  int n[3] = {0, 0, 0};
  std::vector<std::uint8_t> inside;  // per cell, x fastest

  std::size_t index(int i, int j, int k) const
  {
    return (static_cast<std::size_t>(k) * static_cast<std::size_t>(n[1]) + static_cast<std::size_t>(j)) *
             static_cast<std::size_t>(n[0]) +
           static_cast<std::size_t>(i);
  }
  double coord(int axis, int i) const { return origin[axis] + (i + 0.5) * h; }
  P3 point(int i, int j, int k) const { return {coord(0, i), coord(1, j), coord(2, k)}; }
};

// Does the edge p->q own points exactly on it? Each edge shared by two triangles projected with
// the same orientation is owned by exactly one of them, so no ray crosses the surface twice, or
// not at all, at a shared edge.
inline bool owns_edge(double px, double py, double qx, double qy)
{
  const double dx = qx - px, dy = qy - py;
  return dy > 0.0 || (dy == 0.0 && dx < 0.0);
}

// Voxelizes by the winding number along +z rays through the cell centres.
void voxelize(const TriMesh& mesh, int resolution, Grid& g)
{
  Eigen::Vector3d lo, hi;
  bounding_box(mesh, lo, hi);
  const Eigen::Vector3d ext = hi - lo;
  g.h = ext.maxCoeff() / resolution;
  const int margin = resolution / 4;
  for (int a = 0; a < 3; ++a) {
    g.n[a] = static_cast<int>(std::ceil(ext[a] / g.h - 1e-9)) + 2 * margin;
    g.origin[a] = lo[a] - margin * g.h;
  }
  g.inside.assign(static_cast<std::size_t>(g.n[0]) * static_cast<std::size_t>(g.n[1]) * static_cast<std::size_t>(g.n[2]),
                  0);

  // Bucket the triangles by the columns their xy bounding box overlaps.
  const std::size_t columns = static_cast<std::size_t>(g.n[0]) * static_cast<std::size_t>(g.n[1]);
  std::vector<std::vector<std::size_t>> bucket(columns);
  auto cell_of = [&](int axis, double x) {
    return std::clamp(static_cast<int>(std::floor((x - g.origin[axis]) / g.h - 0.5)), 0, g.n[axis] - 1);
  };
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    double x0 = mesh.vertices[f[0]].x(), x1 = x0, y0 = mesh.vertices[f[0]].y(), y1 = y0;
    for (int k = 1; k < 3; ++k) {
      x0 = std::min(x0, mesh.vertices[f[k]].x());
      x1 = std::max(x1, mesh.vertices[f[k]].x());
      y0 = std::min(y0, mesh.vertices[f[k]].y());
      y1 = std::max(y1, mesh.vertices[f[k]].y());
    }
    const int i0 = cell_of(0, x0), i1 = std::min(g.n[0] - 1, cell_of(0, x1) + 1);
    const int j0 = cell_of(1, y0), j1 = std::min(g.n[1] - 1, cell_of(1, y1) + 1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i)
        bucket[static_cast<std::size_t>(j) * static_cast<std::size_t>(g.n[0]) + static_cast<std::size_t>(i)].push_back(t);
  }

  std::vector<std::pair<double, int>> crossings;  // (z, +1 the ray leaves the solid / -1 enters)
  for (int j = 0; j < g.n[1]; ++j) {
    for (int i = 0; i < g.n[0]; ++i) {
      const double x = g.coord(0, i), y = g.coord(1, j);
      crossings.clear();
      for (std::size_t t : bucket[static_cast<std::size_t>(j) * static_cast<std::size_t>(g.n[0]) + static_cast<std::size_t>(i)]) {
        const auto& f = mesh.triangles[t];
        const Eigen::Vector3d& va = mesh.vertices[f[0]];
        const Eigen::Vector3d& vb0 = mesh.vertices[f[1]];
        const Eigen::Vector3d& vc0 = mesh.vertices[f[2]];
        double ax = va.x(), ay = va.y(), az = va.z();
        double bx = vb0.x(), by = vb0.y(), bz = vb0.z();
        double cx = vc0.x(), cy = vc0.y(), cz = vc0.z();
        const double orient = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
        if (orient == 0.0) continue;  // vertical triangle: the ray grazes it
        int sign = 1;                 // outward normal up: the ray leaves the solid here
        if (orient < 0.0) {
          std::swap(bx, cx);
          std::swap(by, cy);
          std::swap(bz, cz);
          sign = -1;
        }
        auto edge = [&](double px, double py, double qx, double qy) {
          const double w = (qx - px) * (y - py) - (qy - py) * (x - px);
          return w > 0.0 || (w == 0.0 && owns_edge(px, py, qx, qy));
        };
        if (!edge(ax, ay, bx, by) || !edge(bx, by, cx, cy) || !edge(cx, cy, ax, ay)) continue;
        const double area = std::fabs(orient);
        const double wa = ((bx - x) * (cy - y) - (by - y) * (cx - x)) / area;
        const double wb = ((cx - x) * (ay - y) - (cy - y) * (ax - x)) / area;
        crossings.emplace_back(wa * az + wb * bz + (1.0 - wa - wb) * cz, sign);
      }
      std::sort(crossings.begin(), crossings.end(), [](const auto& p, const auto& q) {
        return p.first > q.first || (p.first == q.first && p.second < q.second);
      });
      // Winding number of a point = sum of the signs of the crossings above it.
      int winding = 0;
      std::size_t next = 0;
      for (int k = g.n[2] - 1; k >= 0; --k) {
        const double z = g.coord(2, k);
        while (next < crossings.size() && crossings[next].first > z) winding += crossings[next++].second;
        g.inside[g.index(i, j, k)] = winding > 0 ? 1 : 0;
      }
    }
  }
}

// Uniform double in [0, 1) from 53 bits of mt19937_64 (fully specified by the standard, unlike
// std::uniform_real_distribution).
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Weighted k-means (Lloyd) with k-means++ seeding; 16 restarts, the lowest weighted sum of
// squared distances kept (the first on a tie).
std::vector<P3> kmeans(const std::vector<P3>& pts, const std::vector<double>& w, int k)
{
  std::mt19937_64 rng(0x5eed5u);
  const std::size_t n = pts.size();
  const auto nk = static_cast<std::size_t>(k);
  std::vector<P3> best;
  double best_sse = std::numeric_limits<double>::infinity();
  std::vector<int> label(n);
  std::vector<double> d2(n);
  // Draws an index with probability proportional to w[i] (times d2[i] if use_d2).
  auto draw = [&](bool use_d2) {
    double total = 0.0;
    for (std::size_t i = 0; i < n; ++i) total += w[i] * (use_d2 ? d2[i] : 1.0);
    double target = uniform01(rng) * total;
    for (std::size_t i = 0; i < n; ++i) {
      target -= w[i] * (use_d2 ? d2[i] : 1.0);
      if (target < 0.0) return i;
    }
    return n - 1;
  };
  for (int restart = 0; restart < 16; ++restart) {
    std::vector<P3> c;
    c.push_back(pts[draw(false)]);
    for (std::size_t i = 0; i < n; ++i) d2[i] = dist2(pts[i], c[0]);
    while (c.size() < nk) {
      const std::size_t pick = draw(true);
      c.push_back(pts[pick]);
      for (std::size_t i = 0; i < n; ++i) d2[i] = std::min(d2[i], dist2(pts[i], pts[pick]));
    }
    std::fill(label.begin(), label.end(), -1);
    double sse = 0.0;
    for (int iter = 0; iter < 500; ++iter) {
      bool changed = false;
      sse = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        int arg = 0;
        double dmin = dist2(pts[i], c[0]);
        for (std::size_t j = 1; j < nk; ++j) {
          const double d = dist2(pts[i], c[j]);
          if (d < dmin) {
            dmin = d;
            arg = static_cast<int>(j);
          }
        }
        sse += w[i] * dmin;
        d2[i] = dmin;
        if (label[i] != arg) {
          label[i] = arg;
          changed = true;
        }
      }
      if (!changed) break;
      std::vector<P3> sum(nk, P3{0, 0, 0});
      std::vector<double> mass(nk, 0.0);
      for (std::size_t i = 0; i < n; ++i) {
        P3& s = sum[static_cast<std::size_t>(label[i])];
        s.x += w[i] * pts[i].x;
        s.y += w[i] * pts[i].y;
        s.z += w[i] * pts[i].z;
        mass[static_cast<std::size_t>(label[i])] += w[i];
      }
      for (std::size_t j = 0; j < nk; ++j) {
        if (mass[j] > 0.0) {
          c[j] = {sum[j].x / mass[j], sum[j].y / mass[j], sum[j].z / mass[j]};
        } else {  // empty cluster: move it to the point farthest from its centre
          const auto far = static_cast<std::size_t>(std::max_element(d2.begin(), d2.end()) - d2.begin());
          c[j] = pts[far];
          d2[far] = 0.0;
        }
      }
    }
    if (sse < best_sse) {
      best_sse = sse;
      best = c;
    }
  }
  return best;
}

// Score bookkeeping for the union of spheres: cover[i] = number of spheres containing cell i;
// score = sum over covered cells of (+1 inside, -1 outside).
struct Union {
  const Grid& g;
  std::vector<std::uint16_t> cover;
  explicit Union(const Grid& grid) : g(grid), cover(grid.inside.size(), 0) {}

  // The cells of column (i, j) whose centres a ball contains, as the range [k0, k1] (empty when
  // k0 > k1). Membership is defined by this range everywhere in the fit, so it is consistent.
  void column_range(const Ball& b, double x, double y, int& k0, int& k1) const
  {
    const double q = b.r * b.r - (x - b.c.x) * (x - b.c.x) - (y - b.c.y) * (y - b.c.y);
    if (!(q >= 0.0)) {
      k0 = 1;
      k1 = 0;
      return;
    }
    const double s = std::sqrt(q);
    k0 = std::max(0, static_cast<int>(std::ceil((b.c.z - s - g.origin[2]) / g.h - 0.5)));
    k1 = std::min(g.n[2] - 1, static_cast<int>(std::floor((b.c.z + s - g.origin[2]) / g.h - 0.5)));
  }

  // Calls f(cell, in a, in b) for the cells in exactly one of the two balls, column by column.
  template <class F>
  void for_cells(const Ball& a, const Ball& b, F&& f) const
  {
    int lo[2], hi[2];
    const double ac[2] = {a.c.x, a.c.y}, bc[2] = {b.c.x, b.c.y};
    for (int d = 0; d < 2; ++d) {
      const double l = std::min(ac[d] - a.r, bc[d] - b.r);
      const double u = std::max(ac[d] + a.r, bc[d] + b.r);
      lo[d] = std::max(0, static_cast<int>(std::floor((l - g.origin[d]) / g.h - 0.5)));
      hi[d] = std::min(g.n[d] - 1, static_cast<int>(std::ceil((u - g.origin[d]) / g.h - 0.5)));
    }
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const double x = g.coord(0, i), y = g.coord(1, j);
        int a0, a1, b0, b1;
        column_range(a, x, y, a0, a1);
        column_range(b, x, y, b0, b1);
        auto run = [&](int k0, int k1, bool in_a) {
          for (int k = k0; k <= k1; ++k) f(g.index(i, j, k), in_a, !in_a);
        };
        if (a0 > a1 || b0 > b1 || a1 < b0 || b1 < a0) {  // an empty range, or disjoint ranges
          run(a0, a1, true);
          run(b0, b1, false);
          continue;
        }
        if (a0 < b0) run(a0, b0 - 1, true);
        else run(b0, a0 - 1, false);
        if (a1 > b1) run(b1 + 1, a1, true);
        else run(a1 + 1, b1, false);
      }
  }
  // Change of the score if ball `from` became `to`.
  long delta(const Ball& from, const Ball& to) const
  {
    long d = 0;
    for_cells(from, to, [&](std::size_t c, bool was, bool now) {
      const int before = cover[c];
      const int after = before - (was ? 1 : 0) + (now ? 1 : 0);
      if ((before > 0) != (after > 0)) d += (after > 0 ? 1 : -1) * (g.inside[c] ? 1 : -1);
    });
    return d;
  }
  void apply(const Ball& from, const Ball& to)
  {
    for_cells(from, to, [&](std::size_t c, bool was, bool now) {
      cover[c] = static_cast<std::uint16_t>(cover[c] - (was ? 1 : 0) + (now ? 1 : 0));
    });
  }
};

// The radius maximizing (inside cells) - (outside cells) of a ball alone at `centre`.
double best_radius(const Grid& g, const P3& centre, double rmax)
{
  std::vector<std::pair<double, int>> cells;
  const Union u(g);
  u.for_cells(Ball{centre, 0.0}, Ball{centre, rmax}, [&](std::size_t c, bool, bool) {
    const std::size_t layer = static_cast<std::size_t>(g.n[0]) * static_cast<std::size_t>(g.n[1]);
    const auto k = static_cast<int>(c / layer);
    const auto j = static_cast<int>((c % layer) / static_cast<std::size_t>(g.n[0]));
    const auto i = static_cast<int>(c % static_cast<std::size_t>(g.n[0]));
    cells.emplace_back(dist(g.point(i, j, k), centre), g.inside[c] ? 1 : -1);
  });
  std::sort(cells.begin(), cells.end());
  long score = 0, best = 0;
  double r = g.h;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    score += cells[i].second;
    const bool boundary = i + 1 == cells.size() || cells[i + 1].first > cells[i].first;
    if (boundary && score > best) {
      best = score;
      r = cells[i].first;
    }
  }
  return std::max(r, g.h);
}

double round6(double x)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", x);
  return std::strtod(buf, nullptr);
}

// Closest distance from p to the triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               const Eigen::Vector3d& c)
{
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return (p - (a + ab * (d1 / (d1 - d3)))).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return (p - (a + ac * (d2 / (d2 - d6)))).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).norm();
  }
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

// Distance from p to the mesh surface: triangles whose bounding box is farther than the best
// distance so far are skipped; the nearest vertex gives the first bound.
struct SurfaceDistance {
  const TriMesh& mesh;
  std::vector<P3> vertices;
  std::vector<double> box;  // per triangle: min x, y, z, max x, y, z
  explicit SurfaceDistance(const TriMesh& m) : mesh(m)
  {
    for (const auto& v : m.vertices) vertices.push_back(p3(v));
    for (const auto& t : m.triangles) {
      for (int d = 0; d < 3; ++d) box.push_back(std::min({m.vertices[t[0]][d], m.vertices[t[1]][d], m.vertices[t[2]][d]}));
      for (int d = 0; d < 3; ++d) box.push_back(std::max({m.vertices[t[0]][d], m.vertices[t[1]][d], m.vertices[t[2]][d]}));
    }
  }
  double operator()(const P3& p) const
  {
    double best2 = std::numeric_limits<double>::infinity();
    for (const P3& v : vertices) best2 = std::min(best2, dist2(v, p));
    const double q[3] = {p.x, p.y, p.z};
    const Eigen::Vector3d pe(p.x, p.y, p.z);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const double* b = &box[6 * t];
      double box2 = 0.0;
      for (int d = 0; d < 3; ++d) {
        const double e = q[d] < b[d] ? b[d] - q[d] : (q[d] > b[3 + d] ? q[d] - b[3 + d] : 0.0);
        box2 += e * e;
      }
      if (box2 >= best2) continue;
      const auto& f = mesh.triangles[t];
      const double d = point_triangle_distance(pe, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]);
      best2 = std::min(best2, d * d);
    }
    return std::sqrt(best2);
  }
};

}  // namespace

bool fit_spheres(const TriMesh& mesh, int count, int resolution, SphereFit& fit, MeshError& error)
{
  if (count < 1 || count > 64) {
    error.message = "sphere count must be between 1 and 64, got " + std::to_string(count);
    return false;
  }
  if (resolution < 8 || resolution > 256) {
    error.message = "resolution must be between 8 and 256, got " + std::to_string(resolution);
    return false;
  }
  Grid g;
  voxelize(mesh, resolution, g);
  std::vector<P3> inside_pts;
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i)
        if (g.inside[g.index(i, j, k)]) inside_pts.push_back(g.point(i, j, k));
  if (inside_pts.size() < static_cast<std::size_t>(count)) {
    error.message = "the mesh is too thin for the voxel grid (" + std::to_string(inside_pts.size()) +
                    " inside cells); raise --resolution";
    return false;
  }
  fit = SphereFit{};
  fit.cell = g.h;
  fit.voxel_volume = static_cast<double>(inside_pts.size()) * g.h * g.h * g.h;

  Eigen::Vector3d lo, hi;
  bounding_box(mesh, lo, hi);
  const double rmax = 0.5 * (hi - lo).maxCoeff();

  // Surface samples: the centroids of the 4 midpoint sub-triangles of each triangle, each
  // weighted by a quarter of its area.
  std::vector<P3> sp;
  std::vector<double> sw;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d& b = mesh.vertices[t[1]];
    const Eigen::Vector3d& c = mesh.vertices[t[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const Eigen::Vector3d ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
    for (const Eigen::Vector3d& p : {Eigen::Vector3d((a + ab + ca) / 3.0), Eigen::Vector3d((ab + b + bc) / 3.0),
                                     Eigen::Vector3d((ca + bc + c) / 3.0), Eigen::Vector3d((ab + bc + ca) / 3.0)}) {
      sp.push_back(p3(p));
      sw.push_back(0.25 * area);
    }
  }
  const std::size_t ns = sp.size();

  // Start: a ball per surface cluster, at the inside cell centre nearest to the cluster's
  // centroid, with the best radius of a ball alone there.
  std::vector<Ball> balls;
  for (const P3& c0 : kmeans(sp, sw, count)) {
    P3 start = inside_pts[0];
    for (const P3& q : inside_pts) {
      if (dist2(q, c0) < dist2(start, c0)) start = q;
    }
    balls.push_back({start, best_radius(g, start, rmax)});
  }

  // Fit: coordinate descent on E = vol(union xor solid) + sum over the surface samples of
  // weight * |d|, d = min_j (|p - c_j| - r_j). Both terms are volumes.
  const double cell_volume = g.h * g.h * g.h;
  Union u(g);
  for (const Ball& b : balls) u.apply(Ball{b.c, 0.0}, b);
  // dist_to[i * k + m] = |p_i - c_m| - r_m. Moving ball j only changes the samples where it is,
  // or becomes, the nearest: with moves of at most `step`, those with dist_to(j) - step <= the
  // nearest other ball (a 2 * step margin is used).
  const std::size_t nb = balls.size();
  std::vector<double> dist_to(ns * nb);
  for (std::size_t i = 0; i < ns; ++i)
    for (std::size_t m = 0; m < nb; ++m) dist_to[i * nb + m] = dist(sp[i], balls[m].c) - balls[m].r;
  std::vector<double> others(ns);  // per sample: nearest of the balls other than the one moved
  std::vector<std::size_t> active;
  for (double step = 2.0 * g.h; step >= 0.25 * g.h; step *= 0.5) {
    for (int round = 0; round < 200; ++round) {
      bool improved = false;
      for (std::size_t j = 0; j < nb; ++j) {
        for (std::size_t i = 0; i < ns; ++i) {
          double d = std::numeric_limits<double>::infinity();
          for (std::size_t m = 0; m < nb; ++m) {
            if (m != j) d = std::min(d, dist_to[i * nb + m]);
          }
          others[i] = d;
        }
        auto find_active = [&] {
          active.clear();
          for (std::size_t i = 0; i < ns; ++i) {
            if (dist_to[i * nb + j] - 2.0 * step <= others[i]) active.push_back(i);
          }
        };
        find_active();
        for (int move = 0; move < 8; ++move) {
          const Ball s = balls[j];
          Ball t = s;
          const double sgn = (move % 2 == 0) ? 1.0 : -1.0;
          if (move < 2) t.c.x += sgn * step;
          else if (move < 4) t.c.y += sgn * step;
          else if (move < 6) t.c.z += sgn * step;
          else t.r += sgn * step;
          if (t.r < g.h) continue;
          double surface_change = 0.0;
          for (std::size_t i : active) {
            const double before = std::min(others[i], dist_to[i * nb + j]);
            const double after = std::min(others[i], dist(sp[i], t.c) - t.r);
            surface_change += sw[i] * (std::fabs(after) - std::fabs(before));
          }
          // The union's score (inside minus outside cells) rising by n shrinks the symmetric
          // difference by n cells.
          const double change = surface_change - static_cast<double>(u.delta(s, t)) * cell_volume;
          if (change < 0.0) {
            u.apply(s, t);
            balls[j] = t;
            for (std::size_t i = 0; i < ns; ++i) dist_to[i * nb + j] = dist(sp[i], t.c) - t.r;
            find_active();
            improved = true;
          }
        }
      }
      if (!improved) break;
    }
  }

  // Round, then measure the rounded spheres.
  for (const Ball& b : balls) {
    fit.spheres.push_back({Eigen::Vector3d(round6(b.c.x), round6(b.c.y), round6(b.c.z)), round6(b.r)});
  }
  std::vector<Ball> rounded;
  for (const auto& sph : fit.spheres) rounded.push_back({p3(sph.centre), sph.radius});
  auto union_distance = [&](const P3& p) {
    double d = std::numeric_limits<double>::infinity();
    for (const Ball& b : rounded) d = std::min(d, dist(p, b.c) - b.r);
    return d;
  };
  const SurfaceDistance surface_distance(mesh);
  std::size_t in_cov = 0, out_cov = 0, in_total = 0;
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i) {
        const P3 p = g.point(i, j, k);
        const bool in = g.inside[g.index(i, j, k)] != 0;
        in_total += in ? 1 : 0;
        if (!(union_distance(p) <= 0.0)) continue;
        if (in) {
          ++in_cov;
        } else {
          ++out_cov;
          fit.max_protrusion = std::max(fit.max_protrusion, surface_distance(p));
        }
      }
  fit.coverage = static_cast<double>(in_cov) / static_cast<double>(in_total);
  fit.protrusion = static_cast<double>(out_cov) / static_cast<double>(in_total);

  double area_sum = 0.0, sq = 0.0, ab = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d& b = mesh.vertices[t[1]];
    const Eigen::Vector3d& c = mesh.vertices[t[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const double d = union_distance(p3((a + b + c) / 3.0));
    area_sum += area;
    sq += area * d * d;
    ab += area * std::fabs(d);
  }
  for (const auto& p : mesh.vertices) fit.max_uncovered = std::max(fit.max_uncovered, union_distance(p3(p)));
  fit.surface_rms = std::sqrt(sq / area_sum);
  fit.surface_mean_abs = ab / area_sum;
  return true;
}

}  // namespace statsim::tools
