// See rest_poses2d.hpp.
#include "ref2d/rest_poses2d.hpp"

#include "common/pi.hpp"
#include "common/rest_families.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace statsim::tools {

namespace {

double angle_between(Point2 a, Point2 b)
{
  return std::atan2(std::fabs(a.x * b.y - a.y * b.x), a.x * b.x + a.y * b.y) * 180.0 / kPi;
}

Point2 normalized(Point2 p)
{
  const double n = std::hypot(p.x, p.y);
  return {p.x / n, p.y / n};
}

}  // namespace

RestPoses2d cluster_rest_poses(const Shape2& shape, const std::vector<Point2>& ups, const std::vector<char>& settled,
                               const Gather2dOptions& o)
{
  RestPoses2d out;
  struct Acc {
    Point2 sum;
    std::vector<std::size_t> members;
  };
  std::vector<Acc> acc;
  for (std::size_t i = 0; i < ups.size(); ++i) {
    if (!settled[i]) {
      continue;
    }
    const Point2 u = ups[i];
    std::size_t best = acc.size();
    double best_angle = o.cluster_degrees;
    for (std::size_t k = 0; k < acc.size(); ++k) {
      const double a = angle_between(u, normalized(acc[k].sum));
      if (a <= best_angle) {
        best_angle = a;
        best = k;
      }
    }
    if (best == acc.size()) {
      acc.push_back({{0.0, 0.0}, {}});
    }
    acc[best].sum.x += u.x;
    acc[best].sum.y += u.y;
    acc[best].members.push_back(i);
  }
  // Up vectors of the faces of the convex hull: a polygon at rest lies on a hull edge.
  std::vector<Point2> faces;
  const std::vector<Point2>& hull = shape.hull;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Point2 a = hull[i], b = hull[(i + 1) % hull.size()];
    faces.push_back(normalized({-(b.y - a.y), b.x - a.x}));  // minus the outward normal
  }
  // The invariants of resting on hull edge f under the shape's symmetries (common/rest_families.hpp),
  // lengths in units of L: the rest height, the edge's length, how far the centroid's foot is
  // from the edge's middle, and the sorted heights of every hull vertex above the ground.
  const double L = shape.bounding_radius;
  const auto descriptor = [&](std::size_t f) {
    const Point2 up = faces[f], a = hull[f], b = hull[(f + 1) % hull.size()];
    const double h = shape.support_height(up);
    const Point2 along = {up.y, -up.x};
    const double mid = 0.5 * ((a.x + b.x) * along.x + (a.y + b.y) * along.y);
    std::vector<double> heights;
    for (const Point2& v : hull) heights.push_back((v.x * up.x + v.y * up.y + h) / L);
    std::sort(heights.begin(), heights.end());
    std::vector<double> d = {h / L, std::hypot(b.x - a.x, b.y - a.y) / L, std::fabs(mid) / L,
                             static_cast<double>(hull.size())};
    d.insert(d.end(), heights.begin(), heights.end());
    return d;
  };
  out.clusters.clear();
  std::vector<int> face_of;
  const double total = static_cast<double>(ups.size());
  for (const Acc& a : acc) {
    RestCluster c;
    const Point2 mean = normalized(a.sum);
    c.normal = mean;
    c.count = static_cast<int>(a.members.size());
    c.frequency = static_cast<double>(c.count) / total;
    for (std::size_t m : a.members) {
      c.spread_degrees = std::max(c.spread_degrees, angle_between(ups[m], mean));
    }
    // Snap to the nearest hull face within 3 degrees: Box2D leaves a resting body tilted by its
    // solver tolerances only, and the exact face gives the exact rest height.
    double best = 3.0;
    int face = -1;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const double d = angle_between(mean, faces[f]);
      if (d <= best) {
        best = d;
        c.normal = faces[f];
        c.snap_degrees = d;
        face = static_cast<int>(f);
      }
    }
    c.height = shape.support_height(c.normal);
    out.clusters.push_back(c);
    face_of.push_back(face);
  }
  std::vector<std::size_t> order(out.clusters.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto by_count = [&](std::size_t i, std::size_t j) {
    const RestCluster& a = out.clusters[i];
    const RestCluster& b = out.clusters[j];
    if (a.count != b.count) {
      return a.count > b.count;
    }
    return std::atan2(a.normal.x, a.normal.y) < std::atan2(b.normal.x, b.normal.y);
  };
  std::stable_sort(order.begin(), order.end(), by_count);
  std::vector<RestCandidate> candidates;
  for (std::size_t i : order) {
    RestCandidate k;
    k.frequency = out.clusters[i].frequency;
    k.count = out.clusters[i].count;
    if (face_of[i] >= 0) {
      k.descriptor = descriptor(static_cast<std::size_t>(face_of[i]));
    }
    candidates.push_back(k);
  }
  RestSelectionOptions so;
  so.min_frequency = o.min_frequency;
  so.max_dropped = o.max_dropped;
  const RestSelection sel = select_rest_poses(candidates, so);
  std::vector<RestCluster> sorted;
  for (std::size_t k = 0; k < order.size(); ++k) {
    RestCluster c = out.clusters[order[k]];
    c.kept = sel.kept[k] != 0;
    c.family = sel.family[k];
    c.family_frequency = sel.family_frequency[static_cast<std::size_t>(c.family)];
    sorted.push_back(c);
  }
  // Kept ones first, each part still most frequent first.
  std::stable_partition(sorted.begin(), sorted.end(), [](const RestCluster& c) { return c.kept; });
  out.clusters = sorted;
  out.dropped = sel.dropped;
  return out;
}

}  // namespace statsim::tools
