// statsim render / export: frame files, the rasterizer, the GIF writer and the glTF export; the
// frame files of `statsim reference-run`.
#include <doctest/doctest.h>

#include "export/gltf_export.hpp"
#include "export/tinygltf.hpp"
#include "render/frames.hpp"
#include "render/reference_run.hpp"
#include "render/render.hpp"
#include "support/temp_dir.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

using namespace statsim::tools;

namespace {

const char* kTwoBoxes =
    "frame,time,body,shape,x,y,z,qw,qx,qy,qz,state,radius\n"
    "0,0.01667,0,box,0,0,0.5,1,0,0,0,0,0.15\n"
    "0,0.01667,1,box,0.5,0,0.5,1,0,0,0,0,0.15\n"
    "6,0.11667,0,box,0,0,0.3,0.7071068,0,0,0.7071068,1,0.15\n"
    "6,0.11667,1,box,0.5,0,0.25,1,0,0,0,1,0.15\n"
    "12,0.21667,0,box,0,0,0.1,1,0,0,0,2,0.12\n"
    "12,0.21667,1,box,0.5,0,0.1,1,0,0,0,2,0.12\n";

std::string temp_path(const std::string& name)
{
  return (std::filesystem::temp_directory_path() / ("statsim_test_render_" + name)).string();
}

render::RenderShape load(const std::string& name)
{
  render::RenderShape s;
  std::string error;
  REQUIRE_MESSAGE(render::load_render_shape(name, render::default_meshes_dir(), s, error), error);
  return s;
}

bool is_grey(const std::uint8_t* p) { return std::abs(p[0] - p[1]) < 10 && std::abs(p[1] - p[2]) < 10; }

// Where the pinhole camera puts a world point (pixel units, y down), computed independently of
// the renderer from the camera's definition.
Eigen::Vector2d project(const render::Camera& c, const Eigen::Vector3d& p, int w, int h)
{
  const Eigen::Vector3d f = (c.target - c.eye).normalized();
  const Eigen::Vector3d r = f.cross(c.up).normalized();
  const Eigen::Vector3d u = r.cross(f);
  const Eigen::Vector3d q = p - c.eye;
  const double focal = 0.5 * h / std::tan(0.5 * c.fov_deg * 3.14159265358979 / 180);
  return {0.5 * w + focal * q.dot(r) / q.dot(f), 0.5 * h - focal * q.dot(u) / q.dot(f)};
}

}  // namespace

TEST_CASE("frame files parse with and without the radius column and map numeric shape ids")
{
  render::Frames f;
  std::string error;
  REQUIRE(render::parse_frames(kTwoBoxes, "two", {}, f, error));
  CHECK(f.has_radius);
  CHECK(f.frames.size() == 3);
  CHECK(f.body_count() == 2);
  REQUIRE(f.shapes.size() == 1);
  CHECK(f.shapes[0] == "box");
  CHECK(f.frames[1].step == 6);
  CHECK(f.frames[1].bodies[0].position.z() == doctest::Approx(0.3));
  CHECK(f.frames[1].bodies[0].orientation.z() == doctest::Approx(0.7071068));
  CHECK(f.frames[2].bodies[1].state == 2);
  CHECK(f.frames[2].bodies[1].radius == doctest::Approx(0.12));

  const char* ids = "# a comment\nframe,time,body,shape,x,y,z,qw,qx,qy,qz,state\n0,0.1,0,1,0,0,1,1,0,0,0,0\n";
  REQUIRE(render::parse_frames(ids, "ids", {"box", "bunny"}, f, error));
  CHECK_FALSE(f.has_radius);
  CHECK(f.shapes[0] == "bunny");
  CHECK_FALSE(render::parse_frames(ids, "ids", {"box"}, f, error));  // id 1 has no name
  CHECK(error.find("ids:3:") == 0);
  CHECK_FALSE(render::parse_frames("frame,time\n", "bad", {}, f, error));
  CHECK_FALSE(render::parse_frames("frame,time,body,shape,x,y,z,qw,qx,qy,qz,state\n0,0,0,box,nan,0,0,1,0,0,0,0\n", "nan",
                                   {}, f, error));
}

