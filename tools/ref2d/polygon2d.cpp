#include "ref2d/polygon2d.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace statsim::tools {
namespace {

double cross(Point2 o, Point2 a, Point2 b)
{
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

double dist(Point2 a, Point2 b)
{
  return std::hypot(a.x - b.x, a.y - b.y);
}

// The shortest text that reads back to v, by std::to_chars (fixed or scientific, whichever is
// shorter: what format_polygon promises; common/format.hpp's num prefers fixed).
std::string shortest_text(double v)
{
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string pt(Point2 p)
{
  return "(" + shortest_text(p.x) + ", " + shortest_text(p.y) + ")";
}

[[noreturn]] void reject(const std::string& why)
{
  throw std::invalid_argument("polygon: " + why);
}

double signed_area(const std::vector<Point2>& v)
{
  double a = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Point2 p = v[i];
    const Point2 q = v[(i + 1) % v.size()];
    a += p.x * q.y - q.x * p.y;
  }
  return 0.5 * a;
}

// Do the closed segments pq and rs share a point? (`eps` is a length tolerance.)
bool segments_touch(Point2 p, Point2 q, Point2 r, Point2 s, double eps)
{
  const double lpq = std::max(dist(p, q), eps);
  const double lrs = std::max(dist(r, s), eps);
  const double d1 = cross(p, q, r) / lpq;  // signed distances of r, s from line pq
  const double d2 = cross(p, q, s) / lpq;
  const double d3 = cross(r, s, p) / lrs;  // of p, q from line rs
  const double d4 = cross(r, s, q) / lrs;
  const auto sgn = [eps](double d) { return d > eps ? 1 : (d < -eps ? -1 : 0); };
  const int s1 = sgn(d1), s2 = sgn(d2), s3 = sgn(d3), s4 = sgn(d4);
  if (s1 * s2 < 0 && s3 * s4 < 0) {
    return true;  // proper crossing
  }
  // An endpoint on the other segment (within eps).
  const auto on_segment = [eps](Point2 a, Point2 b, Point2 x) {
    const double len = dist(a, b);
    if (len <= eps) {
      return dist(a, x) <= eps;
    }
    const double t = ((x.x - a.x) * (b.x - a.x) + (x.y - a.y) * (b.y - a.y)) / (len * len);
    if (t < -eps / len || t > 1.0 + eps / len) {
      return false;
    }
    return std::fabs(cross(a, b, x)) / len <= eps;
  };
  return on_segment(p, q, r) || on_segment(p, q, s) || on_segment(r, s, p) || on_segment(r, s, q);
}

std::vector<Point2> convex_hull(std::vector<Point2> pts, double eps)
{
  std::sort(pts.begin(), pts.end(), [](Point2 a, Point2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  std::vector<Point2> h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= eps * dist(h[k - 2], pts[i])) {
      --k;
    }
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], pts[i]) <= eps * dist(h[k - 2], pts[i])) {
      --k;
    }
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  return h;
}

