// Reading a fuzzer's bytes as a sequence of calls: small integers, and numbers that are mostly in
// a useful range with, now and then, the values that break arithmetic (NaN, infinities, huge and
// tiny magnitudes, a raw bit pattern). Used by the libFuzzer targets in tests/fuzz and their
// replay driver; exhausted input reads as zeros, so every byte string is a valid program.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

namespace statsim::fuzz {

class Input {
 public:
  Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool empty() const { return pos_ >= size_; }
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : std::uint8_t(0); }
  /// Uniform-ish integer in [0, n), n >= 1.
  std::uint32_t below(std::uint32_t n) { return std::uint32_t(byte()) % n; }

  /// A number in [-scale, scale] (65535 steps), or one time in 32 a special value. `special()`
  /// says whether any special value was read since the last `clear_special()`.
  float value(float scale)
  {
    const std::uint8_t b = byte();
    if (b >= 248) {
      special_ = true;
      switch (b - 248) {
        case 0: return std::numeric_limits<float>::quiet_NaN();
        case 1: return std::numeric_limits<float>::infinity();
        case 2: return -std::numeric_limits<float>::infinity();
        case 3: return 1e30f;
        case 4: return -1e30f;
        case 5: return std::numeric_limits<float>::denorm_min();
        case 6: return std::numeric_limits<float>::max();
        default: {
          std::uint32_t bits = 0;
          for (int i = 0; i < 4; ++i) bits = bits << 8 | byte();
          float f;
          std::memcpy(&f, &bits, sizeof f);
          return f;
        }
      }
    }
    const std::uint16_t q = std::uint16_t(b << 8 | byte());
    return scale * (float(q) / 32767.5f - 1.0f);
  }
  /// As value(), in [0, scale].
  float positive(float scale) { return std::fabs(value(scale)); }

  bool special() const { return special_; }
  void clear_special() { special_ = false; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool special_ = false;
};

/// Stops the process in a way both libFuzzer and the replay test report as a failure.
[[noreturn]] inline void fail(const char* what)
{
  (void)what;
  __builtin_trap();
}

}  // namespace statsim::fuzz
