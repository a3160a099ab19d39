#include "mesh/mesh_commands.hpp"
#include "common/commands.hpp"

#include "mesh/decimate.hpp"
#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "mesh/shapes.hpp"
#include "mesh/spheres.hpp"

#include <CLI/CLI.hpp>
#include <meshoptimizer.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <ostream>
#include <vector>

namespace statsim::tools {

namespace {

// The statsim command as documented in generated files (run from the repository root).
constexpr const char* kStatsim = "build/bin/statsim";

std::string quote(const std::string& s)
{
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./,+=") ==
                      std::string::npos) {
    return s;
  }
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string fmt(const char* format, double x)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x == 0.0 ? 0.0 : x);
  std::string s = buf;
  // "-0.000" -> "0.000": a value that rounds to zero has no sign.
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

// Rounding noise (below 1e-12 of `scale`) shown as 0 in file headers.
Eigen::Vector3d clean(const Eigen::Vector3d& v, double scale)
{
  Eigen::Vector3d r = v;
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(r[i]) < 1e-12 * scale) r[i] = 0.0;
  }
  return r;
}

std::string vec(const Eigen::Vector3d& v, const char* format = "%.6g")
{
  return "(" + fmt(format, v.x()) + ", " + fmt(format, v.y()) + ", " + fmt(format, v.z()) + ")";
}

std::string basename(const std::string& path) { return std::filesystem::path(path).filename().string(); }

std::string meshopt_version()
{
  return std::to_string(MESHOPTIMIZER_VERSION / 1000) + "." + std::to_string(MESHOPTIMIZER_VERSION % 1000 / 10);
}

int fail(std::ostream& err, const std::string& command, const std::string& message)
{
  err << "statsim mesh " << command << ": " << message << "\n";
  return 1;
}

std::vector<std::string> summary(const TriMesh& mesh, const MassProperties& mp)
{
  return {std::to_string(mesh.vertices.size()) + " vertices, " + std::to_string(mesh.triangles.size()) +
            " triangles; closed, counter-clockwise seen from outside.",
          "Volume " + fmt("%.9g", mp.volume) + "; centre of mass " + vec(clean(mp.com, mp.bounding_radius)) + "; bounding radius " +
            fmt("%.6g", mp.bounding_radius) + " (about the centre of mass).",
          "Principal moments per unit density (ascending) " + vec(mp.principal_moments, "%.6g") + "."};
}

int write_obj(const std::string& command, const std::string& path, const TriMesh& mesh,
              const std::vector<std::string>& comments, std::ostream& err)
{
  MeshError e;
  if (!validate_mesh(mesh, basename(path), e)) return fail(err, command, "internal error, generated mesh invalid: " + e.message);
  if (!write_file_atomic(path, obj_text(mesh, comments), e)) return fail(err, command, e.message);
  return 0;
}

}  // namespace

