// See rest_poses.hpp.
#include "ref3d/rest_poses.hpp"

#include "common/pi.hpp"
#include "common/rest_families.hpp"
#include "common/sample_stats.hpp"

#include <algorithm>
#include <cmath>

namespace statsim::tools::ref3d {

namespace {

// Rest normals within this angle of a hull face's are snapped to it.
constexpr double kSnapDegrees = 3.0;

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

}  // namespace

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

RestPoseFit fit_rest_poses(const ShapeModel& m, const std::vector<DropTrial>& drops, const GatherOptions& o)
{
  RestPoseFit fit;
  std::vector<Eigen::Vector3d> ups;
  std::vector<double> heights;
  for (const DropTrial& d : drops) {
    if (!d.settled) {
      ++fit.unsettled;
      continue;
    }
    ++fit.settled;
    fit.mean_settle_time += d.time;
    ups.push_back(d.up);
    heights.push_back(d.height);
  }
  if (fit.settled > 0) fit.mean_settle_time /= fit.settled;
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
    const MeanStd s = mean_std(g.members.size(), [&](std::size_t k) { return heights[g.members[k]]; });
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
    p.frequency = static_cast<double>(p.count) / static_cast<double>(std::max(1, fit.settled));
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
    (sel.kept[k] ? fit.rest : fit.rest_rare).push_back(p);
  }
  fit.rest_dropped = sel.dropped;
  fit.rest_families = static_cast<int>(sel.family_frequency.size());
  return fit;
}

}  // namespace statsim::tools::ref3d
