#include "export/gltf_export.hpp"

#include "common/atomic_file.hpp"
#include "export/tinygltf.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace statsim::tools::exporter {

namespace {

// Appends raw bytes to the buffer as a new buffer view (4-byte aligned); returns its index.
int add_view(tinygltf::Model& m, const void* data, std::size_t bytes, int target)
{
  std::vector<unsigned char>& buf = m.buffers[0].data;
  while (buf.size() % 4) buf.push_back(0);
  tinygltf::BufferView v;
  v.buffer = 0;
  v.byteOffset = buf.size();
  v.byteLength = bytes;
  v.target = target;
  const unsigned char* p = static_cast<const unsigned char*>(data);
  buf.insert(buf.end(), p, p + bytes);
  m.bufferViews.push_back(v);
  return int(m.bufferViews.size()) - 1;
}

int add_accessor(tinygltf::Model& m, int view, int component, int type, std::size_t count,
                 std::vector<double> lo = {}, std::vector<double> hi = {})
{
  tinygltf::Accessor a;
  a.bufferView = view;
  a.componentType = component;
  a.type = type;
  a.count = count;
  a.minValues = std::move(lo);
  a.maxValues = std::move(hi);
  m.accessors.push_back(a);
  return int(m.accessors.size()) - 1;
}

}  // namespace