int mesh_info(const std::string& file, double density, std::ostream& out, std::ostream& err, double scale,
              bool units_given)
{
  if (!(density > 0.0) || !std::isfinite(density)) return fail(err, "info", "--density must be positive");
  if (!(scale > 0.0) || !std::isfinite(scale)) return fail(err, "info", "--scale must be positive");
  TriMesh mesh;
  MeshError e;
  if (!load_mesh(file, mesh, e)) return fail(err, "info", e.message);
  if (scale != 1.0) scale_mesh(mesh, scale);
  if (!check_mesh_size(mesh, file, units_given, e)) return fail(err, "info", e.message);
  const MassProperties mp = compute_mass_properties(mesh, density);
  Eigen::Vector3d lo, hi;
  bounding_box(mesh, lo, hi);
  const Eigen::Matrix3d& r = mp.principal_axes;
  out << "file:               " << file << "\n"
      << "vertices:           " << mesh.vertices.size() << "\n"
      << "triangles:          " << mesh.triangles.size() << "\n"
      << "surface:            closed, manifold, consistently wound, outward normals\n"
      << "bounding box:       " << vec(lo, "%.9g") << " to " << vec(hi, "%.9g") << "\n"
      << "volume:             " << fmt("%.9g", mp.volume) << "\n"
      << "density:            " << fmt("%.9g", density) << "\n"
      << "mass:               " << fmt("%.9g", mp.mass) << "\n"
      << "centre of mass:     " << vec(mp.com, "%.9g") << "\n"
      << "inertia about COM:  " << vec(mp.inertia.row(0).transpose(), "%.9g") << "\n"
      << "                    " << vec(mp.inertia.row(1).transpose(), "%.9g") << "\n"
      << "                    " << vec(mp.inertia.row(2).transpose(), "%.9g") << "\n"
      << "principal moments:  " << vec(mp.principal_moments, "%.9g") << "\n"
      << "principal axes:     e1 " << vec(r.col(0), "%.9f") << "\n"
      << "                    e2 " << vec(r.col(1), "%.9f") << "\n"
      << "                    e3 " << vec(r.col(2), "%.9f") << "\n"
      << "bounding radius:    " << fmt("%.9g", mp.bounding_radius) << "\n";
  return 0;
}

int mesh_decimate(const std::string& in, const std::string& out_file, int vertices, std::ostream& out, std::ostream& err)
{
  TriMesh mesh;
  MeshError e;
  if (!load_obj(in, mesh, e)) return fail(err, "decimate", e.message);
  Decimation d;
  if (!decimate_mesh(mesh, vertices, d, e)) return fail(err, "decimate", in + ": " + e.message);
  const MassProperties before = compute_mass_properties(mesh);
  const MassProperties after = compute_mass_properties(d.mesh);
  std::vector<std::string> c = {
    basename(out_file) + ": " + in + " decimated to about " + std::to_string(vertices) +
      " vertices. Generated by statsim -- do not edit.",
    "Regenerate: " + std::string(kStatsim) + " mesh decimate --in " + quote(in) + " --out " + quote(out_file) +
      " --vertices " + std::to_string(vertices),
    "Method: meshoptimizer " + meshopt_version() +
      " meshopt_simplify (quadric-error edge collapses that keep the topology), no error limit,",
    "  target " + std::to_string(d.target_index_count) + " indices (best of target triangle counts 2V-4 +- 20).",
    "meshoptimizer's error: " + fmt("%.6g", static_cast<double>(d.relative_error)) + " relative to the mesh extent = " +
      fmt("%.6g", static_cast<double>(d.absolute_error)) + " in mesh units.",
    "Input: " + std::to_string(mesh.vertices.size()) + " vertices, " + std::to_string(mesh.triangles.size()) +
      " triangles, volume " + fmt("%.9g", before.volume) + ". Output vertices are input vertices, in input order;",
    "  same frame and units as the input (not re-centred).",
  };
  const double ratio = after.volume / before.volume;
  for (auto& s : summary(d.mesh, after)) c.push_back(s);
  c.push_back("Volume " + fmt("%.4f", 100.0 * ratio) + "% of the input's; centre of mass moved " +
              fmt("%.3g", (after.com - before.com).norm()) + ".");
  if (int rc = write_obj("decimate", out_file, d.mesh, c, err)) return rc;
  out << out_file << ": " << d.mesh.vertices.size() << " vertices, " << d.mesh.triangles.size()
      << " triangles, meshoptimizer error " << d.relative_error << " (relative), " << d.absolute_error
      << " (absolute)\n";
  return 0;
}

