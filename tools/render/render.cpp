#include "render/render.hpp"

#include "common/format.hpp"
#include "common/parallel.hpp"
#include "common/stb_wrapper.hpp"
#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "mesh/shapes.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"
#include "tables/lshape2d.hpp"
#include "tables/square2d.hpp"

#include <gif_lib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <sstream>

#ifndef STATSIM_RENDER_MESHES_DIR
#define STATSIM_RENDER_MESHES_DIR "tools/meshes"
#endif

namespace statsim::tools::render {

std::string default_meshes_dir() { return STATSIM_RENDER_MESHES_DIR; }

namespace {

constexpr double kPi = 3.14159265358979323846;

template <int D>
double largest_rest_height(const SignatureView<D>& sig)
{
  double h = 0;
  for (std::uint32_t i = 0; i < sig.rest.count; ++i) h = std::max(h, double(sig.rest.heights[i]));
  return h;
}

void append(RenderShape& s, const TriMesh& m, const Eigen::Vector3d& offset)
{
  const int base = int(s.vertices.size());
  for (const Eigen::Vector3d& v : m.vertices) s.vertices.push_back((v + offset).cast<float>());
  for (const auto& t : m.triangles) s.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

bool load_body_mesh(const std::string& dir, const std::string& file, const std::string& frame_file, TriMesh& out,
                    std::string& error)
{
  TriMesh mesh, frame_mesh;
  MeshError e;
  if (!load_obj(dir + "/" + file, mesh, e) || !load_obj(dir + "/" + frame_file, frame_mesh, e)) {
    error = e.message;
    return false;
  }
  // The body frame of `frame_file` (centre of mass, principal axes: the frame of the tables).
  out = to_body_frame(mesh, compute_mass_properties(frame_mesh, 1000.0));
  return true;
}

// An icosphere of radius 1: the icosahedron subdivided twice (320 triangles).
TriMesh unit_sphere()
{
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriMesh m;
  m.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : m.vertices) v.normalize();
  m.triangles = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int level = 0; level < 2; ++level) {
    std::vector<std::array<int, 3>> next;
    for (const auto& tri : m.triangles) {
      int mid[3];
      for (int k = 0; k < 3; ++k) {
        m.vertices.push_back((m.vertices[std::size_t(tri[std::size_t(k)])] +
                              m.vertices[std::size_t(tri[std::size_t((k + 1) % 3)])])
                                 .normalized());
        mid[k] = int(m.vertices.size()) - 1;
      }
      next.push_back({tri[0], mid[0], mid[2]});
      next.push_back({tri[1], mid[1], mid[0]});
      next.push_back({tri[2], mid[2], mid[1]});
      next.push_back({mid[0], mid[1], mid[2]});
    }
    m.triangles = next;
  }
  return m;
}

}  // namespace

bool load_render_shape(const std::string& name, const std::string& meshes_dir, RenderShape& shape,
                       std::string& error)
{
  shape = RenderShape{};
  shape.name = name;
  TriMesh m;
  if (name == "box" || name == "lshape" || name == "bunny") {
    if (!load_body_mesh(meshes_dir, name + ".obj", name + ".obj", m, error)) return false;
    append(shape, m, Eigen::Vector3d::Zero());
    shape.table_sphere_radius = name == "box"      ? largest_rest_height(tables::box.view())
                                : name == "lshape" ? largest_rest_height(tables::lshape.view())
                                                   : largest_rest_height(tables::bunny.view());
  } else if (name == "bunny_low") {
    if (!load_body_mesh(meshes_dir, "bunny_low.obj", "bunny.obj", m, error)) return false;
    append(shape, m, Eigen::Vector3d::Zero());
    shape.table_sphere_radius = largest_rest_height(tables::bunny.view());
  } else if (name == "square2d") {
    append(shape, make_box(Eigen::Vector3d(1, 1, 0.5)), Eigen::Vector3d::Zero());
    shape.planar = true;
    shape.table_sphere_radius = largest_rest_height(tables::square2d.view());
  } else if (name == "lshape2d") {
    // The polygon (0,0) (1,0) (1,0.25) (0.25,0.25) (0.25,1) (0,1) of examples/drop2d.cpp as two
    // rectangles, moved so that its centroid (19/56, 19/56) is at the origin.
    const double c = 19.0 / 56.0;
    append(shape, make_box(Eigen::Vector3d(1, 0.25, 0.5)), Eigen::Vector3d(0.5 - c, 0.125 - c, 0));
    append(shape, make_box(Eigen::Vector3d(0.25, 0.75, 0.5)), Eigen::Vector3d(0.125 - c, 0.625 - c, 0));
    shape.planar = true;
    shape.table_sphere_radius = largest_rest_height(tables::lshape2d.view());
  } else if (name == "sphere") {
    append(shape, unit_sphere(), Eigen::Vector3d::Zero());
  } else {
    error = "unknown shape '" + name + "' (box, lshape, bunny, bunny_low, square2d, lshape2d, sphere)";
    return false;
  }
  for (const Eigen::Vector3f& v : shape.vertices) shape.bounding_radius = std::max(shape.bounding_radius, double(v.norm()));
  return true;
}

