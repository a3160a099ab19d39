// See body_contacts.hpp.
#include "common/body_contacts.hpp"
#include "common/stored_values.hpp"

#include "common/format.hpp"
#include "common/pi.hpp"
#include "common/sample_stats.hpp"
#include "common/table_writer.hpp"
#include "statsim/signature.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace statsim::tools {

int packing_bin(double up, double length)
{
  const double deg = std::acos(std::min(1.0, std::fabs(up) / length)) * 180.0 / kPi;
  return deg < 30.0 ? 0 : deg < 60.0 ? 1 : 2;
}

void packing_statistics(const std::vector<PackingSample>& samples, BodyContactData& c)
{
  const std::size_t faces = c.face_count(), per_face = static_cast<std::size_t>(c.dims + 2);
  std::array<std::vector<double>, 3> line;
  std::vector<std::vector<double>> face(faces);
  std::vector<double> all, line_all, face_all;
  for (const PackingSample& p : samples) {
    all.push_back(p.ratio);
    if (p.witness == 0) {
      line[static_cast<std::size_t>(packing_bin(p.up, 1.0))].push_back(p.ratio);
      line_all.push_back(p.ratio);
    } else {
      // Both bodies are of this shape: face i of a is 1 + i, face i of b is 1 + faces + i.
      face[(p.witness - 1) % faces].push_back(p.ratio);
      face_all.push_back(p.ratio);
    }
  }
  c.total_pairs = static_cast<int>(all.size());
  const auto enough = [](const std::vector<double>& v) { return v.size() >= static_cast<std::size_t>(kPackingMinPairs); };
  const MeanStd pooled = all.empty() ? MeanStd{1.0, 0.0} : mean_std(all);
  const MeanStd line_pooled = enough(line_all) ? mean_std(line_all) : pooled;
  const MeanStd face_pooled = enough(face_all) ? mean_std(face_all) : pooled;
  for (std::size_t b = 0; b < 3; ++b) {
    c.packing_pairs[b] = static_cast<int>(line[b].size());
    c.packing_pooled[b] = !enough(line[b]);
    const MeanStd s = c.packing_pooled[b] ? line_pooled : mean_std(line[b]);
    c.packing_mean[b] = s.mean;
    c.packing_std[b] = s.std;
  }
  c.face_pairs.assign(faces, 0);
  c.face_pooled.assign(faces, 0);
  for (std::size_t f = 0; f < faces; ++f) {
    c.face_pairs[f] = static_cast<int>(face[f].size());
    c.face_pooled[f] = !enough(face[f]);
    c.faces[f * per_face + per_face - 1] = c.face_pooled[f] ? face_pooled.mean : mean_std(face[f]).mean;
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
    const Quantized q = quantize(to_float(c.support));
    if (i16_error) *i16_error = q.worst_error;
    s += entry("{" + hex_floats({q.scale, q.offset}) + ", " + int_array(q.q, ArrayStyle{12, 8, false, 6}) + "}",
               "scale, offset, values");
  } else {
    s += entry(inner(c.support, 6));
  }
  s += "      // hull " + std::string(c.dims == 3 ? "faces" : "edges") +
       ", largest first: outward unit normal (body frame), offset (m), packing ratio along it\n";
  s += entry(inner(c.faces, dims + 2));
  s += "      // packing along the line of centres (d / hull distance): mean, std at 0-30, 30-60, 60-90 deg\n";
  s += entry(inner({c.packing_mean[0], c.packing_mean[1], c.packing_mean[2]}));
  s += entry(inner({c.packing_std[0], c.packing_std[1], c.packing_std[2]}));
  s += "    },\n";
  return s;
}

std::string packing_line(const BodyContactData& c)
{
  const char* names[] = {"0-30", "30-60", "60-90"};
  std::string p = " along faces";
  const std::size_t per_face = static_cast<std::size_t>(c.dims + 2);
  for (std::size_t f = 0; f < c.face_count(); ++f)
    p += std::string(f ? "," : "") + " " + fmt("%.4f", c.faces[f * per_face + per_face - 1]) + " (" +
         std::to_string(f < c.face_pairs.size() ? c.face_pairs[f] : 0) +
         (f < c.face_pooled.size() && c.face_pooled[f] ? ", pooled" : "") + ")";
  p += "; along the line of centres";
  for (std::size_t b = 0; b < 3; ++b)
    p += std::string(b ? ";" : "") + " " + names[b] + " deg " + fmt("%.4f", c.packing_mean[b]) + " +- " +
         fmt("%.4f", c.packing_std[b]) + " (" + std::to_string(c.packing_pairs[b]) + " pairs" +
         (c.packing_pooled[b] ? ", pooled" : "") +
         ")";
  return p;
}

}  // namespace statsim::tools
