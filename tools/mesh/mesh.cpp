#include "mesh/mesh.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#include <tiny_obj_loader.h>
#pragma GCC diagnostic pop

#include <Eigen/Geometry>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace statsim::tools {

namespace {

// ---- line checks (tinyobjloader itself reads garbage as 0) -----------------------------------

std::vector<std::string> split_tokens(const std::string& line)
{
  std::vector<std::string> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (j > i) tokens.push_back(line.substr(i, j - i));
    i = j;
  }
  return tokens;
}

std::string lower(std::string s)
{
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

enum class NumberCheck { ok, not_a_number, not_finite };

// A decimal floating-point literal as tinyobjloader understands it ([+-]digits[.digits][e[+-]digits]),
// finite as a double.
NumberCheck check_number(const std::string& token)
{
  const std::string l = lower(token);
  if (l.find("nan") != std::string::npos || l.find("inf") != std::string::npos) {
    return NumberCheck::not_finite;
  }
  for (char c : token) {
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.' || c == 'e' ||
          c == 'E')) {
      return NumberCheck::not_a_number;
    }
  }
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  if (end == token.c_str() || *end != '\0') return NumberCheck::not_a_number;
  if (!std::isfinite(value) || (errno == ERANGE && std::fabs(value) > 1.0)) return NumberCheck::not_finite;
  return NumberCheck::ok;
}

bool parse_index(const std::string& s, long& value)
{
  if (s.empty()) return false;
  std::size_t i = (s[0] == '-' || s[0] == '+') ? 1 : 0;
  if (i == s.size()) return false;
  for (std::size_t k = i; k < s.size(); ++k) {
    if (!std::isdigit(static_cast<unsigned char>(s[k]))) return false;
  }
  if (s.size() - i > 9) return false;  // more than 999,999,999: out of any range we accept
  value = std::strtol(s.c_str(), nullptr, 10);
  return true;
}

struct LineCheck {
  std::vector<int> face_lines;  // source line of each face, in file order
};

bool check_lines(const std::string& text, const std::string& name, LineCheck& out, MeshError& error)
{
  std::vector<std::string> lines;
  {
    std::size_t start = 0;
    while (start <= text.size()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string::npos) end = text.size();
      std::string line = text.substr(start, end - start);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines.push_back(std::move(line));
      if (end == text.size()) break;
      start = end + 1;
    }
  }
  long total[3] = {0, 0, 0};  // v, vt, vn
  for (const std::string& line : lines) {
    const auto tokens = split_tokens(line);
    if (tokens.empty()) continue;
    if (tokens[0] == "v") ++total[0];
    if (tokens[0] == "vt") ++total[1];
    if (tokens[0] == "vn") ++total[2];
  }

  long seen[3] = {0, 0, 0};
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const std::string& line = lines[n];
    const std::string where = name + ":" + std::to_string(n + 1) + ": ";
    if (line.find('\0') != std::string::npos) {
      error.message = where + "unparsable line: contains a NUL byte (binary file?)";
      return false;
    }
    const auto tokens = split_tokens(line);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    const std::string& key = tokens[0];
    const std::size_t args = tokens.size() - 1;

    auto check_numbers = [&](const char* what, std::size_t lo, std::size_t hi, const char* expect) {
      if (args < lo || args > hi) {
        error.message = where + "unparsable '" + key + "' line: expected " + expect + ", found " +
                        std::to_string(args) + " value" + (args == 1 ? "" : "s");
        return false;
      }
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        const NumberCheck c = check_number(tokens[k]);
        if (c == NumberCheck::not_finite) {
          error.message = where + what + " '" + tokens[k] + "' is not finite (NaN or infinite)";
          return false;
        }
        if (c == NumberCheck::not_a_number) {
          error.message = where + "unparsable '" + key + "' line: '" + tokens[k] + "' is not a number";
          return false;
        }
      }
      return true;
    };

    if (key == "v") {
      if (!check_numbers("vertex coordinate", 3, 6, "x y z [w] or x y z r g b")) return false;
      if (args == 5) {
        error.message = where + "unparsable 'v' line: expected x y z [w] or x y z r g b, found 5 values";
        return false;
      }
      ++seen[0];
    } else if (key == "vt") {
      if (!check_numbers("texture coordinate", 1, 3, "u [v [w]]")) return false;
      ++seen[1];
    } else if (key == "vn") {
      if (!check_numbers("normal component", 3, 3, "x y z")) return false;
      ++seen[2];
    } else if (key == "vp") {
      if (!check_numbers("parameter", 1, 3, "u [v [w]]")) return false;
    } else if (key == "f") {
      if (args < 3) {
        error.message = where + "face with " + std::to_string(args) + " vertices (a face needs at least 3)";
        return false;
      }
      if (args > 255) {
        error.message = where + "face with " + std::to_string(args) + " vertices (at most 255 supported)";
        return false;
      }
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        // v, v/vt, v//vn or v/vt/vn
        std::string parts[3];
        int count = 0;
        std::size_t start = 0;
        const std::string& t = tokens[k];
        bool ok = true;
        while (true) {
          const std::size_t slash = t.find('/', start);
          if (count == 3) {
            ok = false;
            break;
          }
          parts[count++] = t.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
          if (slash == std::string::npos) break;
          start = slash + 1;
        }
        static const char* const kind[3] = {"vertex", "texture coordinate", "normal"};
        static const char* const kinds[3] = {"vertices", "texture coordinates", "normals"};
        for (int p = 0; ok && p < count; ++p) {
          if (parts[p].empty()) {
            ok = (p == 1 && count == 3);  // "v//vn"
            continue;
          }
          long index = 0;
          if (!parse_index(parts[p], index) || index == 0) {
            ok = false;
            break;
          }
          const long resolved = index > 0 ? index : seen[p] + index + 1;
          const long limit = index > 0 ? total[p] : seen[p];
          if (resolved < 1 || resolved > limit) {
            error.message = where + "face index out of range: " + kind[p] + " index " + parts[p] +
                            " in '" + t + "' (" + std::to_string(limit) + " " + (limit == 1 ? kind[p] : kinds[p]) +
                            (index > 0 ? " in the file)" : " defined before this line)");
            return false;
          }
        }
        if (!ok) {
          error.message = where + "unparsable face vertex '" + t + "' (expected v, v/vt, v//vn or v/vt/vn with non-zero integers)";
          return false;
        }
      }
      out.face_lines.push_back(static_cast<int>(n + 1));
    } else if (key == "o" || key == "g" || key == "s" || key == "l" || key == "p" || key == "mtllib" ||
               key == "usemtl") {
      // Names, smoothing groups, lines, points and materials do not change the surface.
    } else {
      error.message = where + "unparsable line: unknown or unsupported statement '" + key + "'";
      return false;
    }
  }
  if (out.face_lines.empty()) {
    error.message = name + ": no faces ('f' lines): not a surface";
    return false;
  }
  return true;
}