// Smallest interior angle of triangle abc (radians), a quality measure for ears.
double min_angle(Point2 a, Point2 b, Point2 c)
{
  const auto angle = [](Point2 o, Point2 p, Point2 q) {
    const double ux = p.x - o.x, uy = p.y - o.y, vx = q.x - o.x, vy = q.y - o.y;
    return std::atan2(std::fabs(ux * vy - uy * vx), ux * vx + uy * vy);
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

// Ear clipping of a CCW simple polygon without collinear vertices: triangles as index triples.
// Takes the ear with the largest smallest angle each time (deterministic: ties by position).
std::vector<std::vector<int>> triangulate(const std::vector<Point2>& v, double eps)
{
  std::vector<int> idx(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    idx[i] = static_cast<int>(i);
  }
  std::vector<std::vector<int>> tris;
  while (idx.size() > 3) {
    const std::size_t m = idx.size();
    std::size_t best = m;
    double best_q = -1.0;
    for (std::size_t k = 0; k < m; ++k) {
      const int a = idx[(k + m - 1) % m], b = idx[k], c = idx[(k + 1) % m];
      if (cross(v[a], v[b], v[c]) <= eps * dist(v[a], v[c])) {
        continue;  // reflex or flat
      }
      bool empty = true;
      for (int p : idx) {
        if (p == a || p == b || p == c) {
          continue;
        }
        const double lab = dist(v[a], v[b]), lbc = dist(v[b], v[c]), lca = dist(v[c], v[a]);
        if (cross(v[a], v[b], v[p]) >= -eps * lab && cross(v[b], v[c], v[p]) >= -eps * lbc &&
            cross(v[c], v[a], v[p]) >= -eps * lca) {
          empty = false;
          break;
        }
      }
      if (!empty) {
        continue;
      }
      const double q = min_angle(v[a], v[b], v[c]);
      if (q > best_q) {
        best_q = q;
        best = k;
      }
    }
    if (best == m) {
      reject("could not be triangulated (nearly degenerate geometry?)");
    }
    tris.push_back({idx[(best + m - 1) % m], idx[best], idx[(best + 1) % m]});
    idx.erase(idx.begin() + static_cast<std::ptrdiff_t>(best));
  }
  if (cross(v[idx[0]], v[idx[1]], v[idx[2]]) <= eps * dist(v[idx[0]], v[idx[2]])) {
    reject("could not be triangulated (nearly degenerate geometry?)");
  }
  tris.push_back(idx);
  return tris;
}

bool strictly_convex(const std::vector<int>& poly, const std::vector<Point2>& v, double eps)
{
  const std::size_t m = poly.size();
  for (std::size_t k = 0; k < m; ++k) {
    const Point2 a = v[poly[(k + m - 1) % m]], b = v[poly[k]], c = v[poly[(k + 1) % m]];
    if (cross(a, b, c) <= eps * dist(a, c)) {
      return false;
    }
  }
  return true;
}

// Merges neighbouring pieces while the union stays strictly convex with at most 8 vertices
// (Hertel-Mehlhorn style, greedy in a fixed order).
std::vector<std::vector<int>> merge_convex(std::vector<std::vector<int>> pieces, const std::vector<Point2>& v,
                                           double eps)
{
  bool merged_any = true;
  while (merged_any) {
    merged_any = false;
    for (std::size_t i = 0; i < pieces.size() && !merged_any; ++i) {
      for (std::size_t j = i + 1; j < pieces.size() && !merged_any; ++j) {
        const std::vector<int>& p = pieces[i];
        const std::vector<int>& q = pieces[j];
        for (std::size_t k = 0; k < p.size() && !merged_any; ++k) {
          const int a = p[k], b = p[(k + 1) % p.size()];
          for (std::size_t l = 0; l < q.size(); ++l) {
            if (q[l] != b || q[(l + 1) % q.size()] != a) {
              continue;
            }
            // p from b around to a, then q from after a to before b.
            std::vector<int> m;
            for (std::size_t s = 0; s < p.size(); ++s) {
              m.push_back(p[(k + 1 + s) % p.size()]);
            }
            for (std::size_t s = 2; s < q.size(); ++s) {
              m.push_back(q[(l + s) % q.size()]);
            }
            if (static_cast<int>(m.size()) <= kMaxPieceVertices && strictly_convex(m, v, eps)) {
              pieces[i] = m;
              pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(j));
              merged_any = true;
            }
            break;
          }
        }
      }
    }
  }
  return pieces;
}

}  // namespace

double Shape2::support_height(Point2 up) const
{
  double h = -std::numeric_limits<double>::infinity();
  for (const Point2& p : outline) {
    h = std::max(h, -(p.x * up.x + p.y * up.y));
  }
  return h;
}

