// Mesh files in the formats other than OBJ (STL, PLY, glTF / GLB and the rest assimp reads), and
// the check of a mesh's units. OBJ keeps its own reader (mesh.cpp), which names the line of
// every problem; the others come through assimp and then meet the same `validate_mesh`.
#include "mesh/mesh.hpp"

#include "common/third_party_begin.hpp"
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include "common/third_party_end.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

namespace statsim::tools {

namespace {

std::string lower_extension(const std::string& path)
{
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string fmt(double x)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

bool load_with_assimp(const std::string& path, TriMesh& mesh, MeshError& error)
{
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    error.message = path + ": cannot read mesh: is a directory";
    return false;
  }
  if (!std::filesystem::exists(path, ec)) {
    error.message = path + ": cannot open mesh file: No such file or directory";
    return false;
  }
  Assimp::Importer importer;
  // Node transforms are applied (a glTF scene may place its mesh), polygons become triangles;
  // nothing else is changed: no normals are generated and no vertex is moved.
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode) {
    error.message = path + ": cannot read mesh (assimp: " + std::string(importer.GetErrorString()) +
                    "); formats: OBJ, STL, PLY, glTF/GLB and the others assimp reads";
    return false;
  }
  // Every mesh of the file makes one surface. Formats that store a vertex per face corner (STL)
  // repeat shared vertices: equal positions are welded into one vertex, so that the surface's
  // edges can be checked; positions that differ in any bit stay apart.
  TriMesh result;
  std::map<std::array<double, 3>, int> index_of;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices < 3) {
        error.message = path + ": mesh " + std::to_string(m) + " has points or lines: not a surface";
        return false;
      }
      std::array<int, 3> tri{};
      for (unsigned k = 0; k < 3; ++k) {
        const unsigned vi = face.mIndices[k];
        if (vi >= am->mNumVertices) {
          error.message = path + ": mesh " + std::to_string(m) + ", face " + std::to_string(f) + ": index out of range";
          return false;
        }
        const aiVector3D& p = am->mVertices[vi];
        const std::array<double, 3> key{double(p.x), double(p.y), double(p.z)};
        const auto [it, added] = index_of.emplace(key, int(result.vertices.size()));
        if (added) result.vertices.emplace_back(key[0], key[1], key[2]);
        tri[k] = it->second;
      }
      result.triangles.push_back(tri);
    }
  }
  if (!validate_mesh(result, path, error)) return false;
  mesh = std::move(result);
  return true;
}

}  // namespace

bool load_mesh(const std::string& path, TriMesh& mesh, MeshError& error)
{
  if (lower_extension(path) == ".obj") return load_obj(path, mesh, error);
  try {
    return load_with_assimp(path, mesh, error);
  } catch (const std::exception& e) {
    error.message = path + ": " + e.what();
  }
  return false;
}

bool units_scale(const std::string& units, double& scale)
{
  static const std::map<std::string, double> known = {{"m", 1.0}, {"cm", 0.01}, {"mm", 0.001}, {"in", 0.0254},
                                                      {"ft", 0.3048}};
  const auto it = known.find(units);
  if (it == known.end()) return false;
  scale = it->second;
  return true;
}

void scale_mesh(TriMesh& mesh, double scale)
{
  for (Eigen::Vector3d& v : mesh.vertices) v *= scale;
}

bool check_mesh_size(const TriMesh& mesh, const std::string& name, bool units_given, MeshError& error)
{
  Eigen::Vector3d lo, hi;
  bounding_box(mesh, lo, hi);
  const double size = (hi - lo).maxCoeff();
  if (units_given || (size >= min_mesh_size && size <= max_mesh_size)) return true;
  // Parts drawn in millimetres are the common case of a mesh too large.
  const char* guess = size > max_mesh_size && size <= 1000 * max_mesh_size ? " (millimetres? then --units mm)" : "";
  error.message = name + ": the mesh is " + fmt(size) + " units across; read as metres that is outside " +
                  fmt(min_mesh_size) + " m to " + fmt(max_mesh_size) + " m" + guess +
                  ". Meshes are in metres: give --units m|cm|mm|in|ft or --scale S (metres per unit) to say what is meant";
  return false;
}

}  // namespace statsim::tools