int mesh_spheres(const std::string& in, const std::string& out_file, int count, int resolution, std::ostream& out,
                 std::ostream& err)
{
  TriMesh mesh;
  MeshError e;
  if (!load_obj(in, mesh, e)) return fail(err, "spheres", e.message);
  SphereFit fit;
  if (!fit_spheres(mesh, count, resolution, fit, e)) return fail(err, "spheres", e.message);
  const MassProperties mp = compute_mass_properties(mesh);
  std::string cmd = std::string(kStatsim) + " mesh spheres --in " + quote(in) + " --count " + std::to_string(count) +
                    " --out " + quote(out_file);
  if (resolution != 64) cmd += " --resolution " + std::to_string(resolution);
  const std::vector<std::string> c = {
    basename(out_file) + ": " + std::to_string(count) + " spheres approximating " + in +
      ". Generated by statsim -- do not edit.",
    "Regenerate: " + cmd,
    "Frame and units: those of the input mesh (" + std::to_string(mesh.vertices.size()) + " vertices, " +
      std::to_string(mesh.triangles.size()) + " triangles, volume " + fmt("%.9g", mp.volume) + ", centre of mass " +
      vec(clean(mp.com, mp.bounding_radius)) + ").",
    "Method (tools/mesh/spheres.hpp): voxelize the solid (cell h = longest extent / " + std::to_string(resolution) +
      " = " + fmt("%.6g", fit.cell) + ", inside by winding number);",
    "  sample the surface (4 points per triangle, area-weighted); area-weighted k-means of the samples into " +
      std::to_string(count) + " clusters",
    "  (k-means++ seeding, fixed seed, 16 restarts); a sphere per cluster at the inside cell nearest its centroid,",
    "  radius maximizing covered inside minus covered outside cells; then coordinate descent on all centres and",
    "  radii minimizing vol(union xor solid) + integral over the surface of the distance to the union's",
    "  boundary (both volumes), so the union covers the solid and its boundary follows the surface. Rounded to 6 decimals.",
    "Fit (voxel estimates): the union covers " + fmt("%.1f", 100.0 * fit.coverage) +
      "% of the solid's volume and protrudes from it by " + fmt("%.1f", 100.0 * fit.protrusion) + "% of that volume;",
    "  deepest protrusion " + fmt("%.3g", fit.max_protrusion) + " (about " +
      fmt("%.1f", 100.0 * fit.max_protrusion / mp.bounding_radius) + "% of the bounding radius " +
      fmt("%.4g", mp.bounding_radius) + "); surface to union boundary distance",
    "  RMS " + fmt("%.3g", fit.surface_rms) + ", mean " + fmt("%.3g", fit.surface_mean_abs) +
      " (area-weighted over triangle centroids). Voxel volume / exact volume " +
      fmt("%.4f", fit.voxel_volume / mp.volume) + ".",
    "  The surface sticks out of the union by up to " + fmt("%.3g", fit.max_uncovered) + " (largest vertex distance).",
    "Columns: centre x, centre y, centre z, radius.",
  };
  std::string text;
  for (const auto& line : c) text += "# " + line + "\n";
  for (const auto& s : fit.spheres) {
    text += fmt("%.6f", s.centre.x()) + " " + fmt("%.6f", s.centre.y()) + " " + fmt("%.6f", s.centre.z()) + " " +
            fmt("%.6f", s.radius) + "\n";
  }
  if (!write_file_atomic(out_file, text, e)) return fail(err, "spheres", e.message);
  out << out_file << ": " << count << " spheres, coverage " << fmt("%.1f", 100.0 * fit.coverage) << "%, protrusion "
      << fmt("%.1f", 100.0 * fit.protrusion) << "%, deepest protrusion " << fmt("%.3g", fit.max_protrusion)
      << ", surface RMS " << fmt("%.3g", fit.surface_rms) << "\n";
  return 0;
}

