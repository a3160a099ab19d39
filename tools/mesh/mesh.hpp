#pragma once
/// @file
/// Closed triangle meshes for the host tools: a validated OBJ reader, other formats through
/// assimp (`load_mesh`), the check of units, and an OBJ writer.
///
/// Reading goes through tinyobjloader. tinyobjloader is lenient (it reads "nan" or "abc" as 0,
/// skips unknown statements and faces with bad indices), so `load_obj` first checks every line
/// itself and only then hands the text to tinyobjloader; the geometry comes from tinyobjloader.
/// (tinyobjloader's number parser is not always correctly rounded: a coordinate may differ from
/// strtod's by an ulp or so, far below anything the mass properties or the written files, at 12
/// significant digits, can show.) No exception leaves these functions: failures are reported as a
/// `MeshError`.

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace statsim::tools {

/// An indexed triangle mesh. Triangles are counter-clockwise seen from outside (outward normals).
struct TriMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;  ///< 0-based indices into `vertices`
};

/// Why a mesh was rejected: one line naming the problem, prefixed with "FILE:" or "FILE:LINE:"
/// when it comes from a file ("bunny.obj:12: vertex coordinate 'nan' is not finite").
struct MeshError {
  std::string message;
};

/// Loads and validates an OBJ file: `v` (x y z, optionally w or r g b), `f` (v, v/vt, v//vn,
/// v/vt/vn; 1-based or negative relative indices), and the statements that do not change the
/// surface (vn, vt, vp, o, g, s, l, p, mtllib, usemtl) are accepted; anything else is an error.
/// Faces with more than 3 vertices are triangulated (ear clipping in the polygon's plane).
/// Objects and groups are merged into one mesh; vertices no face uses are dropped (the others
/// keep their order). Then `validate_mesh` runs. Returns false and fills `error` on any problem:
/// missing or unreadable file, unparsable line, non-finite coordinate, face index out of range,
/// face with fewer than 3 vertices, degenerate triangle, open / non-manifold / inconsistently
/// wound surface, zero or negative volume.
bool load_obj(const std::string& path, TriMesh& mesh, MeshError& error);

/// Loads and validates a mesh file by its extension: `.obj` through `load_obj` (every line
/// checked), anything else (STL, PLY, glTF / GLB, ...) through assimp, with node transforms
/// applied, polygons triangulated, vertices at bit-identical positions welded (STL stores one
/// per face corner), then `validate_mesh`. Coordinates are taken as they are in the file.
bool load_mesh(const std::string& path, TriMesh& mesh, MeshError& error);

/// Metres per unit of a unit name: m, cm, mm, in, ft. False for any other name.
bool units_scale(const std::string& units, double& scale);

/// Multiplies every coordinate by `scale` (metres per file unit).
void scale_mesh(TriMesh& mesh, double scale);

/// Meshes are in metres, and a shape the tools can gather spans between these, m (the largest
/// side of its bounding box).
constexpr double min_mesh_size = 0.01;
constexpr double max_mesh_size = 10.0;

/// Refuses a mesh whose largest bounding-box side lies outside [`min_mesh_size`,
/// `max_mesh_size`] m, with a message that says how to give its units, unless `units_given`
/// (the user said what a unit is with --units or --scale).
bool check_mesh_size(const TriMesh& mesh, const std::string& name, bool units_given, MeshError& error);

/// As `load_obj`, reading OBJ text; `name` prefixes the messages in place of the file name.
bool parse_obj(const std::string& text, const std::string& name, TriMesh& mesh, MeshError& error);

/// Checks that a mesh bounds a solid: finite coordinates, indices in range, no degenerate
/// (zero-area) triangle, every edge shared by exactly two triangles that use it in opposite
/// directions (closed, manifold, consistently wound), and positive signed volume (outward
/// normals). A triangle is degenerate when its area is below 1e-12 times the squared diagonal of
/// the mesh's bounding box; the volume must exceed 1e-12 times the cubed diagonal.
/// `face_lines[t]`, when given (one entry per triangle), is the source line of triangle t, used
/// in the messages.
bool validate_mesh(const TriMesh& mesh, const std::string& name, MeshError& error,
                   const std::vector<int>* face_lines = nullptr);

/// Axis-aligned bounding box of the vertices.
void bounding_box(const TriMesh& mesh, Eigen::Vector3d& lo, Eigen::Vector3d& hi);

/// Formats a coordinate for an OBJ or text file: 12 significant digits, no trailing zeros,
/// never "-0" (so files written from the same doubles are byte-identical).
std::string format_number(double x);

/// The OBJ text of a mesh: each entry of `comments` as a "# " line, then `v` and `f` lines.
std::string obj_text(const TriMesh& mesh, const std::vector<std::string>& comments);

/// Writes `content` to `path` atomically: a temporary file in the same directory, then rename.
/// On failure nothing is left at `path` (a previous file there is untouched) and `error` says why.
bool write_file_atomic(const std::string& path, const std::string& content, MeshError& error);

}  // namespace statsim::tools
