// Frame files: per-frame body transforms, the one format the demos (examples/), the reference
// runs (`statsim reference-run`) and the picture tools (`statsim render`, `statsim export`)
// share. This is its one writer; the reader is tools/render/frames.hpp.
//
// CSV with the header line
//   frame,time,body,shape,x,y,z,qw,qx,qy,qz,state,radius
// and one row per body per written frame:
//   frame   step index (integer; rows of one frame are consecutive)
//   time    s, simulated time after that step
//   body    body index (integer, 0-based)
//   shape   the shape's name: the signature's (box, lshape, bunny; square2d, lshape2d), sphere
//           for a plain sphere
//   x y z   centre of mass, m, world frame, z up (2D runs: x, y with y up, z = 0)
//   qw..qz  orientation, unit quaternion, body to world (2D runs: a turn about z)
//   state   0 moving, 1 settling, 2 asleep
//   radius  collision-sphere radius, m
// tools/render/README.md, "Frame files", documents the format for users.
//
// Header-only, C stdio only: no allocation, no exceptions (the examples are built without them).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <cstdio>

namespace statsim::tools::scenes {

/// The header line, without its newline.
inline const char* frames_header() { return "frame,time,body,shape,x,y,z,qw,qx,qy,qz,state,radius"; }

/// Writes the header line.
inline void write_frames_header(std::FILE* f) { std::fprintf(f, "%s\n", frames_header()); }

/// Writes one body of a 3D run: position `x` in m, orientation `q` (body to world), `time` in s,
/// `radius` in m.
inline void write_frame_row(std::FILE* f, int step, double time, std::uint32_t body, const char* shape,
                            const Eigen::Vector3d& x, const Eigen::Quaterniond& q, int state, double radius)
{
  std::fprintf(f, "%d,%.5f,%u,%s,%.6f,%.6f,%.6f,%.7f,%.7f,%.7f,%.7f,%d,%.6f\n", step, time, body, shape, x.x(), x.y(),
               x.z(), q.w(), q.x(), q.y(), q.z(), state, radius);
}

/// Writes one body of a 2D run: position `x` in m (y up), turned by `angle` rad counter-clockwise.
/// z and the quaternion's x and y are written as a plain 0.
inline void write_frame_row(std::FILE* f, int step, double time, std::uint32_t body, const char* shape,
                            const Eigen::Vector2d& x, double angle, int state, double radius)
{
  // A turn by angle a about z: quaternion (cos a/2, 0, 0, sin a/2).
  const double half = 0.5 * angle;
  std::fprintf(f, "%d,%.5f,%u,%s,%.6f,%.6f,0,%.7f,0,0,%.7f,%d,%.6f\n", step, time, body, shape, x.x(), x.y(),
               std::cos(half), std::sin(half), state, radius);
}

/// Writes every body of a statsim world (World2 or World3) after step `step`, at `time` s.
template <class World>
void write_frame(std::FILE* f, const World& w, int step, double time)
{
  for (std::uint32_t i = 0; i < w.body_count(); ++i) {
    const auto& b = w.body(i);
    const auto& shape = w.shape_of(b);
    const char* name = shape.statistical ? shape.signature.name : "sphere";
    if constexpr (World::Vec::RowsAtCompileTime == 3)
      write_frame_row(f, step, time, i, name, b.position.template cast<double>(), b.orientation.template cast<double>(),
                      int(b.state), double(b.radius));
    else
      write_frame_row(f, step, time, i, name, b.position.template cast<double>(), double(b.orientation.angle()),
                      int(b.state), double(b.radius));
  }
}

}  // namespace statsim::tools::scenes