int mesh_box(const std::array<double, 3>& size, const std::string& out_file, std::ostream& out, std::ostream& err)
{
  for (double s : size) {
    if (!(s > 0.0) || !std::isfinite(s)) return fail(err, "box", "--size values must be positive and finite");
  }
  const Eigen::Vector3d sz(size[0], size[1], size[2]);
  const TriMesh mesh = make_box(sz);
  const MassProperties mp = compute_mass_properties(mesh);
  const std::string dims = format_number(size[0]) + "," + format_number(size[1]) + "," + format_number(size[2]);
  std::vector<std::string> c = {
    basename(out_file) + ": a " + format_number(size[0]) + " x " + format_number(size[1]) + " x " +
      format_number(size[2]) + " box centred at the origin, faces normal to the axes. Generated by statsim -- do not edit.",
    "Regenerate: " + std::string(kStatsim) + " mesh box --size " + dims + " --out " + quote(out_file),
    "Reference shape in Bullet: btBoxShape with half extents " + vec(0.5 * sz, "%.12g") + ".",
  };
  for (auto& s : summary(mesh, mp)) c.push_back(s);
  if (int rc = write_obj("box", out_file, mesh, c, err)) return rc;
  out << out_file << ": box " << dims << ", " << mesh.vertices.size() << " vertices, " << mesh.triangles.size()
      << " triangles\n";
  return 0;
}

int mesh_wedge(double leg_x, double leg_y, double depth, const std::string& out_file, std::ostream& out,
               std::ostream& err)
{
  for (double s : {leg_x, leg_y, depth}) {
    if (!(s > 0.0) || !std::isfinite(s)) return fail(err, "wedge", "--legs and --depth must be positive and finite");
  }
  const TriMesh mesh = make_wedge(leg_x, leg_y, depth);
  const MassProperties mp = compute_mass_properties(mesh);
  const std::string legs = format_number(leg_x) + "," + format_number(leg_y);
  const std::string command =
    std::string(kStatsim) + " mesh wedge --legs " + legs + " --depth " + format_number(depth) + " --out " + quote(out_file);
  std::vector<std::string> c = {
    basename(out_file) + ": generated by " + command + " -- do not edit.",
    "A wedge (right triangular prism): the right triangle with legs " + format_number(leg_x) + " (along x) and " +
      format_number(leg_y) + " (along y), extruded " + format_number(depth) + " along z, centre of mass at the origin.",
    "Made as a held-out shape: no table, setting or test was tuned on it. Its convex hull is itself: five faces,",
    "  each of which the centre of mass projects inside (a right triangle's centroid projects inside every side).",
  };
  for (auto& s : summary(mesh, mp)) c.push_back(s);
  if (int rc = write_obj("wedge", out_file, mesh, c, err)) return rc;
  out << out_file << ": wedge " << legs << " x " << format_number(depth) << ", " << mesh.vertices.size() << " vertices, "
      << mesh.triangles.size() << " triangles\n";
  return 0;
}

int mesh_nut(double across_corners, double thickness, double hole_diameter, int hole_segments,
             const std::string& out_file, std::ostream& out, std::ostream& err)
{
  for (double s : {across_corners, thickness, hole_diameter}) {
    if (!(s > 0.0) || !std::isfinite(s))
      return fail(err, "nut", "--across-corners, --thickness and --hole must be positive and finite");
  }
  const double across_flats = across_corners * std::sqrt(3.0) / 2.0;
  if (!(hole_diameter < across_flats)) return fail(err, "nut", "--hole must be narrower than the flats (" + format_number(across_flats) + ")");
  if (hole_segments < 12 || hole_segments % 12 != 0) return fail(err, "nut", "--hole-segments must be a positive multiple of 12");
  const TriMesh mesh = make_nut(across_corners, thickness, hole_diameter, hole_segments);
  const MassProperties mp = compute_mass_properties(mesh);
  const std::string command = std::string(kStatsim) + " mesh nut --across-corners " + format_number(across_corners) +
                              " --thickness " + format_number(thickness) + " --hole " + format_number(hole_diameter) +
                              " --hole-segments " + std::to_string(hole_segments) + " --out " + quote(out_file);
  std::vector<std::string> c = {
    basename(out_file) + ": generated by " + command + " -- do not edit.",
    "A hexagonal nut: a regular hexagonal prism " + format_number(across_corners) + " across the corners (" +
      fmt("%.6g", across_flats) + " across the flats), " + format_number(thickness) + " thick along z, with a round hole",
    "  of diameter " + format_number(hole_diameter) + " along z (" + std::to_string(hole_segments) +
      "-gon), centre of mass at the origin, a corner on +x.",
    "Made as a test shape with many equivalent rest poses: its six side faces are one family under its symmetry,",
    "  and its two flat faces another.",
  };
  for (auto& s : summary(mesh, mp)) c.push_back(s);
  if (int rc = write_obj("nut", out_file, mesh, c, err)) return rc;
  out << out_file << ": nut " << format_number(across_corners) << " x " << format_number(thickness) << ", hole "
      << format_number(hole_diameter) << ", " << mesh.vertices.size() << " vertices, " << mesh.triangles.size()
      << " triangles\n";
  return 0;
}

