// See body_contacts.hpp.
#include "common/body_contacts.hpp"

#include "common/format.hpp"
#include "common/table_writer.hpp"
#include "statsim/signature.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace statsim::tools {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct MeanStd {
  double mean = 0.0, std = 0.0;
};

MeanStd mean_std(const std::vector<double>& v)
{
  MeanStd s;
  if (v.empty()) return s;
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  if (v.size() < 2) return s;
  double sq = 0.0;
  for (double x : v) sq += (x - s.mean) * (x - s.mean);
  s.std = std::sqrt(sq / static_cast<double>(v.size() - 1));
  return s;
}

}  // namespace

int packing_bin(double up, double length)
{
  const double deg = std::acos(std::min(1.0, std::fabs(up) / length)) * 180.0 / kPi;
  return deg < 30.0 ? 0 : deg < 60.0 ? 1 : 2;
}

void packing_statistics(const std::array<std::vector<double>, 3>& ratios, BodyContactData& c)
{
  std::vector<double> all;
  for (const auto& r : ratios) all.insert(all.end(), r.begin(), r.end());
  c.total_pairs = static_cast<int>(all.size());
  const MeanStd pooled = mean_std(all);
  for (std::size_t b = 0; b < 3; ++b) {
    c.packing_pairs[b] = static_cast<int>(ratios[b].size());
    c.packing_pooled[b] = ratios[b].size() < static_cast<std::size_t>(kPackingMinPairs);
    const MeanStd s = c.packing_pooled[b] ? pooled : mean_std(ratios[b]);
    c.packing_mean[b] = all.empty() ? 1.0 : s.mean;
    c.packing_std[b] = all.empty() ? 0.0 : s.std;
  }
}

std::string contact_type(const BodyContactData& c, bool i16)
{
  return std::string(i16 ? "ContactDataQ16" : "ContactData") + "<" + std::to_string(c.dims) + ", " +
         std::to_string(c.pair_mean.size()) + ", " + std::to_string(c.support_size) + ", " +
         std::to_string(c.face_count()) + ">";
}

std::string contact_entries(const BodyContactData& c, bool i16, double* i16_error)
{
  const std::size_t dims = static_cast<std::size_t>(c.dims);
  std::string s = table_comment("mesh frame: body point = R (mesh point - c); R row by row, then c (m)");
  s += table_entry(hex_float_array(c.mesh_frame, ArrayStyle{dims, 6, false}));
  const auto inner = [](const std::vector<double>& v, std::size_t per_line = 8) {
    return hex_float_array(v, ArrayStyle{per_line, 8, true, 6});
  };
  const auto entry = [](const std::string& text, const std::string& comment = "") {
    return "      " + text + "," + (comment.empty() ? "" : "  // " + comment) + "\n";
  };
  s += table_comment("body-body data (statsim::ContactView)");
  s += "    {\n";
  s += entry(std::to_string(c.support_size) + "u", "support map nodes a side, S");
  s += "      // pair distance at first contact per h_coll spin ratio: mean, std (m)\n";
  s += entry(inner(c.pair_mean));
  s += entry(inner(c.pair_std));
  s += c.dims == 3 ? "      // support map (m): face f = 2 m + (u_m < 0), value (f S + i) S + j, node -1 + 2 i / (S - 1)\n"
                   : "      // support map (m): side f = 2 m + (u_m < 0), value f S + i, node -1 + 2 i / (S - 1)\n";
  if (i16) {
    std::vector<float> f;
    for (double v : c.support) f.push_back(static_cast<float>(v) + 0.0f);
    std::vector<std::int16_t> q(f.size());
    float scale = 1, offset = 0;
    statsim::quantize16(f.data(), f.size(), scale, offset, q.data());
    double worst = 0.0;
    for (std::size_t i = 0; i < f.size(); ++i) {
      // As the runtime dequantises: offset + scale * Scalar(q), in float.
      const float back = offset + scale * static_cast<float>(q[i]);
      worst = std::max(worst, std::fabs(static_cast<double>(back) - static_cast<double>(f[i])));
    }
    if (i16_error) *i16_error = worst;
    s += entry("{" + hex_floats({scale, offset}) + ", " + int_array(q, ArrayStyle{12, 8, false, 6}) + "}",
               "scale, offset, values");
  } else {
    s += entry(inner(c.support, 6));
  }
  s += "      // hull " + std::string(c.dims == 3 ? "faces" : "edges") +
       ", largest first: outward unit normal (body frame), offset (m)\n";
  s += entry(inner(c.faces, dims + 1));
  s += "      // packing (d / hull distance along the line of centres): mean, std at 0-30, 30-60, 60-90 deg\n";
  s += entry(inner({c.packing_mean[0], c.packing_mean[1], c.packing_mean[2]}));
  s += entry(inner({c.packing_std[0], c.packing_std[1], c.packing_std[2]}));
  s += "    },\n";
  return s;
}

std::string packing_line(const BodyContactData& c)
{
  const char* names[] = {"0-30", "30-60", "60-90"};
  std::string p;
  for (std::size_t b = 0; b < 3; ++b)
    p += std::string(b ? ";" : "") + " " + names[b] + " deg " + fmt("%.4f", c.packing_mean[b]) + " +- " +
         fmt("%.4f", c.packing_std[b]) + " (" + std::to_string(c.packing_pairs[b]) + " pairs" +
         (c.packing_pooled[b] ? ", fewer than " + std::to_string(kPackingMinPairs) + ": all pairs' statistics" : "") +
         ")";
  return p;
}

}  // namespace statsim::tools