bool load_frames(const std::string& path, const std::string& shape_names, const std::string& detail,
                 const std::string& meshes_dir, LoadedFrames& out, std::string& error)
{
  const std::vector<std::string> names = split_list(shape_names);
  if (!read_frames(path, names, out.frames, error)) return false;
  const int bodies = out.frames.body_count();
  for (const std::string& name : out.frames.shapes) {
    const bool low = name == "bunny" && (detail == "low" || (detail == "auto" && bodies > 1000));
    auto s = std::make_unique<RenderShape>();
    if (!load_render_shape(low ? "bunny_low" : name, meshes_dir, *s, error)) return false;
    out.shapes.push_back(s.get());
    out.owned.push_back(std::move(s));
  }
  return true;
}

Eigen::Vector3f body_colour(int index)
{
  static const float palette[8][3] = {{0.86f, 0.72f, 0.52f}, {0.45f, 0.62f, 0.82f}, {0.84f, 0.47f, 0.38f},
                                      {0.52f, 0.74f, 0.50f}, {0.80f, 0.66f, 0.82f}, {0.93f, 0.82f, 0.42f},
                                      {0.50f, 0.75f, 0.75f}, {0.92f, 0.90f, 0.86f}};
  const float* c = palette[((index % 8) + 8) % 8];
  return Eigen::Vector3f(c[0], c[1], c[2]);
}

namespace {

double body_scale(const RenderShape& s, const BodyPose& b) { return s.name == "sphere" && b.radius > 0 ? b.radius : 1.0; }

struct Basis {
  Eigen::Vector3d f, r, u;
};

Basis basis(const Camera& c)
{
  Basis b;
  b.f = (c.target - c.eye).normalized();
  Eigen::Vector3d up = c.up;
  if (std::abs(b.f.dot(up.normalized())) > 0.999) up = Eigen::Vector3d::UnitY();
  b.r = b.f.cross(up).normalized();
  b.u = b.r.cross(b.f);
  return b;
}

}  // namespace

