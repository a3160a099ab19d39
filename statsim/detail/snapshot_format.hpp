#pragma once
/// @file
/// The byte level of world snapshots (statsim/snapshot.hpp): little-endian writing and
/// bounds-checked reading of integers and of the IEEE bits of scalars, the checksum, and the
/// fingerprint of a shape. Nothing here knows the layout of a snapshot.

#include "statsim/detail/world_data.hpp"

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace statsim {
namespace detail {

/// "STSN" read as a little-endian 32-bit word: the first four bytes of every snapshot.
constexpr std::uint32_t snapshot_magic = 0x4e535453u;
/// Version of the snapshot layout; `load` refuses others with `snapshot_incompatible`.
/// 2: `WorldDef::sleep_islands` follows the broad phase.
/// 3: `WorldDef::body_contacts` may be `automatic` (2), the default.
constexpr std::uint16_t snapshot_version = 3;

/// FNV-1a, 64 bits, of `n` bytes: the snapshot's checksum.
inline std::uint64_t fnv1a64(const unsigned char* p, std::size_t n)
{
  Fnv1a h;
  h.add_bytes(p, n);
  return h.value;
}

/// Writes little-endian values into a caller's buffer; with a null buffer it only counts, so
/// that the size of a snapshot and its bytes come from the same code.
class SnapshotWriter {
 public:
  explicit SnapshotWriter(unsigned char* out) : out_(out) {}
  std::size_t size() const { return n_; }

  void u8(std::uint32_t x) { put(x, 1); }
  void u16(std::uint32_t x) { put(x, 2); }
  void u32(std::uint32_t x) { put(x, 4); }
  void u64(std::uint64_t x) { put(x, 8); }
  /// The IEEE bits of a scalar, as an integer of its width: the byte order of the format, not of
  /// the machine.
  void scalar(Scalar x)
  {
    if constexpr (sizeof(Scalar) == 4) {
      std::uint32_t bits;
      std::memcpy(&bits, &x, 4);
      u32(bits);
    } else {
      std::uint64_t bits;
      std::memcpy(&bits, &x, 8);
      u64(bits);
    }
  }
  template <int R>
  void vec(const Eigen::Matrix<Scalar, R, 1>& v)
  {
    for (int i = 0; i < R; ++i) scalar(v[i]);
  }
  void vec(Scalar x) { scalar(x); }  // a 2D spin
  void rot(const Quaternion& q)
  {
    scalar(q.x());
    scalar(q.y());
    scalar(q.z());
    scalar(q.w());
  }
  void rot(const Rot2& r)
  {
    scalar(r.c);
    scalar(r.s);
  }

 private:
  void put(std::uint64_t x, int bytes)
  {
    if (out_ != nullptr)
      for (int i = 0; i < bytes; ++i) out_[n_ + std::size_t(i)] = static_cast<unsigned char>(x >> (8 * i));
    n_ += std::size_t(bytes);
  }
  unsigned char* out_;
  std::size_t n_ = 0;
};

/// Reads little-endian values from a snapshot. Reading past the end gives zeros and clears
/// `ok()`, so a parser can read a record whole and test once.
class SnapshotReader {
 public:
  SnapshotReader(const unsigned char* in, std::size_t size) : in_(in), size_(size) {}
  bool ok() const { return ok_; }
  std::size_t offset() const { return n_; }

  std::uint8_t u8() { return std::uint8_t(get(1)); }
  std::uint16_t u16() { return std::uint16_t(get(2)); }
  std::uint32_t u32() { return std::uint32_t(get(4)); }
  std::uint64_t u64() { return get(8); }
  Scalar scalar()
  {
    Scalar x;
    if constexpr (sizeof(Scalar) == 4) {
      const std::uint32_t bits = u32();
      std::memcpy(&x, &bits, 4);
    } else {
      const std::uint64_t bits = u64();
      std::memcpy(&x, &bits, 8);
    }
    return x;
  }
  template <int R>
  void vec(Eigen::Matrix<Scalar, R, 1>& v)
  {
    for (int i = 0; i < R; ++i) v[i] = scalar();
  }
  void vec(Scalar& x) { x = scalar(); }
  void rot(Quaternion& q)
  {
    const Scalar x = scalar(), y = scalar(), z = scalar(), w = scalar();
    q = Quaternion(w, x, y, z);
  }
  void rot(Rot2& r)
  {
    r.c = scalar();
    r.s = scalar();
  }

 private:
  std::uint64_t get(int bytes)
  {
    if (!ok_ || size_ - n_ < std::size_t(bytes)) {
      ok_ = false;
      return 0;
    }
    std::uint64_t x = 0;
    for (int i = 0; i < bytes; ++i) x |= std::uint64_t(in_[n_ + std::size_t(i)]) << (8 * i);
    n_ += std::size_t(bytes);
    return x;
  }
  const unsigned char* in_;
  std::size_t size_;
  std::size_t n_ = 0;
  bool ok_ = true;
};

/// FNV-1a of everything of a shape that a step reads (its signature through `signature_hash`):
/// a snapshot records it so that `load` can tell whether the world it loads into has the same
/// shapes, since the signature tables themselves are not in the snapshot.
template <int D>
std::uint64_t shape_fingerprint(const Shape<D>& s)
{
  Fnv1a h;
  h.add_all(s.radius, s.bounding_radius, s.material.restitution, s.material.friction, s.material.rolling_resistance,
            std::uint8_t(s.statistical), s.signature_hash, s.mean_rest_height, s.support_floor, s.largest_packing,
            s.mass, s.signature.rest.count);
  for (std::uint32_t k = 0; k < s.signature.rest.count && k < max_rest_poses; ++k) h.add(s.rest_bias[k]);
  return h.value;
}

}  // namespace detail
}  // namespace statsim