std::vector<Point2> parse_polygon(const std::string& spec)
{
  std::vector<Point2> out;
  std::size_t pos = 0;
  int index = 0;
  while (true) {
    while (pos < spec.size() && std::isspace(static_cast<unsigned char>(spec[pos]))) {
      ++pos;
    }
    if (pos >= spec.size()) {
      break;
    }
    std::size_t end = pos;
    while (end < spec.size() && !std::isspace(static_cast<unsigned char>(spec[end]))) {
      ++end;
    }
    const std::string token = spec.substr(pos, end - pos);
    pos = end;
    ++index;
    const std::size_t comma = token.find(',');
    const std::string where = "vertex " + std::to_string(index) + " '" + token + "'";
    if (comma == std::string::npos || token.find(',', comma + 1) != std::string::npos) {
      reject(where + " is not of the form x,y (vertices are separated by spaces, coordinates by a comma)");
    }
    const auto parse = [&](const std::string& s) {
      double value = 0.0;
      const char* first = s.data();
      const char* last = s.data() + s.size();
      if (!s.empty() && *first == '+') {
        ++first;
      }
      const auto r = std::from_chars(first, last, value);
      if (s.empty() || r.ec != std::errc() || r.ptr != last) {
        reject(where + ": '" + s + "' is not a number");
      }
      if (!std::isfinite(value)) {
        reject(where + ": coordinates must be finite");
      }
      return value;
    };
    out.push_back({parse(token.substr(0, comma)), parse(token.substr(comma + 1))});
  }
  return out;
}

std::string format_polygon(const std::vector<Point2>& vertices)
{
  std::string s;
  for (const Point2& p : vertices) {
    if (!s.empty()) {
      s += ' ';
    }
    s += shortest_text(p.x) + "," + shortest_text(p.y);
  }
  return s;
}