Camera frame_camera(const std::vector<const Frames*>& frames, const std::vector<std::vector<const RenderShape*>>& shapes,
                    const CameraView& view, double aspect)
{
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  bool planar = true;
  for (std::size_t k = 0; k < frames.size(); ++k)
    for (const Frame& f : frames[k]->frames)
      for (const BodyPose& b : f.bodies) {
        const RenderShape& s = *shapes[k][std::size_t(b.shape)];
        planar = planar && s.planar;
        const double r = s.bounding_radius * body_scale(s, b);
        lo = lo.cwiseMin(b.position - Eigen::Vector3d::Constant(r));
        hi = hi.cwiseMax(b.position + Eigen::Vector3d::Constant(r));
      }
  if (!(lo.x() <= hi.x())) {
    lo = Eigen::Vector3d(-1, -1, 0);
    hi = Eigen::Vector3d(1, 1, 1);
  }
  Camera cam;
  cam.fov_deg = view.fov_deg;
  if (planar) {
    // Front view of the xy plane, y up, with some ground below y = 0.
    lo.y() = std::min(lo.y(), -0.1 * (hi.y() - std::min(lo.y(), 0.0)) - 0.2);
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    cam.orthographic = true;
    cam.target = Eigen::Vector3d(centre.x(), centre.y(), 0);
    cam.eye = cam.target + Eigen::Vector3d(0, 0, 10 + hi.z());
    cam.up = Eigen::Vector3d::UnitY();
    cam.ortho_height = 1.06 * std::max(hi.y() - lo.y(), (hi.x() - lo.x()) / aspect);
    return cam;
  }
  lo.z() = std::min(lo.z(), 0.0);
  // The spheres to fit: every drawn body's bounding sphere (at most about 200,000 of them, evenly
  // strided), and the bounding box's footprint on the ground.
  std::vector<Eigen::Vector4d> pts;
  std::size_t total = 0;
  for (std::size_t k = 0; k < frames.size(); ++k)
    for (const Frame& f : frames[k]->frames) total += f.bodies.size();
  const std::size_t stride = std::max<std::size_t>(1, total / 200000);
  std::size_t counter = 0;
  for (std::size_t k = 0; k < frames.size(); ++k)
    for (const Frame& f : frames[k]->frames)
      for (const BodyPose& b : f.bodies)
        if (counter++ % stride == 0) {
          const RenderShape& s = *shapes[k][std::size_t(b.shape)];
          const double r = s.bounding_radius * body_scale(s, b);
          pts.emplace_back(b.position.x(), b.position.y(), std::max(b.position.z(), r), r);
        }
  if (view.fit_share < 1 && pts.size() > 1) {
    // Keep the share of spheres nearest the median centre (stray bodies far off are left out).
    Eigen::Vector3d median;
    for (int k = 0; k < 3; ++k) {
      std::vector<double> c(pts.size());
      for (std::size_t i = 0; i < pts.size(); ++i) c[i] = pts[i][k];
      std::nth_element(c.begin(), c.begin() + std::ptrdiff_t(c.size() / 2), c.end());
      median[k] = c[c.size() / 2];
    }
    std::stable_sort(pts.begin(), pts.end(), [&](const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
      return (a.head<3>() - median).squaredNorm() < (b.head<3>() - median).squaredNorm();
    });
    pts.resize(std::max<std::size_t>(1, std::size_t(std::ceil(view.fit_share * double(pts.size())))));
    lo = hi = pts[0].head<3>();
    for (const Eigen::Vector4d& p : pts) {
      lo = lo.cwiseMin(p.head<3>() - Eigen::Vector3d::Constant(p[3]));
      hi = hi.cwiseMax(p.head<3>() + Eigen::Vector3d::Constant(p[3]));
    }
    lo.z() = std::min(lo.z(), 0.0);
  }
  const double az = view.azimuth_deg * kPi / 180, el = view.elevation_deg * kPi / 180;
  const Eigen::Vector3d dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  const double ty = std::tan(0.5 * view.fov_deg * kPi / 180), tx = ty * aspect;
  // Projected extent of the spheres, in units of the half image: x0, x1, y0, y1.
  auto extent = [&](const Camera& c, std::array<double, 4>& e) {
    const Basis b = basis(c);
    e = {1e300, -1e300, 1e300, -1e300};
    for (const Eigen::Vector4d& p : pts) {
      const Eigen::Vector3d q = p.head<3>() - c.eye;
      const double z = q.dot(b.f);
      if (z - p[3] <= 1e-6) return false;
      const double x = q.dot(b.r) / z / tx, y = q.dot(b.u) / z / ty, rx = p[3] / (z - p[3]) / tx,
                   ry = p[3] / (z - p[3]) / ty;
      e = {std::min(e[0], x - rx), std::max(e[1], x + rx), std::min(e[2], y - ry), std::max(e[3], y + ry)};
    }
    return true;
  };
  cam.target = 0.5 * (lo + hi);
  double dist = 1.0;
  for (int pass = 0; pass < 3; ++pass) {
    // Bisection on the distance: the smallest at which every sphere fits within 96% of the image.
    auto fits = [&](double d) {
      Camera c = cam;
      c.eye = cam.target + d * dir;
      std::array<double, 4> e{};
      return extent(c, e) && e[0] > -0.96 && e[1] < 0.96 && e[2] > -0.96 && e[3] < 0.96;
    };
    double near = 0.0, far = 1.0;
    while (!fits(far) && far < 1e7) far *= 2;
    for (int i = 0; i < 50; ++i) {
      const double mid = 0.5 * (near + far);
      (fits(mid) ? far : near) = mid;
    }
    dist = far;
    cam.eye = cam.target + dist * dir;
    // Centre the drawn extent: move the target across the view by the extent's offset.
    std::array<double, 4> e{};
    if (!extent(cam, e)) break;
    const Basis b = basis(cam);
    cam.target += b.r * (0.5 * (e[0] + e[1]) * tx * dist) + b.u * (0.5 * (e[2] + e[3]) * ty * dist);
    cam.eye = cam.target + dist * dir;
  }
  return cam;
}