int mesh_lshape(const std::string& out_file, std::ostream& out, std::ostream& err)
{
  const TriMesh mesh = make_lshape();
  const MassProperties mp = compute_mass_properties(mesh);
  const auto boxes = lshape_boxes();
  std::vector<std::string> c = {
    basename(out_file) + ": the L-shape. Generated by statsim -- do not edit.",
    "Regenerate: " + std::string(kStatsim) + " mesh lshape --out " + quote(out_file),
    "Dimensions (metres; the paper gives none): an L profile in the xy plane extruded 0.05 along z:",
    "  a 0.20 x 0.05 x 0.05 foot along x and a 0.05 x 0.10 x 0.05 upright standing on its -x end, so the L",
    "  is 0.20 wide, 0.15 tall and 0.05 thick everywhere. Placed with its centre of mass at the origin.",
    "Reference shape in Bullet: btCompoundShape of two btBoxShapes (no rotation):",
    "  foot:    centre " + vec(boxes[0].centre, "%.12g") + ", half extents " + vec(boxes[0].half_extents, "%.12g") + ";",
    "  upright: centre " + vec(boxes[1].centre, "%.12g") + ", half extents " + vec(boxes[1].half_extents, "%.12g") + ".",
  };
  for (auto& s : summary(mesh, mp)) c.push_back(s);
  if (int rc = write_obj("lshape", out_file, mesh, c, err)) return rc;
  out << out_file << ": L-shape, " << mesh.vertices.size() << " vertices, " << mesh.triangles.size() << " triangles\n";
  return 0;
}

