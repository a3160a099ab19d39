// A user's own mesh: the formats the tools read (OBJ, STL, PLY, glTF, GLB), the check of its
// units, `statsim mesh info` and `statsim gather` agreeing on density, and gather refusing a
// mesh or table the runtime would refuse before any trial, leaving no file.
// Runs with the repository root as working directory (reads tests/meshes/*).
#include "mesh/mass.hpp"
#include "mesh/mesh.hpp"
#include "mesh/mesh_commands.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/ref3d.hpp"

#include "support/temp_dir.hpp"

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace statsim::tools;

namespace {

const char* const kMeshes = "tests/meshes/";

int gather_cli(std::vector<std::string> args, std::string& err_text)
{
  std::ostringstream out, err;
  const int rc = run_gather_command(args, out, err);
  err_text = err.str();
  return rc;
}

std::vector<std::string> tiny_gather(const std::string& mesh, const std::string& out)
{
  return {"--mesh", mesh, "--out", out, "--cos-theta", "0.5,1", "--cos-phi", "-1,1", "--spin-ratios", "0,1",
          "--height-ratios", "0,1,4", "--trials", "3", "--height-trials", "8", "--rest-drops", "24", "--quiet",
          "--threads", "2"};
}

}  // namespace

TEST_CASE("the block loads alike from OBJ, STL, PLY, glTF and GLB")
{
  TriMesh obj;
  MeshError e;
  REQUIRE(load_mesh(std::string(kMeshes) + "block.obj", obj, e));
  const MassProperties ref = compute_mass_properties(obj, default_density);
  CHECK(ref.volume == doctest::Approx(0.06 * 0.04 * 0.02).epsilon(1e-9));
  for (const char* ext : {"stl", "ply", "gltf", "glb"}) {
    CAPTURE(ext);
    TriMesh m;
    MeshError err;
    const bool ok = load_mesh(std::string(kMeshes) + "block." + ext, m, err);
    CAPTURE(err.message);
    REQUIRE(ok);
    // STL stores a vertex per face corner: they are welded back into the block's 8.
    CHECK(m.vertices.size() == 8);
    CHECK(m.triangles.size() == 12);
    const MassProperties mp = compute_mass_properties(m, default_density);
    // The binary formats hold single-precision coordinates.
    CHECK(mp.volume == doctest::Approx(ref.volume).epsilon(1e-6));
    CHECK((mp.com - ref.com).norm() < 1e-8);
    CHECK((mp.principal_moments - ref.principal_moments).norm() < 1e-6 * ref.principal_moments.norm());
  }
}

TEST_CASE("an unreadable or open mesh in any format is refused with a message naming the file")
{
  statsim::testing::TempDir dir("own-shape");
  const std::string garbage = (dir.path / "garbage.stl").string();
  std::ofstream(garbage) << "this is not a mesh\n";
  TriMesh m;
  MeshError e;
  CHECK(!load_mesh(garbage, m, e));
  CHECK(e.message.find("garbage.stl") != std::string::npos);

  CHECK(!load_mesh((dir.path / "missing.ply").string(), m, e));
  CHECK(e.message.find("missing.ply: cannot open mesh file") != std::string::npos);

  // The block without its top: open, refused by the same check as an OBJ.
  const std::string open = (dir.path / "open.ply").string();
  std::ofstream(open) << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                         "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                         "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 2 1\n3 0 3 2\n";
  CHECK(!load_mesh(open, m, e));
  CHECK(e.message.find("open.ply: open surface (has a hole)") != std::string::npos);
}

TEST_CASE("a mesh outside 1 cm to 10 m needs its units")
{
  TriMesh m;
  MeshError e;
  REQUIRE(load_mesh(std::string(kMeshes) + "block_mm.stl", m, e));
  CHECK(!check_mesh_size(m, "block_mm.stl", false, e));
  CHECK(e.message.find("60 units across") != std::string::npos);
  CHECK(e.message.find("--units mm") != std::string::npos);
  CHECK(check_mesh_size(m, "block_mm.stl", true, e));
  double scale = 0;
  REQUIRE(units_scale("mm", scale));
  CHECK(scale == 0.001);
  CHECK(!units_scale("furlong", scale));
  scale_mesh(m, scale);
  CHECK(check_mesh_size(m, "block_mm.stl", false, e));

  TriMesh tiny = m;
  scale_mesh(tiny, 0.1);  // 6 mm
  CHECK(!check_mesh_size(tiny, "tiny", false, e));
}

TEST_CASE("mesh info and gather take the same density, and info checks units as gather does")
{
  const ref3d::GatherOptions defaults;
  CHECK(defaults.density == default_density);
  std::ostringstream out, err;
  REQUIRE(mesh_info(std::string(kMeshes) + "block.stl", default_density, out, err) == 0);
  CHECK(out.str().find("density:            1000\n") != std::string::npos);
  CHECK(out.str().find("mass:               0.04") != std::string::npos);
  std::ostringstream out2, err2;
  CHECK(mesh_info(std::string(kMeshes) + "block_mm.stl", default_density, out2, err2) != 0);
  CHECK(err2.str().find("--units") != std::string::npos);
  std::ostringstream out3, err3;
  CHECK(mesh_info(std::string(kMeshes) + "block_mm.stl", default_density, out3, err3, 0.001, true) == 0);
  CHECK(out3.str().find("mass:               0.04") != std::string::npos);
}

TEST_CASE("gather refuses a wrong-scale mesh or a table the runtime would refuse, before gathering, leaving no file")
{
  statsim::testing::TempDir dir("own-shape-gather");
  const std::string out = (dir.path / "block_mm.hpp").string();
  std::string err;
  CHECK(gather_cli(tiny_gather(std::string(kMeshes) + "block_mm.stl", out), err) != 0);
  CHECK(err.find("--units") != std::string::npos);
  CHECK(!fs::exists(out));

  // The mass a body of the table would get is beyond the runtime's limits.
  std::vector<std::string> heavy = tiny_gather(std::string(kMeshes) + "block.stl", out);
  heavy.insert(heavy.end(), {"--density", "1e14"});
  CHECK(gather_cli(heavy, err) != 0);
  CHECK(err.find("mass") != std::string::npos);
  CHECK(err.find("outside the runtime's") != std::string::npos);
  CHECK(!fs::exists(out));

  // With its units the same mesh gathers, and the header records them.
  std::vector<std::string> mm = tiny_gather(std::string(kMeshes) + "block_mm.stl", out);
  mm.insert(mm.end(), {"--units", "mm"});
  REQUIRE(gather_cli(mm, err) == 0);
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  CHECK(text.str().find("--units mm") != std::string::npos);
  CHECK(text.str().find("0.04") != std::string::npos);  // the mass, kg
}