namespace {

struct Projector {
  Basis b;
  Eigen::Vector3d eye;
  bool ortho;
  double focal = 1, scale = 1, cx = 0, cy = 0;
  // Screen x, y (pixels, y down), key (larger is nearer: 1/z in perspective, -z orthographic,
  // both affine in screen space), z (view depth).
  void project(const Eigen::Vector3d& p, double& sx, double& sy, double& key, double& z) const
  {
    const Eigen::Vector3d q = p - eye;
    z = q.dot(b.f);
    const double x = q.dot(b.r), y = q.dot(b.u);
    if (ortho) {
      sx = cx + scale * x;
      sy = cy - scale * y;
      key = -z;
    } else {
      sx = cx + focal * x / z;
      sy = cy - focal * y / z;
      key = 1.0 / z;
    }
  }
  // The ray through screen point (sx, sy): origin and direction with direction . f = 1.
  void ray(double sx, double sy, Eigen::Vector3d& o, Eigen::Vector3d& d) const
  {
    if (ortho) {
      o = eye + b.r * ((sx - cx) / scale) - b.u * ((sy - cy) / scale);
      d = b.f;
    } else {
      o = eye;
      d = b.f + b.r * ((sx - cx) / focal) - b.u * ((sy - cy) / focal);
    }
  }
  double depth_of_key(double key) const { return ortho ? -key : (key > 0 ? 1.0 / key : 1e300); }
};

struct ScreenBox {
  double x0 = 0, x1 = -1, y0 = 0, y1 = -1, z = 0;
  bool visible = false;
};

/// The pixels to visit for `box` in the band of rows y0 .. y1 of an image `w` pixels wide: from
/// x0 to x1 and y0 to y1, inclusive (empty when a start is past its end).
struct PixelSpan {
  int x0, x1, y0, y1;
};
PixelSpan pixel_span(const ScreenBox& box, int y0, int y1, int w)
{
  return {int(std::clamp(box.x0, 0.0, double(w))), int(std::clamp(box.x1 + 1, -1.0, double(w - 1))),
          int(std::clamp(box.y0, double(y0), double(y1))), int(std::clamp(box.y1 + 1, double(y0 - 1), double(y1 - 1)))};
}

}  // namespace