// ---- polygon triangulation -------------------------------------------------------------------

// Ear clipping in the plane of the polygon (Newell normal). Emits n - 2 triangles; a polygon
// without an ear (self-intersecting or degenerate) is finished as a fan, and the validation
// then reports what is wrong with it.
void triangulate_polygon(const std::vector<int>& poly, const std::vector<Eigen::Vector3d>& v,
                         std::vector<std::array<int, 3>>& out)
{
  const std::size_t n = poly.size();
  if (n == 3) {
    out.push_back({poly[0], poly[1], poly[2]});
    return;
  }
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = v[poly[i]];
    const Eigen::Vector3d& b = v[poly[(i + 1) % n]];
    normal += a.cross(b);
  }
  std::vector<int> rest = poly;
  if (normal.norm() > 0.0) {
    const Eigen::Vector3d w = normal.normalized();
    const Eigen::Vector3d helper = std::fabs(w.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d ax = w.cross(helper).normalized();
    const Eigen::Vector3d ay = w.cross(ax);
    auto p2 = [&](int i) { return Eigen::Vector2d(v[i].dot(ax), v[i].dot(ay)); };
    auto cross2 = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
      return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    };
    while (rest.size() > 3) {
      const std::size_t m = rest.size();
      bool clipped = false;
      for (std::size_t k = 0; k < m && !clipped; ++k) {
        const std::size_t i = (k + 1) % m;  // try the ear at vertex 1 first: a convex polygon becomes a fan from vertex 0
        const int a = rest[(i + m - 1) % m], b = rest[i], c = rest[(i + 1) % m];
        const Eigen::Vector2d pa = p2(a), pb = p2(b), pc = p2(c);
        if (cross2(pa, pb, pc) <= 0.0) continue;  // reflex or flat corner
        bool inside = false;
        for (std::size_t j = 0; j < m && !inside; ++j) {
          const int q = rest[j];
          if (q == a || q == b || q == c) continue;
          const Eigen::Vector2d pq = p2(q);
          inside = cross2(pa, pb, pq) >= 0.0 && cross2(pb, pc, pq) >= 0.0 && cross2(pc, pa, pq) >= 0.0;
        }
        if (inside) continue;
        out.push_back({a, b, c});
        rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(i));
        clipped = true;
      }
      if (!clipped) break;
    }
  }
  for (std::size_t i = 1; i + 1 < rest.size(); ++i) out.push_back({rest[0], rest[i], rest[i + 1]});
}

