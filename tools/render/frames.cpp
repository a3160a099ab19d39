#include "render/frames.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace statsim::tools::render {

int Frames::body_count() const
{
  int n = 0;
  for (const Frame& f : frames)
    for (const BodyPose& b : f.bodies) n = std::max(n, b.body + 1);
  return n;
}

namespace {

std::vector<std::string> split(const std::string& line)
{
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r' && c != ' ' && c != '\t') {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  return out;
}

bool to_double(const std::string& s, double& v)
{
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && errno == 0 && std::isfinite(v);
}

bool to_int(const std::string& s, long& v)
{
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  v = std::strtol(s.c_str(), &end, 10);
  return end == s.c_str() + s.size() && errno == 0;
}

}  // namespace

bool parse_frames(const std::string& text, const std::string& name, const std::vector<std::string>& shape_names,
                  Frames& out, std::string& error)
{
  out = Frames{};
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  bool header = false;
  auto fail = [&](const std::string& what) {
    error = name + ":" + std::to_string(line_no) + ": " + what;
    return false;
  };
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#' || line == "\r") continue;
    const std::vector<std::string> cols = split(line);
    if (!header) {
      const std::string h12 = "frame,time,body,shape,x,y,z,qw,qx,qy,qz,state";
      std::string joined;
      for (std::size_t i = 0; i < cols.size(); ++i) joined += (i ? "," : "") + cols[i];
      if (joined == h12) {
        out.has_radius = false;
      } else if (joined == frames_header()) {
        out.has_radius = true;
      } else {
        return fail(std::string("expected the header '") + frames_header() + "'");
      }
      header = true;
      continue;
    }
    const std::size_t want = out.has_radius ? 13 : 12;
    if (cols.size() != want) return fail("expected " + std::to_string(want) + " columns");
    long step = 0, body = 0, state = 0;
    double time = 0, v[8] = {}, radius = 0;
    if (!to_int(cols[0], step)) return fail("frame '" + cols[0] + "' is not an integer");
    if (!to_double(cols[1], time)) return fail("time '" + cols[1] + "' is not a finite number");
    if (!to_int(cols[2], body) || body < 0 || body > 100000000) return fail("body '" + cols[2] + "' is not a body index");
    for (int k = 0; k < 7; ++k)
      if (!to_double(cols[std::size_t(4 + k)], v[k])) return fail("'" + cols[std::size_t(4 + k)] + "' is not a finite number");
    if (!to_int(cols[11], state)) return fail("state '" + cols[11] + "' is not an integer");
    if (out.has_radius && (!to_double(cols[12], radius) || radius < 0))
      return fail("radius '" + cols[12] + "' is not a number >= 0");
    std::string shape = cols[3];
    long id = 0;
    if (to_int(shape, id)) {
      if (id < 0 || std::size_t(id) >= shape_names.size())
        return fail("shape id " + shape + " has no name: give the shapes' names (--shapes NAME,...)");
      shape = shape_names[std::size_t(id)];
    }
    if (shape.empty()) return fail("empty shape name");
    auto it = std::find(out.shapes.begin(), out.shapes.end(), shape);
    const int shape_index = int(it - out.shapes.begin());
    if (it == out.shapes.end()) out.shapes.push_back(shape);
    if (out.frames.empty() || out.frames.back().step != int(step)) {
      out.frames.push_back(Frame{int(step), time, {}});
    }
    BodyPose p;
    p.body = int(body);
    p.shape = shape_index;
    p.position = Eigen::Vector3d(v[0], v[1], v[2]);
    Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    const double n = q.norm();
    if (!(n > 0.5 && n < 2)) return fail("orientation is not a unit quaternion");
    p.orientation = Eigen::Quaterniond(q.coeffs() / n);
    p.state = int(state);
    p.radius = radius;
    out.frames.back().bodies.push_back(p);
  }
  if (!header) {
    line_no = 0;
    return fail("empty file (no header)");
  }
  if (out.frames.empty()) return fail("no frames");
  return true;
}

bool read_frames(const std::string& path, const std::vector<std::string>& shape_names, Frames& out,
                 std::string& error)
{
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    error = path + ": cannot open";
    return false;
  }
  std::ostringstream ss;
  ss << f.rdbuf();
  return parse_frames(ss.str(), path, shape_names, out, error);
}

}  // namespace statsim::tools::render