Image render_frame(const Frame& frame, const std::vector<const RenderShape*>& shapes, const Camera& camera,
                   const RenderOptions& options)
{
  const int ss = std::max(1, options.supersample);
  const int W = options.width * ss, H = options.height * ss;
  Projector pj;
  pj.b = basis(camera);
  pj.eye = camera.eye;
  pj.ortho = camera.orthographic;
  pj.cx = 0.5 * W;
  pj.cy = 0.5 * H;
  pj.focal = 0.5 * H / std::tan(0.5 * camera.fov_deg * kPi / 180);
  pj.scale = H / camera.ortho_height;
  const double near = camera.orthographic ? -1e300 : 1e-3;

  // Light towards the upper left behind the camera, and a weaker fill from the right.
  const Eigen::Vector3d key_light =
      (-0.45 * pj.b.r + (pj.ortho ? Eigen::Vector3d(0.7 * pj.b.u) : Eigen::Vector3d(0.9 * Eigen::Vector3d::UnitZ())) -
       0.5 * pj.b.f)
          .normalized();
  const Eigen::Vector3d fill_light = (0.7 * pj.b.r - 0.3 * pj.b.f + 0.2 * pj.b.u).normalized();
  auto shade = [&](const Eigen::Vector3f& c, const Eigen::Vector3d& n) {
    const double k = 0.32 + 0.62 * std::max(0.0, n.dot(key_light)) + 0.16 * std::max(0.0, n.dot(fill_light));
    return Eigen::Vector3f(c * float(k));
  };

  // The framed distance sets the ground's tile size and fog.
  const double view_distance = (camera.target - camera.eye).norm();
  double tile = options.ground_tile;
  if (!(tile > 0)) {
    const double want = (pj.ortho ? camera.ortho_height : view_distance * std::tan(0.5 * camera.fov_deg * kPi / 180)) / 5;
    const double p10 = std::pow(10.0, std::floor(std::log10(want)));
    tile = want / p10 < 2 ? p10 : want / p10 < 5 ? 2 * p10 : 5 * p10;
  }

  // Screen boxes of the bodies' bounding spheres: bands skip bodies outside them.
  const std::size_t n = frame.bodies.size();
  std::vector<ScreenBox> boxes(n);
  for (std::size_t i = 0; i < n; ++i) {
    const BodyPose& b = frame.bodies[i];
    const RenderShape& s = *shapes[std::size_t(b.shape)];
    const double r = std::max(s.bounding_radius * body_scale(s, b), b.radius) * 1.001;
    double sx, sy, key, z;
    pj.project(b.position, sx, sy, key, z);
    ScreenBox& box = boxes[i];
    box.z = z;
    if (!pj.ortho && z - r <= near) continue;
    const double rp = pj.ortho ? pj.scale * r : pj.focal * r / (z - r);
    box = ScreenBox{sx - rp, sx + rp, sy - rp, sy + rp, z, true};
    if (box.x1 < 0 || box.x0 > W || box.y1 < 0 || box.y0 > H) box.visible = false;
  }
  // Contact shadows (perspective views): a soft dark disc on the ground under each body, of
  // radius 0.8 x its bounding radius, darker the nearer the body is to the ground (none from 3
  // radii up). Here: the screen boxes of those discs.
  std::vector<ScreenBox> shadows(n);
  for (std::size_t i = 0; i < n && options.shadows && !pj.ortho && pj.eye.z() > 0; ++i) {
    const BodyPose& b = frame.bodies[i];
    const RenderShape& s = *shapes[std::size_t(b.shape)];
    const double r = 0.8 * s.bounding_radius * body_scale(s, b);
    if (!(b.position.z() < 3 * r + r) || !boxes[i].visible) continue;
    ScreenBox& box = shadows[i];
    box = ScreenBox{1e300, -1e300, 1e300, -1e300, 0, true};
    for (int k = 0; k < 4 && box.visible; ++k) {
      const Eigen::Vector3d p(b.position.x() + (k & 1 ? r : -r), b.position.y() + (k & 2 ? r : -r), 0);
      double sx, sy, key, z;
      pj.project(p, sx, sy, key, z);
      if (z <= 1e-3) box.visible = false;
      box = ScreenBox{std::min(box.x0, sx), std::max(box.x1, sx), std::min(box.y0, sy), std::max(box.y1, sy), 0, box.visible};
    }
    if (box.x1 < 0 || box.x0 > W || box.y1 < 0 || box.y0 > H) box.visible = false;
  }
  std::vector<std::size_t> sphere_order(n);
  std::iota(sphere_order.begin(), sphere_order.end(), std::size_t(0));
  std::stable_sort(sphere_order.begin(), sphere_order.end(),
                   [&](std::size_t a, std::size_t c) { return boxes[a].z > boxes[c].z; });

  std::vector<float> rgb(std::size_t(W) * std::size_t(H) * 3);
  std::vector<double> depth(std::size_t(W) * std::size_t(H));
  const Eigen::Vector3f sky_top(0.62f, 0.74f, 0.88f), sky_horizon(0.90f, 0.93f, 0.96f);
  const Eigen::Vector3f tile_a(0.74f, 0.74f, 0.72f), tile_b(0.66f, 0.66f, 0.64f);
  const int band_rows = 16 * ss;
  const int bands = (H + band_rows - 1) / band_rows;

  parallel_for(
      std::size_t(bands),
      [&](std::size_t band) {
        const int y0 = int(band) * band_rows, y1 = std::min(H, y0 + band_rows);
        // Background: sky, and the ground where the pixel's ray meets it.
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < W; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(W) + std::size_t(x);
            Eigen::Vector3d o, d;
            pj.ray(x + 0.5, y + 0.5, o, d);
            Eigen::Vector3f c;
            double key = -std::numeric_limits<double>::infinity();
            if (pj.ortho) {
              c = sky_horizon;
              if (o.y() < 0) {
                c = (int(std::floor(o.x() / tile)) & 1) ? tile_a : tile_b;
                c *= 0.9f;
              }
            } else {
              const double up = d.normalized().z();
              c = sky_horizon + (sky_top - sky_horizon) * float(std::clamp(up * 2.5, 0.0, 1.0));
              const double t = d.z() < 0 && o.z() > 0 ? -o.z() / d.z() : -1.0;
              if (t > 0 && t < 1e6 * view_distance) {  // farther is all fog
                const Eigen::Vector3d hit = o + t * d;
                const bool odd = ((long long)(std::floor(hit.x() / tile)) + (long long)(std::floor(hit.y() / tile))) & 1;
                const Eigen::Vector3f g = shade(odd ? tile_a : tile_b, Eigen::Vector3d::UnitZ());
                const float fog = float(1.0 - std::exp(-t * d.norm() / (4.0 * view_distance)));
                c = g + (sky_horizon - g) * fog;
                key = 1.0 / t;
              }
            }
            depth[p] = key;
            std::memcpy(&rgb[3 * p], c.data(), 3 * sizeof(float));
          }

        // Contact shadows darken the ground (pixels with a finite key: ground, not sky).
        for (std::size_t i = 0; i < n; ++i) {
          const ScreenBox& box = shadows[i];
          if (!box.visible || box.y1 < y0 || box.y0 > y1) continue;
          const BodyPose& b = frame.bodies[i];
          const RenderShape& s = *shapes[std::size_t(b.shape)];
          const double r = 0.8 * s.bounding_radius * body_scale(s, b);
          const double strength = 0.45 * std::max(0.0, 1.0 - std::max(0.0, b.position.z() - r) / (3 * r));
          const PixelSpan span = pixel_span(box, y0, y1, W);
          for (int y = span.y0; y <= span.y1; ++y)
            for (int x = span.x0; x <= span.x1; ++x) {
              const std::size_t p = std::size_t(y) * std::size_t(W) + std::size_t(x);
              if (!(depth[p] > 0)) continue;
              Eigen::Vector3d o, d;
              pj.ray(x + 0.5, y + 0.5, o, d);
              const Eigen::Vector3d hit = o + (1.0 / depth[p]) * d;  // depth is 1/t on the ground
              const double q = (hit.head<2>() - b.position.head<2>()).squaredNorm() / (r * r);
              if (q >= 1) continue;
              const float keep = float(1.0 - strength * (1 - q) * (1 - q));
              for (int k = 0; k < 3; ++k) rgb[3 * p + std::size_t(k)] *= keep;
            }
        }

        // Opaque bodies.
        std::vector<double> sx, sy, key, z;
        std::vector<Eigen::Vector3d> world;
        for (std::size_t i = 0; i < n; ++i) {
          const ScreenBox& box = boxes[i];
          if (!box.visible || box.y1 < y0 || box.y0 > y1) continue;
          const BodyPose& b = frame.bodies[i];
          const RenderShape& s = *shapes[std::size_t(b.shape)];
          const double scale = body_scale(s, b);
          const Eigen::Matrix3d rot = b.orientation.toRotationMatrix() * scale;
          const std::size_t nv = s.vertices.size();
          sx.resize(nv);
          sy.resize(nv);
          key.resize(nv);
          z.resize(nv);
          world.resize(nv);
          for (std::size_t v = 0; v < nv; ++v) {
            world[v] = rot * s.vertices[v].cast<double>() + b.position;
            pj.project(world[v], sx[v], sy[v], key[v], z[v]);
          }
          const Eigen::Vector3f colour = body_colour(b.body);
          for (const auto& t : s.triangles) {
            const std::size_t a = std::size_t(t[0]), c1 = std::size_t(t[1]), c2 = std::size_t(t[2]);
            if (z[a] <= near || z[c1] <= near || z[c2] <= near) continue;
            const Eigen::Vector3d nrm = (world[c1] - world[a]).cross(world[c2] - world[a]);
            const Eigen::Vector3d to_eye = pj.ortho ? Eigen::Vector3d(-pj.b.f) : Eigen::Vector3d(pj.eye - world[a]);
            if (nrm.dot(to_eye) <= 0) continue;  // facing away
            const double area = (sx[c1] - sx[a]) * (sy[c2] - sy[a]) - (sx[c2] - sx[a]) * (sy[c1] - sy[a]);
            if (area == 0) continue;
            // Clamped in floating point first: a vertex just in front of the camera projects far out.
            const int bx0 = int(std::floor(std::clamp(std::min({sx[a], sx[c1], sx[c2]}), 0.0, double(W))));
            const int bx1 = int(std::ceil(std::clamp(std::max({sx[a], sx[c1], sx[c2]}), -1.0, double(W - 1))));
            const int by0 = int(std::floor(std::clamp(std::min({sy[a], sy[c1], sy[c2]}), double(y0), double(y1))));
            const int by1 = int(std::ceil(std::clamp(std::max({sy[a], sy[c1], sy[c2]}), double(y0 - 1), double(y1 - 1))));
            if (bx0 > bx1 || by0 > by1) continue;
            const Eigen::Vector3f c = shade(colour, nrm.normalized());
            const double inv = 1.0 / area;
            for (int y = by0; y <= by1; ++y) {
              const double py = y + 0.5;
              for (int x = bx0; x <= bx1; ++x) {
                const double px = x + 0.5;
                const double w0 = ((sx[c1] - px) * (sy[c2] - py) - (sx[c2] - px) * (sy[c1] - py)) * inv;
                const double w1 = ((sx[c2] - px) * (sy[a] - py) - (sx[a] - px) * (sy[c2] - py)) * inv;
                const double w2 = 1.0 - w0 - w1;
                if (w0 < 0 || w1 < 0 || w2 < 0) continue;
                const double k = w0 * key[a] + w1 * key[c1] + w2 * key[c2];
                const std::size_t p = std::size_t(y) * std::size_t(W) + std::size_t(x);
                if (k > depth[p]) {
                  depth[p] = k;
                  std::memcpy(&rgb[3 * p], c.data(), 3 * sizeof(float));
                }
              }
            }
          }
        }

        // Collision spheres, far to near, blended over what is in front of them.
        if (!options.spheres) return;
        const Eigen::Vector3f sphere_colour(0.55f, 0.72f, 1.0f);
        for (std::size_t i : sphere_order) {
          const ScreenBox& box = boxes[i];
          if (!box.visible || box.y1 < y0 || box.y0 > y1) continue;
          const BodyPose& b = frame.bodies[i];
          const RenderShape& s = *shapes[std::size_t(b.shape)];
          const double r = b.radius > 0 ? b.radius : s.table_sphere_radius;
          if (!(r > 0)) continue;
          const PixelSpan span = pixel_span(box, y0, y1, W);
          for (int y = span.y0; y <= span.y1; ++y)
            for (int x = span.x0; x <= span.x1; ++x) {
              Eigen::Vector3d o, d;
              pj.ray(x + 0.5, y + 0.5, o, d);
              const Eigen::Vector3d oc = o - b.position;
              const double qa = d.squaredNorm(), qb = oc.dot(d), qc = oc.squaredNorm() - r * r;
              const double disc = qb * qb - qa * qc;
              if (disc < 0) continue;
              const double t = (-qb - std::sqrt(disc)) / qa;
              if (!pj.ortho && t <= 0) continue;
              const std::size_t p = std::size_t(y) * std::size_t(W) + std::size_t(x);
              const Eigen::Vector3d hit = o + t * d;
              if ((hit - pj.eye).dot(pj.b.f) >= pj.depth_of_key(depth[p])) continue;
              const Eigen::Vector3d nrm = (hit - b.position) / r;
              const double facing = std::abs(nrm.dot(d.normalized()));
              const double alpha = options.sphere_alpha + (1 - options.sphere_alpha) * 0.6 * (1 - facing) * (1 - facing);
              const Eigen::Vector3f c = shade(sphere_colour, nrm);
              for (int k = 0; k < 3; ++k)
                rgb[3 * p + std::size_t(k)] = float((1 - alpha) * rgb[3 * p + std::size_t(k)] + alpha * c[k]);
            }
        }
      },
      options.threads);

  Image img;
  img.width = options.width;
  img.height = options.height;
  img.rgb.resize(std::size_t(img.width) * std::size_t(img.height) * 3);
  const float norm = 1.0f / float(ss * ss);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int k = 0; k < 3; ++k) {
        float sum = 0;
        for (int j = 0; j < ss; ++j)
          for (int i = 0; i < ss; ++i)
            sum += rgb[3 * (std::size_t(y * ss + j) * std::size_t(W) + std::size_t(x * ss + i)) + std::size_t(k)];
        img.rgb[std::size_t(3 * (y * img.width + x) + k)] = std::uint8_t(std::clamp(sum * norm * 255.0f + 0.5f, 0.0f, 255.0f));
      }
  return img;
}