Shape2 make_shape(std::vector<Point2> v, std::string name, std::string description)
{
  if (v.size() < 3) {
    reject("needs at least 3 vertices, got " + std::to_string(v.size()));
  }
  double extent = 0.0;
  for (const Point2& p : v) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      reject("coordinates must be finite");
    }
  }
  for (const Point2& p : v) {
    for (const Point2& q : v) {
      extent = std::max(extent, dist(p, q));
    }
  }
  const double eps = 1e-9 * std::max(extent, 1e-300);
  for (std::size_t i = 0; i < v.size(); ++i) {
    for (std::size_t j = i + 1; j < v.size(); ++j) {
      if (dist(v[i], v[j]) <= eps) {
        reject("vertices " + std::to_string(i + 1) + " and " + std::to_string(j + 1) + " coincide at " + pt(v[i]));
      }
    }
  }
  // Simple: no two edges share a point except neighbours at their common vertex, and neighbours
  // do not fold back onto each other.
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2 a = v[i], b = v[(i + 1) % n];
    for (std::size_t j = i + 1; j < n; ++j) {
      const Point2 c = v[j], d = v[(j + 1) % n];
      const bool next = j == i + 1;
      const bool prev = i == 0 && j == n - 1;
      if (next || prev) {
        // Shared vertex: b == c (next) or d == a (prev). Folding back: the far end of one edge
        // lies on the other.
        const bool fold = next ? segments_touch(a, b, d, d, eps) || segments_touch(c, d, a, a, eps)
                               : segments_touch(a, b, c, c, eps) || segments_touch(c, d, b, b, eps);
        if (fold && n > 3) {
          reject("is self-intersecting: edges " + std::to_string(i + 1) + " and " + std::to_string(j + 1) +
                 " fold back onto each other");
        }
        continue;
      }
      if (segments_touch(a, b, c, d, eps)) {
        reject("is self-intersecting: edge " + std::to_string(i + 1) + " " + pt(a) + "-" + pt(b) + " meets edge " +
               std::to_string(j + 1) + " " + pt(c) + "-" + pt(d));
      }
    }
  }
  const double area0 = signed_area(v);
  if (!(std::fabs(area0) > 1e-9 * extent * extent)) {
    reject("has zero area");
  }
  if (area0 < 0.0) {
    std::reverse(v.begin(), v.end());
  }
  // Drop collinear vertices (they add nothing and make flat "ears").
  for (bool changed = true; changed && v.size() > 3;) {
    changed = false;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const Point2 a = v[(i + v.size() - 1) % v.size()], b = v[i], c = v[(i + 1) % v.size()];
      if (std::fabs(cross(a, b, c)) <= eps * dist(a, c)) {
        v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
    }
  }

  Shape2 s;
  s.name = std::move(name);
  s.description = std::move(description);
  // Centroid.
  const double area = signed_area(v);
  double cx = 0.0, cy = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Point2 p = v[i], q = v[(i + 1) % v.size()];
    const double c = p.x * q.y - q.x * p.y;
    cx += (p.x + q.x) * c;
    cy += (p.y + q.y) * c;
  }
  s.offset = {cx / (6.0 * area), cy / (6.0 * area)};
  for (Point2& p : v) {
    p.x -= s.offset.x;
    p.y -= s.offset.y;
  }
  s.outline = v;
  s.area = signed_area(v);
  double inertia = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Point2 p = v[i], q = v[(i + 1) % v.size()];
    const double c = p.x * q.y - q.x * p.y;
    inertia += c * (p.x * p.x + p.x * q.x + q.x * q.x + p.y * p.y + p.y * q.y + q.y * q.y);
  }
  s.polar_inertia = inertia / 12.0;
  for (const Point2& p : v) {
    s.bounding_radius = std::max(s.bounding_radius, std::hypot(p.x, p.y));
  }
  s.hull = convex_hull(v, eps);
  s.inradius_min = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < s.hull.size(); ++i) {
    const Point2 a = s.hull[i], b = s.hull[(i + 1) % s.hull.size()];
    s.inradius_min = std::min(s.inradius_min, cross(a, b, Point2{0.0, 0.0}) / dist(a, b));
  }
  if (s.bounding_radius < 0.05 || s.bounding_radius > 20.0) {
    reject("its size (bounding radius " + shortest_text(s.bounding_radius) +
           " m about the centroid) is outside 0.05..20 m, the range Box2D is tuned for");
  }

  // Convex pieces.
  const std::vector<std::vector<int>> pieces = merge_convex(triangulate(v, eps), v, eps);
  for (const std::vector<int>& piece : pieces) {
    std::vector<Point2> pv;
    for (int k : piece) {
      pv.push_back(v[k]);
    }
    // Box2D welds vertices closer than 0.0025 m and asserts (or silently substitutes a 2 x 2 box)
    // when a polygon degenerates: keep well clear of that before calling it, then check that it
    // kept this piece as it is.
    std::string where;
    for (const Point2& p : pv) {
      where += (where.empty() ? "" : " ") + pt({p.x + s.offset.x, p.y + s.offset.y});
    }
    const std::string too_thin =
        "has a part too thin for Box2D (which welds vertices closer than 0.0025 m): the convex piece " + where;
    const double min_feature = static_cast<double>(b2_linearSlop);
    for (std::size_t a = 0; a < pv.size(); ++a) {
      for (std::size_t b = a + 1; b < pv.size(); ++b) {
        if (dist(pv[a], pv[b]) < min_feature) {
          reject(too_thin);
        }
      }
      // Each vertex well off the line through its neighbours (Box2D's hull works in float).
      const Point2 prev = pv[(a + pv.size() - 1) % pv.size()], next = pv[(a + 1) % pv.size()];
      if (cross(prev, pv[a], next) / dist(prev, next) < 0.1 * min_feature) {
        reject(too_thin);
      }
    }
    b2Vec2 bv[kMaxPieceVertices];
    for (std::size_t k = 0; k < pv.size(); ++k) {
      bv[k].Set(static_cast<float>(pv[k].x), static_cast<float>(pv[k].y));
    }
    b2PolygonShape shape;
    shape.Set(bv, static_cast<int32>(pv.size()));
    b2MassData md;
    shape.ComputeMass(&md, 1.0f);
    const double piece_area = signed_area(pv);
    if (shape.m_count != static_cast<int32>(pv.size()) ||
        std::fabs(static_cast<double>(md.mass) - piece_area) > 1e-4 * piece_area + 1e-9) {
      reject(too_thin);
    }
    s.pieces.push_back(std::move(pv));
  }
  return s;
}

Shape2 square_shape()
{
  return make_shape({{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}, "square", "1 x 1 m square");
}

Shape2 lshape_shape()
{
  return make_shape({{0.0, 0.0}, {1.0, 0.0}, {1.0, 0.25}, {0.25, 0.25}, {0.25, 1.0}, {0.0, 1.0}}, "lshape",
                    "L of a 1.0 x 0.25 m foot along x and a 0.25 x 0.75 m upright on its left end "
                    "(outline (0,0) (1,0) (1,0.25) (0.25,0.25) (0.25,1) (0,1), centred on its centroid)");
}

}  // namespace statsim::tools
