// Frame files: per-frame body transforms, the one format the demos (examples/), the reference
// runs (`statsim reference-run`) and the picture tools (`statsim render`, `statsim export`)
// share. The format and its one writer are in tools/scenes/frames.hpp; this is the reader.
//
// Besides the files that writer writes, the reader accepts files without the radius column
// (radius 0: unknown), a plain integer as the shape (a shape id, as older files wrote, mapped by
// the caller), and lines starting with '#' (comments).
#pragma once

#include "scenes/frames.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

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

/// The writer's header line and rows (tools/scenes/frames.hpp).
using scenes::frames_header;
using scenes::write_frame_row;

}  // namespace statsim::tools::render
