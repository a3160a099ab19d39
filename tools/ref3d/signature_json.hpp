// Loading a 3D signature at run time from the JSON that `statsim gather --json FILE` writes
// (tools/ref3d/gather.cpp json_text()), for host tools that compare tables without compiling them
// in (`statsim fidelity --table NAME=FILE.json`). The runtime itself never parses files; this is
// a host-side stand-in for a generated tables/NAME.hpp.
//
// Fields read: name, length, bounding_radius, mass, unit_inertia, material {restitution,
// friction, rolling_resistance}, restitution_threshold, h_coll {ratio, mean, std},
// response {layout, axes [{values}], mean, std, i16 {mean_scale, mean_offset, std_scale,
// std_offset} (optional)}, rest [{normal, height, frequency}]. When the JSON has "i16", the
// response tables are quantised again by the generator's rule (q = nearest integer to
// (v - offset) / scale, clamped to +-32767, v as float) and used as 16-bit integers, as the
// generated SignatureQ16 header stores them.
#pragma once

#include "statsim/signature.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace statsim::tools {

/// A signature loaded from JSON, owning its arrays; view() points into them (the object must
/// outlive every view and every world that uses one, and must not be moved while they live:
/// moving a std::vector keeps its buffer, so moving the object itself is safe).
struct LoadedSignature3 {
  std::string name;
  std::string path;  ///< the file it came from
  Scalar length = 0;
  Scalar bounding_radius = 0;
  Scalar mass = 0;
  std::array<Scalar, 3> unit_inertia{};
  Material material{};
  Scalar restitution_threshold = 0;
  ResponseLayout layout = ResponseLayout::scaled;
  std::vector<Scalar> height_axis, height_mean, height_stddev;
  std::vector<std::vector<Scalar>> axes;  ///< 3 (scaled) or 4 (with_speed)
  std::vector<Scalar> response_mean, response_stddev;  ///< f32 storage (empty when i16)
  bool i16 = false;
  std::vector<std::int16_t> response_mean_q, response_stddev_q;  ///< i16 storage
  Scalar mean_scale = 1, mean_offset = 0, stddev_scale = 1, stddev_offset = 0;
  std::vector<Scalar> rest_normals, rest_heights, rest_frequencies;

  SignatureView<3> view() const;
  /// Table bytes as stored in a generated header: axes, h_coll table, response tables at the
  /// stored precision (4 or 2 bytes a value, plus the i16 scales and offsets), rest poses, and
  /// the scalar fields. Equal to signature_bytes(view()).
  std::size_t bytes() const;
};

/// Bytes of a signature's tables as stored (see LoadedSignature3::bytes): 4 bytes per float
/// (Scalar), 2 per 16-bit response value; the name string is not counted.
std::size_t signature_bytes(const SignatureView<3>& sig);

/// Loads `path`. Throws std::runtime_error with a message naming the file and the problem
/// (unreadable, not JSON, a field missing or of the wrong size, or rejected by the runtime's
/// add_shape, whose status is named).
LoadedSignature3 load_signature_json(const std::string& path);

/// The same from JSON text (`origin` names it in messages).
LoadedSignature3 parse_signature_json(const std::string& text, const std::string& origin);

}  // namespace statsim::tools
