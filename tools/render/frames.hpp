// Frame files: per-frame body transforms, the one format the demos (examples/demo.hpp), the
// reference runs (`statsim reference-run`) and the picture tools (`statsim render`, `statsim
// export`) share.
//
// CSV with the header line
//   frame,time,body,shape,x,y,z,qw,qx,qy,qz,state,radius
// and one row per body per written frame:
//   frame   step index (integer; rows of one frame are consecutive)
//   time    s, simulated time after that step
//   body    body index (integer, 0-based)
//   shape   the shape's name: box, lshape, bunny (3D); square2d, lshape2d (2D); sphere. A plain
//           integer (a shape id, as older files wrote) is accepted and mapped by the caller.
//   x y z   centre of mass, m, world frame, z up (2D runs: x, y with y up, z = 0)
//   qw..qz  orientation, unit quaternion, body to world (2D runs: a turn about z)
//   state   0 moving, 1 settling, 2 asleep
//   radius  collision-sphere radius, m (optional column; 0 or absent: unknown)
// Lines starting with '#' are comments.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdio>
#include <string>
#include <vector>

namespace statsim::tools::render {

/// One body in one frame.
struct BodyPose {
  int body = 0;
  int shape = 0;  ///< index into Frames::shapes
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  int state = 0;
  double radius = 0.0;  ///< m; 0 when the file has no radius
};

struct Frame {
  int step = 0;
  double time = 0.0;
  std::vector<BodyPose> bodies;
};

struct Frames {
  std::vector<std::string> shapes;  ///< names, in order of first appearance
  std::vector<Frame> frames;
  bool has_radius = false;
  /// Largest body index + 1 over all frames.
  int body_count() const;
};

/// Reads a frame file. `shape_names` maps numeric shape columns (shape id i -> shape_names[i]);
/// names in the file are kept as they are. Returns false with `error` ("FILE:LINE: ...") on a
/// missing file, a wrong header, a malformed row or a non-finite number.
bool read_frames(const std::string& path, const std::vector<std::string>& shape_names, Frames& out,
                 std::string& error);
/// As read_frames, from the file's text.
bool parse_frames(const std::string& text, const std::string& name, const std::vector<std::string>& shape_names,
                  Frames& out, std::string& error);

/// The header line (without newline).
const char* frames_header();
/// Writes one row in the same number format as examples/demo.hpp.
void write_frame_row(std::FILE* f, int step, double time, int body, const std::string& shape,
                     const Eigen::Vector3d& x, const Eigen::Quaterniond& q, int state, double radius);

}  // namespace statsim::tools::render