TEST_CASE("a box on the ground covers its projected pixels and the ground and sky stay visible")
{
  const render::RenderShape box = load("box");  // 0.2 m cube
  const std::vector<const render::RenderShape*> shapes = {&box};
  render::Frame frame;
  render::BodyPose b;
  b.position = Eigen::Vector3d(0, 0, 0.1);
  frame.bodies.push_back(b);
  render::Camera cam;
  cam.eye = Eigen::Vector3d(0.3, -1.2, 0.6);
  cam.target = Eigen::Vector3d(0, 0, 0.1);
  cam.fov_deg = 40;
  render::RenderOptions o;
  o.width = 96;
  o.height = 64;
  o.supersample = 1;
  o.shadows = false;  // the coverage check below counts only the body's own pixels
  const render::Image with = render::render_frame(frame, shapes, cam, o);
  const render::Image without = render::render_frame(render::Frame{}, shapes, cam, o);
  REQUIRE(with.width == 96);
  REQUIRE(with.height == 64);
  REQUIRE(with.rgb.size() == std::size_t(96 * 64 * 3));

  // The cube's corners, projected independently: every changed pixel lies in their box, and the
  // body covers a good share of it (a cube's silhouette fills more than half of its box).
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d c(i & 1 ? 0.1 : -0.1, i & 2 ? 0.1 : -0.1, i & 4 ? 0.2 : 0.0);
    const Eigen::Vector2d p = project(cam, c, o.width, o.height);
    x0 = std::min(x0, p.x());
    x1 = std::max(x1, p.x());
    y0 = std::min(y0, p.y());
    y1 = std::max(y1, p.y());
  }
  int changed = 0, outside = 0;
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x)
      if (std::memcmp(with.pixel(x, y), without.pixel(x, y), 3) != 0) {
        ++changed;
        if (x + 0.5 < x0 - 1 || x + 0.5 > x1 + 1 || y + 0.5 < y0 - 1 || y + 0.5 > y1 + 1) ++outside;
      }
  CHECK(outside == 0);
  CHECK(changed > 0.5 * (x1 - x0) * (y1 - y0));
  const Eigen::Vector2d centre = project(cam, b.position, o.width, o.height);
  const std::uint8_t* c = with.pixel(int(centre.x()), int(centre.y()));
  CHECK(std::memcmp(c, without.pixel(int(centre.x()), int(centre.y())), 3) != 0);
  CHECK_FALSE(is_grey(c));  // the body's colour, not the ground's grey

  // The ground (grey, below the horizon) and the sky (blue, above it) in the empty picture.
  CHECK(is_grey(without.pixel(2, o.height - 2)));
  CHECK(is_grey(without.pixel(o.width - 3, o.height - 2)));
  const std::uint8_t* sky = without.pixel(o.width / 2, 0);
  CHECK(sky[2] > sky[0] + 10);
  // The checkerboard: the ground is not one flat colour.
  bool varies = false;
  for (int x = 1; x < o.width; ++x) varies = varies || std::memcmp(without.pixel(x, o.height - 1), without.pixel(0, o.height - 1), 3) != 0;
  CHECK(varies);

  // Contact shadow: ground pixels next to the cube's base get darker, the far corner does not.
  o.shadows = true;
  const render::Image shadowed = render::render_frame(frame, shapes, cam, o);
  int darker = 0;
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      const std::uint8_t* p = shadowed.pixel(x, y);
      const std::uint8_t* q = with.pixel(x, y);
      if (std::memcmp(p, q, 3) != 0) {
        CHECK(p[0] + p[1] + p[2] < q[0] + q[1] + q[2]);
        ++darker;
      }
    }
  CHECK(darker > 0);
  CHECK(std::memcmp(shadowed.pixel(0, 0), with.pixel(0, 0), 3) == 0);
  o.shadows = false;

  // Collision spheres: a translucent sphere (radius 0.15 m > the cube's half size) changes
  // pixels around the cube, inside the sphere's outline only.
  render::Frame with_sphere = frame;
  with_sphere.bodies[0].radius = 0.15;
  o.spheres = true;
  const render::Image spheres = render::render_frame(with_sphere, shapes, cam, o);
  int more = 0;
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x)
      if (std::memcmp(spheres.pixel(x, y), with.pixel(x, y), 3) != 0) ++more;
  CHECK(more > changed / 4);
  const render::Image far_corner = spheres;
  CHECK(std::memcmp(far_corner.pixel(0, o.height - 1), with.pixel(0, o.height - 1), 3) == 0);

  // Deterministic: one thread or several, the same bytes.
  o.threads = 1;
  const render::Image one = render::render_frame(with_sphere, shapes, cam, o);
  o.threads = 3;
  const render::Image three = render::render_frame(with_sphere, shapes, cam, o);
  CHECK(one.rgb == three.rgb);

  const render::Image pair = render::side_by_side(with, without, "statsim", "reference");
  CHECK(pair.width == 2 * o.width);
  CHECK(pair.height == o.height);
}