// ---- validation ------------------------------------------------------------------------------

struct Context {
  const std::vector<int>* face_lines = nullptr;     // per triangle
  const std::vector<int>* vertex_numbers = nullptr; // 1-based number in the file, per vertex
};

std::string triangle_name(const Context& ctx, std::size_t t)
{
  if (ctx.face_lines && t < ctx.face_lines->size()) return "the face on line " + std::to_string((*ctx.face_lines)[t]);
  return "triangle index " + std::to_string(t);
}

std::string vertex_name(const Context& ctx, int i)
{
  if (ctx.vertex_numbers && i >= 0 && static_cast<std::size_t>(i) < ctx.vertex_numbers->size()) {
    return std::to_string((*ctx.vertex_numbers)[i]);
  }
  return "index " + std::to_string(i);
}

std::string where_prefix(const std::string& name, const Context& ctx, std::size_t t)
{
  if (ctx.face_lines && t < ctx.face_lines->size()) return name + ":" + std::to_string((*ctx.face_lines)[t]) + ": ";
  return name + ": ";
}

std::string fmt_g(double x)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

bool validate(const TriMesh& mesh, const std::string& name, MeshError& error, const Context& ctx)
{
  const std::size_t nv = mesh.vertices.size();
  if (mesh.triangles.empty()) {
    error.message = name + ": no triangles: not a surface";
    return false;
  }
  for (std::size_t i = 0; i < nv; ++i) {
    if (!mesh.vertices[i].allFinite()) {
      error.message = name + ": vertex " + vertex_name(ctx, static_cast<int>(i)) + " has a non-finite coordinate (NaN or infinite)";
      return false;
    }
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int i : mesh.triangles[t]) {
      if (i < 0 || static_cast<std::size_t>(i) >= nv) {
        error.message = where_prefix(name, ctx, t) + "face index out of range: " + triangle_name(ctx, t) +
                        " uses vertex index " + std::to_string(i) + " (" + std::to_string(nv) + " vertices)";
        return false;
      }
    }
  }
  Eigen::Vector3d lo, hi;
  bounding_box(mesh, lo, hi);
  const double diag = (hi - lo).norm();
  const Eigen::Vector3d centre = 0.5 * (lo + hi);

  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    const Eigen::Vector3d& a = mesh.vertices[f[0]];
    const Eigen::Vector3d& b = mesh.vertices[f[1]];
    const Eigen::Vector3d& c = mesh.vertices[f[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (f[0] == f[1] || f[1] == f[2] || f[2] == f[0] || !(area > 1e-12 * diag * diag)) {
      error.message = where_prefix(name, ctx, t) + "degenerate (zero-area) triangle: " + triangle_name(ctx, t) +
                      " has vertices " + vertex_name(ctx, f[0]) + ", " + vertex_name(ctx, f[1]) + ", " +
                      vertex_name(ctx, f[2]) + " (area " + fmt_g(area) + ")";
      return false;
    }
  }

  // Edge use: for the undirected edge {a, b} (a < b), how often a->b and b->a occur.
  struct Use {
    int forward = 0;   // a -> b
    int backward = 0;  // b -> a
  };
  std::unordered_map<std::uint64_t, Use> edges;
  edges.reserve(mesh.triangles.size() * 2);
  auto key = [](int a, int b) {
    const auto lo_ = static_cast<std::uint64_t>(std::min(a, b));
    const auto hi_ = static_cast<std::uint64_t>(std::max(a, b));
    return (lo_ << 32) | hi_;
  };
  for (const auto& f : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      Use& u = edges[key(a, b)];
      (a < b ? u.forward : u.backward) += 1;
    }
  }
  std::size_t open = 0, nonmanifold = 0, inconsistent = 0;
  for (const auto& e : edges) {
    const int uses = e.second.forward + e.second.backward;
    if (uses == 1) ++open;
    else if (uses > 2) ++nonmanifold;
    else if (e.second.forward != 1) ++inconsistent;
  }
  // Name the first offending edge in triangle order, so the message is deterministic.
  auto report = [&](auto bad, const std::string& what, std::size_t total, const std::string& totals) {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& f = mesh.triangles[t];
      for (int k = 0; k < 3; ++k) {
        const int a = f[k], b = f[(k + 1) % 3];
        const Use& u = edges[key(a, b)];
        if (!bad(u)) continue;
        error.message = where_prefix(name, ctx, t) + what + ": edge between vertices " + vertex_name(ctx, a) +
                        " and " + vertex_name(ctx, b) + " of " + triangle_name(ctx, t) + " " +
                        (what.rfind("open", 0) == 0 ? "belongs to no other triangle"
                         : what.rfind("non", 0) == 0
                           ? "is shared by " + std::to_string(u.forward + u.backward) + " triangles"
                           : "is used in the same direction by two triangles (a directed edge appears twice)") +
                        "; " + std::to_string(total) + " " + totals + " in total";
        return;
      }
    }
  };
  if (nonmanifold > 0) {
    report([](const Use& u) { return u.forward + u.backward > 2; }, "non-manifold surface", nonmanifold,
           "non-manifold edge" + std::string(nonmanifold == 1 ? "" : "s"));
    return false;
  }
  if (open > 0) {
    report([](const Use& u) { return u.forward + u.backward == 1; }, "open surface (has a hole)", open,
           "boundary edge" + std::string(open == 1 ? "" : "s"));
    return false;
  }
  if (inconsistent > 0) {
    report([](const Use& u) { return u.forward + u.backward == 2 && u.forward != 1; }, "inconsistently wound surface",
           inconsistent, "such edge" + std::string(inconsistent == 1 ? "" : "s"));
    return false;
  }

  double volume6 = 0.0;
  for (const auto& f : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[f[0]] - centre;
    const Eigen::Vector3d b = mesh.vertices[f[1]] - centre;
    const Eigen::Vector3d c = mesh.vertices[f[2]] - centre;
    volume6 += a.dot(b.cross(c));
  }
  const double volume = volume6 / 6.0;
  if (!(std::fabs(volume) > 1e-12 * diag * diag * diag)) {
    error.message = name + ": zero volume (signed volume " + fmt_g(volume) + "): the surface encloses no solid";
    return false;
  }
  if (volume < 0.0) {
    error.message = name + ": negative volume " + fmt_g(volume) +
                    ": the faces are wound clockwise seen from outside (inward normals); reverse every face";
    return false;
  }
  return true;
}

