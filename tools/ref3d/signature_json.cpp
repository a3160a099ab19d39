#include "ref3d/signature_json.hpp"

#include "statsim/world3.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace statsim::tools {
namespace {

using json = nlohmann::json;

[[noreturn]] void fail(const std::string& origin, const std::string& what)
{
  throw std::runtime_error(origin + ": " + what);
}

const json& field(const json& j, const char* key, const std::string& origin, const std::string& where = "")
{
  if (!j.is_object() || !j.contains(key)) fail(origin, "missing field '" + where + key + "'");
  return j.at(key);
}

Scalar number(const json& j, const char* key, const std::string& origin, const std::string& where = "")
{
  const json& v = field(j, key, origin, where);
  if (!v.is_number()) fail(origin, "field '" + where + key + "' is not a number");
  return static_cast<Scalar>(v.get<double>());
}

std::vector<Scalar> numbers(const json& j, const char* key, const std::string& origin, const std::string& where = "")
{
  const json& v = field(j, key, origin, where);
  if (!v.is_array()) fail(origin, "field '" + where + key + "' is not an array");
  std::vector<Scalar> out;
  out.reserve(v.size());
  for (const json& x : v) {
    if (!x.is_number()) fail(origin, "field '" + where + key + "' holds a value that is not a number");
    out.push_back(static_cast<Scalar>(x.get<double>()));
  }
  return out;
}

void expect_size(const std::vector<Scalar>& v, std::size_t n, const std::string& name, const std::string& origin)
{
  if (v.size() != n)
    fail(origin, "field '" + name + "' has " + std::to_string(v.size()) + " values, expected " + std::to_string(n));
}

// Response tables as floats.
void set_responses(BasicLoadedSignature3<std::vector<Scalar>>& s, std::vector<Scalar> mean, std::vector<Scalar> spread,
                   const json&, const std::string&)
{
  s.response_mean = std::move(mean);
  s.response_spread = std::move(spread);
}

// Response tables as 16-bit integers, by the generator's rule (statsim::quantize16), which must
// give the scales and offsets that `i16` states.
void set_responses(BasicLoadedSignature3<LoadedQuantized16>& s, std::vector<Scalar> mean, std::vector<Scalar> spread,
                   const json& i16, const std::string& origin)
{
  const Scalar mean_scale = number(i16, "mean_scale", origin, "response.i16.");
  const Scalar mean_offset = number(i16, "mean_offset", origin, "response.i16.");
  // Files of table format 1 name the spread "std".
  const bool old = !i16.contains("spread_scale");
  const Scalar std_scale = number(i16, old ? "std_scale" : "spread_scale", origin, "response.i16.");
  const Scalar std_offset = number(i16, old ? "std_offset" : "spread_offset", origin, "response.i16.");
  if (!(mean_scale > 0) || !(std_scale > 0)) fail(origin, "i16 scales must be positive");
  const auto quantized = [&](const std::vector<Scalar>& values, Scalar scale, Scalar offset, const char* table) {
    LoadedQuantized16 q;
    q.q.resize(values.size());
    quantize16(values.data(), values.size(), q.scale, q.offset, q.q.data());
    if (q.scale != scale || q.offset != offset)
      fail(origin, std::string("the i16 scale and offset of the ") + table +
                       " table are not those of the 16-bit rule (statsim::quantize16) for its values");
    return q;
  };
  s.response_mean = quantized(mean, mean_scale, mean_offset, "mean");
  s.response_spread = quantized(spread, std_scale, std_offset, "spread");
}

// The support map as the table stores it: floats, or 16 bits by statsim::quantize16.
void set_support(BasicLoadedSignature3<std::vector<Scalar>>& s, std::vector<Scalar> values)
{
  s.contact.support = std::move(values);
}
void set_support(BasicLoadedSignature3<LoadedQuantized16>& s, const std::vector<Scalar>& values)
{
  LoadedQuantized16& q = s.contact.support;
  q.q.resize(values.size());
  quantize16(values.data(), values.size(), q.scale, q.offset, q.q.data());
}

// Every part of `s` from the JSON `j`, checked in the order of the format.
template <class Responses>
void parse_parts(const json& j, BasicLoadedSignature3<Responses>& s, const std::string& origin)
{
  const json& name = field(j, "name", origin);
  if (!name.is_string()) fail(origin, "field 'name' is not a string");
  s.name = name.get<std::string>();
  s.length = number(j, "length", origin);
  s.bounding_radius = number(j, "bounding_radius", origin);
  s.mass = number(j, "mass", origin);
  const std::vector<Scalar> ui = numbers(j, "unit_inertia", origin);
  expect_size(ui, 3, "unit_inertia", origin);
  std::copy(ui.begin(), ui.end(), s.unit_inertia.begin());
  const json& mat = field(j, "material", origin);
  s.material.restitution = number(mat, "restitution", origin, "material.");
  s.material.friction = number(mat, "friction", origin, "material.");
  s.material.rolling_resistance = number(mat, "rolling_resistance", origin, "material.");
  s.restitution_threshold = number(j, "restitution_threshold", origin);

  const json& h = field(j, "h_coll", origin);
  s.height_axis = numbers(h, "ratio", origin, "h_coll.");
  s.height_mean = numbers(h, "mean", origin, "h_coll.");
  s.height_stddev = numbers(h, "std", origin, "h_coll.");
  if (s.height_axis.empty()) fail(origin, "field 'h_coll.ratio' is empty");
  expect_size(s.height_mean, s.height_axis.size(), "h_coll.mean", origin);
  expect_size(s.height_stddev, s.height_axis.size(), "h_coll.std", origin);

  const json& r = field(j, "response", origin);
  const json& layout = field(r, "layout", origin, "response.");
  if (layout == "scaled") s.layout = ResponseLayout::scaled;
  else if (layout == "with_speed") s.layout = ResponseLayout::with_speed;
  else fail(origin, "field 'response.layout' is neither \"scaled\" nor \"with_speed\"");
  const json& axes = field(r, "axes", origin, "response.");
  const std::size_t want_axes = s.layout == ResponseLayout::scaled ? 3 : 4;
  if (!axes.is_array() || axes.size() != want_axes)
    fail(origin, "field 'response.axes' must hold " + std::to_string(want_axes) + " axes for this layout");
  s.axis_count = static_cast<std::uint32_t>(want_axes);
  std::vector<Scalar>* const parts[] = {&s.axis0, &s.axis1, &s.axis2, &s.axis3};
  std::size_t cells = 1;
  for (std::size_t a = 0; a < want_axes; ++a) {
    *parts[a] = numbers(axes[a], "values", origin, "response.axes[].");
    if (parts[a]->empty()) fail(origin, "a response axis is empty");
    cells *= parts[a]->size();
  }
  if (want_axes == 3) s.axis3 = {0};
  // Files without "model" (table format 1) hold the paper's model, their spread as "std".
  s.model = ResponseModel::independent_gaussian;
  if (r.contains("model")) {
    const json& m = r.at("model");
    if (m == "paper") s.model = ResponseModel::independent_gaussian;
    else if (m == "correlated") s.model = ResponseModel::correlated_gaussian;
    else if (m == "empirical") s.model = ResponseModel::empirical;
    else fail(origin, "field 'response.model' is not \"paper\", \"correlated\" or \"empirical\"");
  }
  // Files without "spin" (before table format 2.4) measure spin by length.
  s.spin = ResponseSpin::length;
  if (r.contains("spin")) {
    const json& m = r.at("spin");
    if (m == "length") s.spin = ResponseSpin::length;
    else if (m == "gyration") s.spin = ResponseSpin::gyration;
    else if (m == "energy") s.spin = ResponseSpin::energy;
    else fail(origin, "field 'response.spin' is not \"length\", \"gyration\" or \"energy\"");
  }
  std::vector<Scalar> mean = numbers(r, "mean", origin, "response.");
  std::vector<Scalar> spread = numbers(r, r.contains("spread") ? "spread" : "std", origin, "response.");
  expect_size(mean, cells * 6, "response.mean", origin);
  if (s.model != ResponseModel::empirical)
    expect_size(spread, cells * response_spread_size(s.model, 6), "response.spread", origin);
  else if (spread.empty() || spread.size() % (cells * 6) != 0)
    fail(origin, "field 'response.spread' of an empirical table must hold whole outcomes for every cell");
  set_responses(s, std::move(mean), std::move(spread), r.contains("i16") ? r.at("i16") : json(), origin);

  const json& rest = field(j, "rest", origin);
  if (!rest.is_array()) fail(origin, "field 'rest' is not an array");
  for (const json& p : rest) {
    const std::vector<Scalar> n = numbers(p, "normal", origin, "rest[].");
    expect_size(n, 3, "rest[].normal", origin);
    s.rest_normals.insert(s.rest_normals.end(), n.begin(), n.end());
    s.rest_heights.push_back(number(p, "height", origin, "rest[]."));
    s.rest_frequencies.push_back(number(p, "frequency", origin, "rest[]."));
  }

  // Landing data (table format 2.2): optional; its values are checked by add_shape.
  if (j.contains("landing")) {
    const json& l = field(j, "landing", origin);
    s.landing.hop = number(l, "hop", origin, "landing.");
    s.landing.cos_theta = numbers(l, "cos_theta", origin, "landing.");
    s.landing.spin_ratio = numbers(l, "spin_ratio", origin, "landing.");
    s.landing.froude = numbers(l, "froude", origin, "landing.");
    s.landing.probability = numbers(l, "probability", origin, "landing.");
    if (s.landing.cos_theta.empty() || s.landing.spin_ratio.empty() || s.landing.froude.empty())
      fail(origin, "a landing axis is empty");
    expect_size(s.landing.probability,
                s.landing.cos_theta.size() * s.landing.spin_ratio.size() * s.landing.froude.size(),
                "landing.probability", origin);
  }
  // Settling data (table format 2.3): optional; its values are checked by add_shape.
  if (j.contains("settle")) {
    const json& t = field(j, "settle", origin);
    const Scalar quantiles = number(t, "quantiles", origin, "settle.");
    if (!(quantiles >= 1 && quantiles <= Scalar(max_settle_quantiles)) || quantiles != std::floor(quantiles))
      fail(origin,
           "field 'settle.quantiles' must be a whole number in [1, " + std::to_string(max_settle_quantiles) + "]");
    s.settle.time = numbers(t, "time", origin, "settle.");
    expect_size(s.settle.time, static_cast<std::size_t>(quantiles) * s.rest_heights.size(), "settle.time", origin);
  }
  if (!j.contains("body_contacts")) return;
  s.mesh_frame = numbers(j, "mesh_frame", origin);
  expect_size(s.mesh_frame, 12, "mesh_frame", origin);
  const json& c = field(j, "body_contacts", origin);
  const Scalar size = number(c, "support_size", origin, "body_contacts.");
  if (!(size >= 2 && size <= Scalar(max_support_size)) || size != std::floor(size))
    fail(origin, "field 'body_contacts.support_size' must be a whole number in [2, " +
                     std::to_string(max_support_size) + "]");
  s.contact.support_size = static_cast<std::uint32_t>(size);
  std::vector<Scalar> support = numbers(c, "support", origin, "body_contacts.");
  expect_size(support, support_values(3, s.contact.support_size), "body_contacts.support", origin);
  set_support(s, std::move(support));
  s.contact.pair_mean = numbers(c, "pair_mean", origin, "body_contacts.");
  s.contact.pair_stddev = numbers(c, "pair_stddev", origin, "body_contacts.");
  expect_size(s.contact.pair_mean, s.height_axis.size(), "body_contacts.pair_mean", origin);
  expect_size(s.contact.pair_stddev, s.height_axis.size(), "body_contacts.pair_stddev", origin);
  s.contact.faces = numbers(c, "faces", origin, "body_contacts.");
  if (s.contact.faces.size() % statsim::face_values(3) != 0)
    fail(origin, "field 'body_contacts.faces' must hold 5 numbers a face (normal, offset, packing ratio)");
  const std::vector<Scalar> pm = numbers(c, "packing_mean", origin, "body_contacts.");
  const std::vector<Scalar> ps = numbers(c, "packing_stddev", origin, "body_contacts.");
  expect_size(pm, 3, "body_contacts.packing_mean", origin);
  expect_size(ps, 3, "body_contacts.packing_stddev", origin);
  std::copy(pm.begin(), pm.end(), s.contact.packing_mean.begin());
  std::copy(ps.begin(), ps.end(), s.contact.packing_stddev.begin());
}

}  // namespace