TEST_CASE("the default camera frames every body and 2D shapes get a front view")
{
  render::Frames f;
  std::string error;
  REQUIRE(render::parse_frames(kTwoBoxes, "two", {}, f, error));
  const render::RenderShape box = load("box");
  const render::Camera cam = render::frame_camera({&f}, {{&box}}, render::CameraView{}, 1.5);
  CHECK_FALSE(cam.orthographic);
  for (const render::Frame& fr : f.frames)
    for (const render::BodyPose& b : fr.bodies) {
      const Eigen::Vector2d p = project(cam, b.position, 150, 100);
      CHECK(p.x() > 0);
      CHECK(p.x() < 150);
      CHECK(p.y() > 0);
      CHECK(p.y() < 100);
    }
  const render::RenderShape square = load("square2d");
  CHECK(square.planar);
  render::Frames flat;
  REQUIRE(render::parse_frames("frame,time,body,shape,x,y,z,qw,qx,qy,qz,state\n0,0.1,0,square2d,0,0.5,0,1,0,0,0,2\n",
                               "2d", {}, flat, error));
  const render::Camera front = render::frame_camera({&flat}, {{&square}}, render::CameraView{}, 1.5);
  CHECK(front.orthographic);
  render::RenderOptions o;
  o.width = 60;
  o.height = 40;
  o.supersample = 1;
  const render::Image img = render::render_frame(flat.frames[0], {&square}, front, o);
  const std::uint8_t* centre = img.pixel(30, 20);  // the square is at the centre of the view
  CHECK_FALSE(is_grey(centre));
}

TEST_CASE("animated GIF files are written")
{
  render::Image a;
  a.width = 8;
  a.height = 4;
  a.rgb.assign(8 * 4 * 3, 200);
  render::Image b = a;
  b.rgb[0] = 10;
  const std::string path = temp_path("anim.gif");
  std::string error;
  REQUIRE_MESSAGE(render::write_gif(path, {a, b}, 5, error), error);
  std::ifstream in(path, std::ios::binary);
  char magic[6] = {};
  in.read(magic, 6);
  CHECK(std::string(magic, 6) == "GIF89a");
  std::filesystem::remove(path);
}

TEST_CASE("export writes binary glTF that loads back with its nodes and keyframes")
{
  render::Frames f;
  std::string error;
  REQUIRE(render::parse_frames(kTwoBoxes, "two", {}, f, error));
  const render::RenderShape box = load("box");
  const std::string path = temp_path("two.glb");
  REQUIRE_MESSAGE(exporter::export_glb(f, {&box}, path, error), error);
  CHECK_FALSE(exporter::export_glb(f, {&box}, temp_path("no-such-directory") + "/two.glb", error));
  CHECK_FALSE(error.empty());

  tinygltf::TinyGLTF loader;
  tinygltf::Model m;
  std::string err, warn;
  REQUIRE_MESSAGE(loader.LoadBinaryFromFile(&m, &err, &warn, path), err);
  std::filesystem::remove(path);
  CHECK(m.asset.version == "2.0");
  CHECK(m.nodes.size() == 3);  // two bodies and the z-up root
  REQUIRE(m.scenes.size() == 1);
  REQUIRE(m.scenes[0].nodes.size() == 1);
  const tinygltf::Node& root = m.nodes[std::size_t(m.scenes[0].nodes[0])];
  CHECK(root.children.size() == 2);
  REQUIRE(m.animations.size() == 1);
  const tinygltf::Animation& anim = m.animations[0];
  REQUIRE(anim.channels.size() == 4);

  auto floats = [&](int accessor) {
    const tinygltf::Accessor& a = m.accessors[std::size_t(accessor)];
    const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
    const unsigned char* p = m.buffers[std::size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
    const std::size_t n = a.count * std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(a.type)));
    std::vector<float> out(n);
    std::memcpy(out.data(), p, n * sizeof(float));
    return out;
  };
  for (const tinygltf::AnimationChannel& c : anim.channels) {
    const tinygltf::AnimationSampler& s = anim.samplers[std::size_t(c.sampler)];
    const std::vector<float> t = floats(s.input);
    REQUIRE(t.size() == 3);
    CHECK(t[0] == doctest::Approx(0.01667));
    CHECK(t[2] == doctest::Approx(0.21667));
    const std::vector<float> v = floats(s.output);
    const std::string& name = m.nodes[std::size_t(c.target_node)].name;
    const int body = name == "body 0" ? 0 : 1;
    for (std::size_t k = 0; k < 3; ++k) {
      const render::BodyPose& pose = f.frames[k].bodies[std::size_t(body)];
      if (c.target_path == "translation") {
        REQUIRE(v.size() == 9);
        CHECK(v[3 * k] == doctest::Approx(pose.position.x()));
        CHECK(v[3 * k + 2] == doctest::Approx(pose.position.z()));
      } else {
        REQUIRE(c.target_path == "rotation");
        REQUIRE(v.size() == 12);
        CHECK(v[4 * k + 2] == doctest::Approx(pose.orientation.z()));  // glTF order x, y, z, w
        CHECK(v[4 * k + 3] == doctest::Approx(pose.orientation.w()));
      }
    }
  }
  // The body meshes are the box: 8 vertices, 12 triangles.
  const tinygltf::Mesh& mesh = m.meshes[std::size_t(m.nodes[0].mesh)];
  CHECK(m.accessors[std::size_t(mesh.primitives[0].attributes.at("POSITION"))].count == 8);
  CHECK(m.accessors[std::size_t(mesh.primitives[0].indices)].count == 36);
}