bool read_file(const std::string& path, std::string& text, MeshError& error)
{
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    error.message = path + ": cannot read mesh: is a directory";
    return false;
  }
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    error.message = path + ": cannot open mesh file: " + std::strerror(errno);
    return false;
  }
  text.clear();
  char buf[65536];
  std::size_t got = 0;
  while ((got = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, got);
  const bool failed = std::ferror(f) != 0;
  const int err = errno;
  std::fclose(f);
  if (failed) {
    error.message = path + ": cannot read mesh file: " + std::strerror(err);
    return false;
  }
  return true;
}

bool parse_obj_impl(const std::string& text, const std::string& name, TriMesh& mesh, MeshError& error)
{
  LineCheck lines;
  if (!check_lines(text, name, lines, error)) return false;

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::istringstream in(text);
  // No material reader: mtllib lines are ignored (materials do not change the solid).
  const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, nullptr,
                                   /*triangulate=*/false, /*default_vcols_fallback=*/false);
  auto first_line = [](const std::string& s) {
    std::string l = s.substr(0, s.find('\n'));
    while (!l.empty() && (l.back() == '\r' || l.back() == '.' || l.back() == ' ')) l.pop_back();
    return l;
  };
  if (!ok || !err.empty()) {
    error.message = name + ": tinyobjloader: " + first_line(err.empty() ? std::string("failed to parse") : err);
    return false;
  }
  {
    std::istringstream ws(warn);
    std::string w;
    while (std::getline(ws, w)) {
      if (w.empty() || w == "." || w.find("material") != std::string::npos || w.find("group name") != std::string::npos) {
        continue;  // appearance only
      }
      error.message = name + ": tinyobjloader: " + first_line(w);
      return false;
    }
  }

  const std::size_t nv = attrib.vertices.size() / 3;
  std::vector<Eigen::Vector3d> all(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    all[i] = Eigen::Vector3d(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
  }

  std::vector<std::array<int, 3>> triangles;
  std::vector<int> tri_lines;
  std::size_t face = 0;
  for (const auto& shape : shapes) {
    std::size_t offset = 0;
    for (const unsigned char count : shape.mesh.num_face_vertices) {
      if (face >= lines.face_lines.size()) {
        error.message = name + ": tinyobjloader returned more faces than the file has";
        return false;
      }
      std::vector<int> poly;
      for (std::size_t k = 0; k < count; ++k) {
        const int vi = shape.mesh.indices[offset + k].vertex_index;
        if (vi < 0 || static_cast<std::size_t>(vi) >= nv) {
          error.message = name + ":" + std::to_string(lines.face_lines[face]) + ": face index out of range";
          return false;
        }
        poly.push_back(vi);
      }
      offset += count;
      const std::size_t before = triangles.size();
      triangulate_polygon(poly, all, triangles);
      tri_lines.insert(tri_lines.end(), triangles.size() - before, lines.face_lines[face]);
      ++face;
    }
  }
  if (face != lines.face_lines.size()) {
    error.message = name + ": tinyobjloader read " + std::to_string(face) + " faces, the file has " +
                    std::to_string(lines.face_lines.size()) + " (a face with more than 255 vertices?)";
    return false;
  }

  // Keep the vertices the faces use, in file order.
  std::vector<int> remap(nv, -1);
  for (const auto& t : triangles) {
    for (int i : t) remap[i] = 0;
  }
  TriMesh result;
  std::vector<int> numbers;
  for (std::size_t i = 0; i < nv; ++i) {
    if (remap[i] < 0) continue;
    remap[i] = static_cast<int>(result.vertices.size());
    result.vertices.push_back(all[i]);
    numbers.push_back(static_cast<int>(i + 1));
  }
  result.triangles = triangles;
  for (auto& t : result.triangles) {
    for (int& i : t) i = remap[i];
  }

  Context ctx;
  ctx.face_lines = &tri_lines;
  ctx.vertex_numbers = &numbers;
  if (!validate(result, name, error, ctx)) return false;
  mesh = std::move(result);
  return true;
}

}  // namespace