void register_mesh_commands(CLI::App& app)
{
  CLI::App* mesh = app.add_subcommand("mesh", "Meshes: check and measure OBJ files, derive the low-resolution and "
                                              "sphere models, write the box, the wedge, the nut and the L-shape");
  mesh->require_subcommand(1);

  auto run = [](int rc) {
    if (rc != 0) throw CLI::RuntimeError(rc);
  };

  {
    auto file = std::make_shared<std::string>();
    auto density = std::make_shared<double>(default_density);
    auto units = std::make_shared<std::string>();
    auto scale = std::make_shared<double>(1.0);
    CLI::App* sub = mesh->add_subcommand("info", "Validate a mesh (OBJ, STL, PLY, glTF/GLB, ...) and print its mass "
                                                 "properties");
    sub->add_option("file", *file, "mesh file, in metres")->required();
    sub->add_option("--density", *density, "uniform density, kg/m^3 (statsim gather's default)")->capture_default_str();
    auto* u = sub->add_option("--units", *units, "unit of the coordinates: m, cm, mm, in or ft")
                  ->check(CLI::IsMember({"m", "cm", "mm", "in", "ft"}));
    auto* s = sub->add_option("--scale", *scale, "metres per unit of the coordinates (instead of --units)")->excludes(u);
    sub->callback([=] {
      double metres = *scale;
      if (!units->empty()) units_scale(*units, metres);
      run(mesh_info(*file, *density, std::cout, std::cerr, metres, !units->empty() || s->count() > 0));
    });
  }
  {
    auto in = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    auto vertices = std::make_shared<int>(100);
    CLI::App* sub = mesh->add_subcommand("decimate", "Decimate a closed mesh with meshoptimizer, keeping it closed");
    sub->add_option("--in", *in, "input OBJ")->required();
    sub->add_option("--out", *out, "output OBJ")->required();
    sub->add_option("--vertices", *vertices, "target vertex count (default 100)");
    sub->callback([=] { run(mesh_decimate(*in, *out, *vertices, std::cout, std::cerr)); });
  }
  {
    auto in = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    auto count = std::make_shared<int>(7);
    auto resolution = std::make_shared<int>(64);
    CLI::App* sub = mesh->add_subcommand("spheres", "Fit a union of spheres to a closed mesh");
    sub->add_option("--in", *in, "input OBJ")->required();
    sub->add_option("--out", *out, "output text file (x y z radius per line)")->required();
    sub->add_option("--count", *count, "number of spheres (default 7)");
    sub->add_option("--resolution", *resolution, "voxels along the longest extent (default 64)");
    sub->callback([=] { run(mesh_spheres(*in, *out, *count, *resolution, std::cout, std::cerr)); });
  }
  {
    auto size = std::make_shared<std::vector<double>>();
    auto out = std::make_shared<std::string>();
    CLI::App* sub = mesh->add_subcommand("box", "Write a box centred at the origin");
    sub->add_option("--size", *size, "full size X,Y,Z")->required()->delimiter(',')->expected(3);
    sub->add_option("--out", *out, "output OBJ")->required();
    sub->callback([=] { run(mesh_box({(*size)[0], (*size)[1], (*size)[2]}, *out, std::cout, std::cerr)); });
  }
  {
    auto legs = std::make_shared<std::vector<double>>();
    auto depth = std::make_shared<double>(0.08);
    auto out = std::make_shared<std::string>();
    CLI::App* sub = mesh->add_subcommand("wedge", "Write a wedge (right triangular prism) with its centre of mass at the origin");
    sub->add_option("--legs", *legs, "the right triangle's legs along x and y, m (e.g. 0.2,0.1)")
      ->required()
      ->delimiter(',')
      ->expected(2);
    sub->add_option("--depth", *depth, "extrusion along z, m (default 0.08)");
    sub->add_option("--out", *out, "output OBJ")->required();
    sub->callback([=] { run(mesh_wedge((*legs)[0], (*legs)[1], *depth, *out, std::cout, std::cerr)); });
  }
  {
    auto across = std::make_shared<double>(0.12);
    auto thickness = std::make_shared<double>(0.05);
    auto hole = std::make_shared<double>(0.06);
    auto segments = std::make_shared<int>(24);
    auto out = std::make_shared<std::string>();
    CLI::App* sub = mesh->add_subcommand("nut", "Write a hexagonal nut (hexagonal prism with a round hole) centred at the origin");
    sub->add_option("--across-corners", *across, "width between opposite corners, m")->capture_default_str();
    sub->add_option("--thickness", *thickness, "thickness along the hole's axis, m")->capture_default_str();
    sub->add_option("--hole", *hole, "hole diameter, m")->capture_default_str();
    sub->add_option("--hole-segments", *segments, "vertices of the hole's polygon (a multiple of 12)")->capture_default_str();
    sub->add_option("--out", *out, "output OBJ")->required();
    sub->callback([=] { run(mesh_nut(*across, *thickness, *hole, *segments, *out, std::cout, std::cerr)); });
  }
  {
    auto out = std::make_shared<std::string>();
    CLI::App* sub = mesh->add_subcommand("lshape", "Write the L-shape (fixed dimensions, see tools/mesh/shapes.hpp)");
    sub->add_option("--out", *out, "output OBJ")->required();
    sub->callback([=] { run(mesh_lshape(*out, std::cout, std::cerr)); });
  }
}

}  // namespace statsim::tools