namespace {
std::string read_all(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The shared bunny drop of `scene` with `engine`, written to `frames`.
render::ReferenceRunOptions run_options(const std::string& scene, const std::string& engine, const std::string& frames)
{
  render::ReferenceRunOptions o;
  o.scene = scene;
  o.meshes_dir = render::default_meshes_dir();
  o.engine = engine;
  o.frames = frames;
  return o;
}
}  // namespace

TEST_CASE("reference-run: statsim with hull contacts runs the same scene, touching at the hulls")
{
  statsim::testing::TempDir dir("reference-run");
  render::ReferenceRunOptions o = run_options("bunnies12", "statsim", dir.file("spheres.csv"));
  o.hull_contacts = false;  // --body-contacts spheres; the default is the library's, hulls
  o.seconds = 3.0;
  o.every = 120;
  std::string error;
  CAPTURE(error);
  REQUIRE(render::reference_run(o, error));
  // Again: the runner's world is set up afresh, so a second run gives the same bytes.
  o.frames = dir.file("again.csv");
  REQUIRE(render::reference_run(o, error));
  CHECK(read_all(dir.file("again.csv")) == read_all(dir.file("spheres.csv")));
  o.hull_contacts = true;
  o.frames = dir.file("hulls.csv");
  REQUIRE(render::reference_run(o, error));
  const std::string spheres = read_all(dir.file("spheres.csv")), hulls = read_all(dir.file("hulls.csv"));
  // The first frame is the same dropped scene; by the last the bodies have met at their hulls.
  const std::string first = spheres.substr(0, spheres.find("\n120,"));
  REQUIRE(first.size() < spheres.size());
  CHECK(first.size() > 100);
  CHECK(hulls.compare(0, first.size(), first) == 0);
  CHECK(spheres != hulls);
}

TEST_CASE("reference-run: statsim's body contacts are refused for Bullet, and nothing is written")
{
  statsim::testing::TempDir dir("reference-run");
  render::ReferenceRunOptions o = run_options("bunnies3", "bullet", dir.file("bullet.csv"));
  o.hull_contacts = false;
  std::string error;
  CHECK_FALSE(render::reference_run(o, error));
  CHECK(error.find("--body-contacts") != std::string::npos);
  CHECK_FALSE(std::ifstream(o.frames).good());
}

TEST_CASE("reference-run: Bullet's substeps refine its step, and a bad count is refused with nothing written")
{
  statsim::testing::TempDir dir("reference-run");
  render::ReferenceRunOptions o = run_options("bunnies3", "bullet", dir.file("four.csv"));
  o.seconds = 0.5;
  o.every = 30;
  std::string error;
  CAPTURE(error);
  REQUIRE(render::reference_run(o, error));
  o.substeps = 8;
  o.frames = dir.file("eight.csv");
  REQUIRE(render::reference_run(o, error));
  // The same scene at half the step: the bunnies fall the same way, but not to the same bits.
  CHECK(read_all(dir.file("four.csv")) != read_all(dir.file("eight.csv")));
  o.substeps = 0;
  o.frames = dir.file("none.csv");
  CHECK_FALSE(render::reference_run(o, error));
  CHECK(error.find("--substeps") != std::string::npos);
  CHECK_FALSE(std::ifstream(o.frames).good());
}
