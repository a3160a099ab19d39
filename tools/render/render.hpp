// Pictures of frame files (render/frames.hpp): a software z-buffer rasterizer for the host tools.
//
// What a picture shows:
//  - each body as its true shape (tools/meshes: bunny, box, lshape, in the body frame the tables
//    use: centre of mass, principal axes), flat-shaded by a key light from the camera's upper
//    left plus ambient light, one colour per body from a fixed palette (body index modulo 8);
//    2D shapes (square2d, lshape2d) as prisms seen from the front;
//  - the ground z = 0 as a grey checkerboard (tiles of 1, 2 or 5 x 10^k m, about a tenth of the
//    framed region), fading into the sky colour with distance, with a soft contact shadow under
//    each body near it (a disc of 0.8 x its bounding radius, fading out from 3 radii up); 2D: the
//    region y < 0;
//  - optionally each body's collision sphere, translucent (paper Figure 7), of the frame file's
//    radius, or, without a radius column, of the shape table's largest rest height h_rest (the
//    radius the runtime gives a resting body);
//  - supersampled (default 2 x 2 samples per pixel, box filter) for smooth edges.
// Default camera: looks at the centre of the bodies' bounding box over the rendered frames from
// azimuth -60 deg (measured from +x towards +y), elevation 25 deg, vertical field of view 35 deg,
// at the distance where that box (grown by the shapes' bounding radius, its bottom at least at
// the ground) just fits the image with a 4% margin (optionally only a share of the bodies). 2D runs: an orthographic front view.
//
// Rendering is deterministic: the image depends only on the inputs, not on the thread count
// (horizontal bands are rendered in parallel, each pixel by exactly one band, bodies in order).
#pragma once

#include "render/frames.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace statsim::tools::render {

/// A shape as drawn: triangles in the body frame.
struct RenderShape {
  std::string name;
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<int, 3>> triangles;
  bool planar = false;             ///< a 2D shape (prism along z)
  double bounding_radius = 0.0;    ///< m, farthest vertex from the centre of mass
  double table_sphere_radius = 0.0;  ///< m, largest h_rest of the shape's table (0: no table)
};

/// Loads a shape by name: box, lshape, bunny (tools/meshes/NAME.obj in the body frame), bunny_low
/// (the decimated bunny in the full bunny's body frame), square2d, lshape2d (the 2D tables'
/// polygons as prisms 0.5 m deep), sphere (an icosphere of radius 1, scaled by each body's
/// radius). Returns false with `error` set for an unknown name or an unreadable mesh.
bool load_render_shape(const std::string& name, const std::string& meshes_dir, RenderShape& shape,
                       std::string& error);

/// The directory of the committed meshes (tools/meshes of the source tree).
std::string default_meshes_dir();

/// A frame file and the shapes its bodies are drawn with (shapes[i] is shape index i).
struct LoadedFrames {
  Frames frames;
  std::vector<std::unique_ptr<RenderShape>> owned;
  std::vector<const RenderShape*> shapes;
};

/// Reads the frame file `path` (`shape_names`: names of numeric shape ids, comma-separated) and
/// loads its shapes from `meshes_dir`. `detail` picks the bunny's mesh: "full", "low" (bunny_low)
/// or "auto" (low above 1,000 bodies). Returns false with `error` set.
bool load_frames(const std::string& path, const std::string& shape_names, const std::string& detail,
                 const std::string& meshes_dir, LoadedFrames& out, std::string& error);

struct Camera {
  Eigen::Vector3d eye = Eigen::Vector3d(3, -3, 2);
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double fov_deg = 35.0;         ///< vertical field of view (perspective)
  bool orthographic = false;
  double ortho_height = 10.0;    ///< m of world shown vertically (orthographic)
};

/// How the default camera looks at a scene (see the file comment).
struct CameraView {
  double azimuth_deg = -60.0;
  double elevation_deg = 25.0;
  double fov_deg = 35.0;
  /// Share of the bodies' spheres (over all frames) the camera fits, those nearest their median
  /// centre; 1 fits every body.
  double fit_share = 1.0;
};

/// The default camera framing every body of `frames` (each with its shape's bounding radius)
/// for an image of aspect width / height.
Camera frame_camera(const std::vector<const Frames*>& frames, const std::vector<std::vector<const RenderShape*>>& shapes,
                    const CameraView& view, double aspect);

struct RenderOptions {
  int width = 640;
  int height = 360;
  int supersample = 2;         ///< samples per pixel along each axis
  bool spheres = false;        ///< draw the collision spheres, translucent
  bool shadows = true;         ///< contact shadows on the ground (perspective views)
  double sphere_alpha = 0.3;   ///< opacity facing the camera (more towards the rim)
  double ground_tile = 0.0;    ///< m; 0 picks one from the framed region
  unsigned threads = 0;        ///< 0: all cores
};

/// An 8-bit RGB image, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;
  const std::uint8_t* pixel(int x, int y) const { return &rgb[std::size_t(3 * (y * width + x))]; }
};

/// Renders one frame. `shapes[i]` draws Frame bodies with shape index i (Frames::shapes order).
Image render_frame(const Frame& frame, const std::vector<const RenderShape*>& shapes, const Camera& camera,
                   const RenderOptions& options);

/// The two images next to each other (same height), with a label drawn at the top of each.
Image side_by_side(const Image& left, const Image& right, const std::string& left_label,
                   const std::string& right_label);

/// Writes a PNG (stb_image_write). Returns false on failure.
bool write_png(const std::string& path, const Image& image);

/// Writes an animated GIF (giflib; each frame quantized to its own 256-colour table by giflib's
/// median cut), `delay_cs` hundredths of a second per frame, looping. Returns false with `error`.
bool write_gif(const std::string& path, const std::vector<Image>& images, int delay_cs, std::string& error);

/// The colour of body `index` (fixed palette of 8), linear 0..1.
Eigen::Vector3f body_colour(int index);

}  // namespace statsim::tools::render

