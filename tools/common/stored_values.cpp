// See stored_values.hpp.
#include "common/stored_values.hpp"

#include "statsim/signature.hpp"

#include <algorithm>
#include <cmath>

namespace statsim::tools {

std::vector<float> to_float(const std::vector<double>& v)
{
  std::vector<float> f;
  f.reserve(v.size());
  for (double x : v) f.push_back(static_cast<float>(x) + 0.0f);
  return f;
}

Quantized quantize(const std::vector<float>& values)
{
  Quantized out;
  out.q.resize(values.size());
  statsim::quantize16(values.data(), values.size(), out.scale, out.offset, out.q.data());
  for (std::size_t i = 0; i < values.size(); ++i) {
    // As the runtime dequantises: offset + scale * Scalar(q), in float.
    const float back = out.offset + out.scale * static_cast<float>(out.q[i]);
    out.worst_error = std::max(out.worst_error, std::fabs(static_cast<double>(back) - static_cast<double>(values[i])));
  }
  return out;
}

}  // namespace statsim::tools