namespace {

void draw_label(Image& img, int x0, int y0, const std::string& text)
{
  std::vector<char> buf(text.begin(), text.end());
  buf.push_back('\0');
  std::vector<char> verts(buf.size() * 1024 + 64);
  const int quads = stb_easy_font_print(0.0f, 0.0f, buf.data(), nullptr, verts.data(), int(verts.size()));
  const int scale = 2;
  for (int q = 0; q < quads; ++q) {
    float qx0 = 1e9f, qy0 = 1e9f, qx1 = -1e9f, qy1 = -1e9f;
    for (int v = 0; v < 4; ++v) {
      float vx = 0, vy = 0;
      const char* vp = verts.data() + (std::size_t(q) * 4 + std::size_t(v)) * 16;
      std::memcpy(&vx, vp, sizeof vx);
      std::memcpy(&vy, vp + 4, sizeof vy);
      qx0 = std::min(qx0, vx);
      qx1 = std::max(qx1, vx);
      qy0 = std::min(qy0, vy);
      qy1 = std::max(qy1, vy);
    }
    for (int y = y0 + int(qy0) * scale; y < y0 + int(qy1) * scale; ++y)
      for (int x = x0 + int(qx0) * scale; x < x0 + int(qx1) * scale; ++x)
        if (x >= 0 && y >= 0 && x < img.width && y < img.height)
          std::memset(&img.rgb[std::size_t(3 * (y * img.width + x))], 30, 3);
  }
}

}  // namespace