bool export_glb(const render::Frames& frames, const std::vector<const render::RenderShape*>& shapes,
                const std::string& path, std::string& error)
{
  if (frames.frames.empty()) {
    error = "no frames";
    return false;
  }
  for (std::size_t i = 1; i < frames.frames.size(); ++i)
    if (!(frames.frames[i].time > frames.frames[i - 1].time)) {
      error = "frame times must increase (frame " + std::to_string(frames.frames[i].step) + ")";
      return false;
    }
  const int bodies = frames.body_count();
  tinygltf::Model m;
  m.asset.version = "2.0";
  m.asset.generator = "statsim export";
  m.buffers.resize(1);

  // Geometry, one pair of accessors per shape.
  std::vector<int> pos_acc(shapes.size()), idx_acc(shapes.size());
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    const render::RenderShape& sh = *shapes[s];
    std::vector<float> pos;
    std::vector<double> lo(3, std::numeric_limits<double>::infinity()), hi(3, -std::numeric_limits<double>::infinity());
    for (const Eigen::Vector3f& v : sh.vertices)
      for (int k = 0; k < 3; ++k) {
        pos.push_back(v[k]);
        lo[std::size_t(k)] = std::min(lo[std::size_t(k)], double(v[k]));
        hi[std::size_t(k)] = std::max(hi[std::size_t(k)], double(v[k]));
      }
    std::vector<std::uint32_t> idx;
    for (const auto& t : sh.triangles)
      for (int k = 0; k < 3; ++k) idx.push_back(std::uint32_t(t[std::size_t(k)]));
    const int pv = add_view(m, pos.data(), pos.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
    pos_acc[s] = add_accessor(m, pv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, sh.vertices.size(), lo, hi);
    const int iv = add_view(m, idx.data(), idx.size() * sizeof(std::uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    idx_acc[s] = add_accessor(m, iv, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, idx.size());
  }
  for (int c = 0; c < 8; ++c) {
    tinygltf::Material mat;
    mat.name = "colour " + std::to_string(c);
    const Eigen::Vector3f col = render::body_colour(c);
    mat.pbrMetallicRoughness.baseColorFactor = {double(col.x()), double(col.y()), double(col.z()), 1.0};
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 0.7;
    m.materials.push_back(mat);
  }
  std::map<std::pair<int, int>, int> mesh_of;  // (shape, colour) -> mesh
  auto mesh_index = [&](int shape, int colour) {
    const auto key = std::make_pair(shape, colour);
    auto it = mesh_of.find(key);
    if (it != mesh_of.end()) return it->second;
    tinygltf::Mesh mesh;
    mesh.name = shapes[std::size_t(shape)]->name + " " + std::to_string(colour);
    tinygltf::Primitive p;
    p.attributes["POSITION"] = pos_acc[std::size_t(shape)];
    p.indices = idx_acc[std::size_t(shape)];
    p.material = colour;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    mesh.primitives.push_back(p);
    m.meshes.push_back(mesh);
    mesh_of[key] = int(m.meshes.size()) - 1;
    return mesh_of[key];
  };

  // Keyframes: every body's pose at every frame (holding the last pose where it is absent).
  const std::size_t nf = frames.frames.size();
  std::vector<float> times(nf);
  const std::size_t nb = static_cast<std::size_t>(bodies);
  std::vector<std::vector<float>> trans(nb), rot(nb);
  std::vector<const render::BodyPose*> last(nb, nullptr);
  for (const render::Frame& f : frames.frames)
    for (const render::BodyPose& b : f.bodies)
      if (!last[std::size_t(b.body)]) last[std::size_t(b.body)] = &b;  // first pose, for frames before it
  for (std::size_t i = 0; i < nf; ++i) {
    const render::Frame& f = frames.frames[i];
    times[i] = float(f.time);
    for (const render::BodyPose& b : f.bodies) last[std::size_t(b.body)] = &b;
    for (int b = 0; b < bodies; ++b) {
      const render::BodyPose* p = last[std::size_t(b)];
      if (!p) continue;
      for (int k = 0; k < 3; ++k) trans[std::size_t(b)].push_back(float(p->position[k]));
      const Eigen::Quaterniond& q = p->orientation;
      rot[std::size_t(b)].insert(rot[std::size_t(b)].end(), {float(q.x()), float(q.y()), float(q.z()), float(q.w())});
    }
  }
  const int tv = add_view(m, times.data(), times.size() * sizeof(float), 0);
  const int time_acc = add_accessor(m, tv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, nf,
                                    {double(times.front())}, {double(times.back())});

  tinygltf::Node root;
  root.name = "statsim world (z up)";
  const double h = std::sqrt(0.5);
  root.rotation = {-h, 0, 0, h};  // -90 deg about x: z up becomes y up
  tinygltf::Animation anim;
  anim.name = "frames";
  for (int b = 0; b < bodies; ++b) {
    const render::BodyPose* first = nullptr;
    for (const render::Frame& f : frames.frames) {
      for (const render::BodyPose& p : f.bodies)
        if (p.body == b) {
          first = &p;
          break;
        }
      if (first) break;
    }
    if (!first) continue;  // an index no frame uses
    tinygltf::Node node;
    node.name = "body " + std::to_string(b);
    node.mesh = mesh_index(first->shape, b % 8);
    node.translation = {first->position.x(), first->position.y(), first->position.z()};
    const Eigen::Quaterniond& q = first->orientation;
    node.rotation = {q.x(), q.y(), q.z(), q.w()};
    const render::RenderShape& sh = *shapes[std::size_t(first->shape)];
    if (sh.name == "sphere" && first->radius > 0) node.scale = {first->radius, first->radius, first->radius};
    m.nodes.push_back(node);
    const int node_index = int(m.nodes.size()) - 1;
    root.children.push_back(node_index);

    const std::vector<float>& t = trans[std::size_t(b)];
    const std::vector<float>& r = rot[std::size_t(b)];
    const int t_acc = add_accessor(m, add_view(m, t.data(), t.size() * sizeof(float), 0), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                   TINYGLTF_TYPE_VEC3, nf);
    const int r_acc = add_accessor(m, add_view(m, r.data(), r.size() * sizeof(float), 0), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                   TINYGLTF_TYPE_VEC4, nf);
    for (int k = 0; k < 2; ++k) {
      tinygltf::AnimationSampler s;
      s.input = time_acc;
      s.output = k == 0 ? t_acc : r_acc;
      s.interpolation = "LINEAR";
      anim.samplers.push_back(s);
      tinygltf::AnimationChannel c;
      c.sampler = int(anim.samplers.size()) - 1;
      c.target_node = node_index;
      c.target_path = k == 0 ? "translation" : "rotation";
      anim.channels.push_back(c);
    }
  }
  m.nodes.push_back(root);
  const int root_index = int(m.nodes.size()) - 1;
  m.animations.push_back(anim);
  tinygltf::Scene scene;
  scene.name = "statsim";
  scene.nodes.push_back(root_index);
  m.scenes.push_back(scene);
  m.defaultScene = 0;
  m.buffers[0].name = "statsim frames";

  // Serialised in memory, then written atomically (tinygltf's own file writer does not report a
  // file it could not open).
  tinygltf::TinyGLTF writer;
  std::ostringstream glb;
  if (!writer.WriteGltfSceneToStream(&m, glb, false, true)) {
    error = path + ": tinygltf could not serialise the model";
    return false;
  }
  try {
    write_file_atomic(path, glb.str());
  } catch (const std::exception& e) {
    error = e.what();
    return false;
  }
  return true;
}

}  // namespace statsim::tools::exporter
