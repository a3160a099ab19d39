// A generated table's numbers as the runtime stores them: Scalar (float), or 16 bits by
// statsim::quantize16 (the one rule, --precision i16). Shared by `statsim gather`, `gather2d`
// and the body-body data's text, so that a header's values and the checks made on them agree.
#pragma once

#include <cstdint>
#include <vector>

namespace statsim::tools {

/// The values as floats, negative zeros made positive (a header never writes -0).
std::vector<float> to_float(const std::vector<double>& v);

/// The 16-bit form of the float (Scalar) values written to a header, by statsim::quantize16, and
/// the largest error of reading them back.
struct Quantized {
  float scale = 1.0f, offset = 0.0f;
  std::vector<std::int16_t> q;
  double worst_error = 0.0;  ///< largest |dequantised - float value|, as the runtime computes it
};
Quantized quantize(const std::vector<float>& values);

}  // namespace statsim::tools