Image side_by_side(const Image& left, const Image& right, const std::string& left_label, const std::string& right_label)
{
  Image out;
  out.width = left.width + right.width;
  out.height = std::max(left.height, right.height);
  out.rgb.assign(std::size_t(out.width) * std::size_t(out.height) * 3, 255);
  for (int y = 0; y < out.height; ++y) {
    if (y < left.height)
      std::memcpy(&out.rgb[std::size_t(3 * y * out.width)], left.pixel(0, y), std::size_t(3 * left.width));
    if (y < right.height)
      std::memcpy(&out.rgb[std::size_t(3 * (y * out.width + left.width))], right.pixel(0, y),
                  std::size_t(3 * right.width));
  }
  // A one-pixel divider.
  for (int y = 0; y < out.height; ++y) std::memset(&out.rgb[std::size_t(3 * (y * out.width + left.width))], 40, 3);
  draw_label(out, 8, 8, left_label);
  draw_label(out, left.width + 8, 8, right_label);
  return out;
}

bool write_png(const std::string& path, const Image& image)
{
  return stbi_write_png(path.c_str(), image.width, image.height, 3, image.rgb.data(), image.width * 3) != 0;
}

bool write_gif(const std::string& path, const std::vector<Image>& images, int delay_cs, std::string& error)
{
  if (images.empty()) {
    error = "no frames for the GIF";
    return false;
  }
  int code = 0;
  GifFileType* gif = EGifOpenFileName(path.c_str(), false, &code);
  if (!gif) {
    error = path + ": " + GifErrorString(code);
    return false;
  }
  auto fail = [&](const char* what) {
    error = path + ": " + what + ": " + GifErrorString(gif->Error);
    int ignored = 0;
    EGifCloseFile(gif, &ignored);
    return false;
  };
  EGifSetGifVersion(gif, true);
  const int w = images[0].width, h = images[0].height;
  if (EGifPutScreenDesc(gif, w, h, 8, 0, nullptr) == GIF_ERROR) return fail("screen descriptor");
  // Loop for ever (the NETSCAPE2.0 application extension).
  unsigned char loop[3] = {1, 0, 0};
  if (EGifPutExtensionLeader(gif, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
      EGifPutExtensionBlock(gif, 11, "NETSCAPE2.0") == GIF_ERROR || EGifPutExtensionBlock(gif, 3, loop) == GIF_ERROR ||
      EGifPutExtensionTrailer(gif) == GIF_ERROR)
    return fail("loop extension");
  std::vector<GifByteType> r(std::size_t(w * h)), g(r.size()), b(r.size()), idx(r.size());
  for (const Image& img : images) {
    if (img.width != w || img.height != h) return fail("frames differ in size");
    for (std::size_t p = 0; p < r.size(); ++p) {
      r[p] = img.rgb[3 * p];
      g[p] = img.rgb[3 * p + 1];
      b[p] = img.rgb[3 * p + 2];
    }
    int colours = 256;
    ColorMapObject* map = GifMakeMapObject(256, nullptr);
    if (!map) return fail("colour map");
    if (GifQuantizeBuffer(unsigned(w), unsigned(h), &colours, r.data(), g.data(), b.data(), idx.data(), map->Colors) ==
        GIF_ERROR) {
      GifFreeMapObject(map);
      return fail("quantize");
    }
    GraphicsControlBlock gcb{};
    gcb.DisposalMode = DISPOSE_DO_NOT;
    gcb.DelayTime = delay_cs;
    gcb.TransparentColor = NO_TRANSPARENT_COLOR;
    GifByteType ext[4];
    const std::size_t len = EGifGCBToExtension(&gcb, ext);
    const bool ok = EGifPutExtension(gif, GRAPHICS_EXT_FUNC_CODE, int(len), ext) != GIF_ERROR &&
                    EGifPutImageDesc(gif, 0, 0, w, h, false, map) != GIF_ERROR;
    GifFreeMapObject(map);
    if (!ok) return fail("image descriptor");
    for (int y = 0; y < h; ++y)
      if (EGifPutLine(gif, &idx[std::size_t(y * w)], w) == GIF_ERROR) return fail("pixels");
  }
  if (EGifCloseFile(gif, &code) == GIF_ERROR) {
    error = path + ": " + GifErrorString(code);
    return false;
  }
  return true;
}

}  // namespace statsim::tools::render