std::string& LoadedSignature3::name()
{
  return std::visit([](auto& t) -> std::string& { return t.name; }, tables);
}

const std::string& LoadedSignature3::name() const
{
  return std::visit([](const auto& t) -> const std::string& { return t.name; }, tables);
}

SignatureView<3> LoadedSignature3::view() const
{
  return std::visit([](const auto& t) { return t.view(); }, tables);
}

std::size_t LoadedSignature3::bytes() const
{
  return signature_bytes(view());
}

std::size_t signature_bytes(const SignatureView<3>& sig)
{
  const std::size_t f = sizeof(Scalar);
  // length, bounding radius, mass, 3 unit inertia, 3 material, restitution threshold; layout
  // and model (one byte each, in one padded 4-byte word) and the axis count.
  std::size_t bytes = 10 * f + 8;
  bytes += 3 * sig.height.spin_ratio.size * f;  // axis, mean, std
  std::size_t cells = 1;
  for (std::uint32_t a = 0; a < max_response_axes; ++a) {
    bytes += sig.response.axes[a].size * f;
    cells *= sig.response.axes[a].size;
  }
  const std::size_t values = cells * (sig.response.components + sig.response.spread_per_cell);
  const bool q16 = sig.response.mean.f32 == nullptr;
  bytes += q16 ? values * sizeof(std::int16_t) + 4 * f : values * f;
  bytes += sig.rest.count * (3 + 2) * f;  // normal, height, frequency
  if (sig.landing.present()) {  // hop, axes, probabilities
    bytes += f + sig.landing.probability.size * f;
    for (const AxisView& a : sig.landing.axes) bytes += a.size * f;
  }
  bytes += sig.settle.time.size * f;  // the quantiles of every rest pose
  return bytes;
}

LoadedSignature3 parse_signature_json(const std::string& text, const std::string& origin)
{
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    fail(origin, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) fail(origin, "not a JSON object");
  LoadedSignature3 s;
  s.path = origin;
  const json* response = j.contains("response") ? &j.at("response") : nullptr;
  if (response && response->is_object() && response->contains("i16")) s.tables.emplace<1>();
  try {
    std::visit([&](auto& t) { parse_parts(j, t, origin); }, s.tables);
  } catch (const json::exception& e) {
    fail(origin, std::string("bad field: ") + e.what());
  }

  // The runtime's own checks (finite, positive, increasing axes, unit normals, sizes within its
  // limits): a table it would reject is reported here rather than at the first world.
  World3<1, 1, 1, 1> world{WorldDef3{}};
  const Added<ShapeId> added = world.add_shape(s.view());
  if (!added.ok()) fail(origin, std::string("the runtime rejects the table: add_shape returned ") + to_string(added.status));
  return s;
}

LoadedSignature3 load_signature_json(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::ostringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) throw std::runtime_error(path + ": read error");
  return parse_signature_json(text.str(), path);
}

}  // namespace statsim::tools