bool parse_obj(const std::string& text, const std::string& name, TriMesh& mesh, MeshError& error)
{
  try {
    return parse_obj_impl(text, name, mesh, error);
  } catch (const std::exception& e) {
    error.message = name + ": " + e.what();
  } catch (...) {
    error.message = name + ": unknown error while reading the mesh";
  }
  return false;
}

bool load_obj(const std::string& path, TriMesh& mesh, MeshError& error)
{
  std::string text;
  return read_file(path, text, error) && parse_obj(text, path, mesh, error);
}

bool validate_mesh(const TriMesh& mesh, const std::string& name, MeshError& error, const std::vector<int>* face_lines)
{
  try {
    Context ctx;
    ctx.face_lines = face_lines;
    return validate(mesh, name, error, ctx);
  } catch (const std::exception& e) {
    error.message = name + ": " + e.what();
  }
  return false;
}

void bounding_box(const TriMesh& mesh, Eigen::Vector3d& lo, Eigen::Vector3d& hi)
{
  if (mesh.vertices.empty()) {
    lo = hi = Eigen::Vector3d::Zero();
    return;
  }
  lo = hi = mesh.vertices[0];
  for (const auto& p : mesh.vertices) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
}

std::string format_number(double x)
{
  if (x == 0.0) return "0";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", x);
  return buf;
}

std::string obj_text(const TriMesh& mesh, const std::vector<std::string>& comments)
{
  std::string s;
  for (const auto& c : comments) s += c.empty() ? "#\n" : "# " + c + "\n";
  for (const auto& p : mesh.vertices) {
    s += "v " + format_number(p.x()) + " " + format_number(p.y()) + " " + format_number(p.z()) + "\n";
  }
  for (const auto& t : mesh.triangles) {
    s += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  }
  return s;
}

bool write_file_atomic(const std::string& path, const std::string& content, MeshError& error)
{
  std::string tmpl = path + ".tmp.XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) {
    error.message = path + ": cannot create output file: " + std::strerror(errno);
    return false;
  }
  const std::string tmp(name.data());
  auto fail = [&](const char* what, int err) {
    ::close(fd);
    ::unlink(tmp.c_str());
    error.message = path + ": " + what + ": " + std::strerror(err);
    return false;
  };
  if (::fchmod(fd, 0644) != 0) return fail("cannot set permissions", errno);
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail("cannot write", errno);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    error.message = path + ": cannot write: " + std::strerror(err);
    return false;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    error.message = path + ": cannot rename the temporary file into place: " + std::strerror(err);
    return false;
  }
  return true;
}

}  // namespace statsim::tools
