// Loading a 3D signature at run time from the JSON that `statsim gather --json FILE` writes
// (tools/ref3d/gather.cpp json_text()), for host tools that compare tables without compiling them
// in (`statsim fidelity --table NAME=FILE.json`). The runtime itself never parses files; this is
// a host-side stand-in for a generated tables/NAME.hpp.
//
// Fields read: name, length, bounding_radius, mass, unit_inertia, material {restitution,
// friction, rolling_resistance}, restitution_threshold, h_coll {ratio, mean, std},
// response {layout, model, spin (optional: "length" when absent), axes [{values}], mean, spread,
// i16 {mean_scale, mean_offset, spread_scale, spread_offset} (optional)}, rest [{normal, height, frequency}]. Files of table
// format 1 (no "model"; "std" and std_scale / std_offset) load as the paper's model. When the JSON has "i16", the
// response tables are quantised again by the generator's rule, statsim::quantize16 (which must
// give the scales and offsets the JSON states), and used as 16-bit integers, as the generated
// SignatureQ16 header stores them. Tables of format 2.1 also give mesh_frame and body_contacts
// {support_size, support, pair_mean, pair_stddev, faces, packing_mean, packing_stddev}; the
// support map of an i16 table is quantised by statsim::quantize16 as the header stores it.
// Tables of format 2.2 may give landing {hop, cos_theta, spin_ratio, froude, probability}, and
// of format 2.3 settle {quantiles, time} (`quantiles` values for each rest pose).
#pragma once

#include "statsim/signature.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace statsim::tools {

/// 16-bit response values with their scale and offset, as statsim::Quantized16 holds them, in a
/// growable array.
struct LoadedQuantized16 {
  Scalar scale = 1;
  Scalar offset = 0;
  std::vector<std::int16_t> q;
};

/// The parts of a signature loaded from JSON, named as in statsim::BasicSignature so that
/// statsim::signature_view<3> builds their view. `Responses`: std::vector<Scalar> (f32 tables)
/// or LoadedQuantized16 (i16 tables). Unused response axes hold one sample, as in a generated
/// header.
template <class Responses>
struct BasicLoadedSignature3 {
  std::string name;
  Scalar length = 0;
  Scalar bounding_radius = 0;
  Scalar mass = 0;
  std::array<Scalar, 3> unit_inertia{};
  Material material{};
  Scalar restitution_threshold = 0;
  ResponseLayout layout = ResponseLayout::scaled;
  ResponseModel model = ResponseModel::independent_gaussian;
  ResponseSpin spin = ResponseSpin::length;
  std::uint32_t axis_count = 0;  ///< 3 (scaled) or 4 (with_speed)
  std::vector<Scalar> height_axis, height_mean, height_stddev;
  std::vector<Scalar> axis0, axis1, axis2, axis3;
  Responses response_mean, response_spread;
  std::vector<Scalar> rest_normals, rest_heights, rest_frequencies;
  /// Mesh frame (12 numbers); empty in a table without body-body data (the identity).
  std::vector<Scalar> mesh_frame;
  /// Body-body data (statsim::ContactView); support_size 0 when the JSON has none. The support
  /// map is stored as the response tables are (i16 tables: by statsim::quantize16).
  struct Contact {
    std::uint32_t support_size = 0;
    std::vector<Scalar> pair_mean, pair_stddev;
    Responses support;
    std::vector<Scalar> faces;
    std::array<Scalar, 3> packing_mean{}, packing_stddev{};
  } contact;
  /// Landing data (statsim::LandingView); `probability` empty when the JSON has none.
  struct Landing {
    Scalar hop = 0;
    std::vector<Scalar> cos_theta, spin_ratio, froude, probability;
  } landing;
  /// Settling data (statsim::SettleView); `time` empty when the JSON has none.
  struct Settle {
    std::vector<Scalar> time;
  } settle;

  SignatureView<3> view() const { return signature_view<3>(*this); }
};

/// A signature loaded from JSON, owning its arrays; view() points into them (the object must
/// outlive every view and every world that uses one, and must not be moved while they live:
/// moving a std::vector keeps its buffer, so moving the object itself is safe).
struct LoadedSignature3 {
  std::string path;  ///< the file it came from
  /// f32 tables, or i16 tables when the JSON has "response.i16".
  std::variant<BasicLoadedSignature3<std::vector<Scalar>>, BasicLoadedSignature3<LoadedQuantized16>> tables;

  bool i16() const { return tables.index() == 1; }
  /// The table's name (from the JSON; a caller may rename it).
  std::string& name();
  const std::string& name() const;
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
