// The body-body data of a generated table (statsim::ContactView), shared by `statsim gather`
// (3D) and `statsim gather2d` (2D): what was measured, the packing statistics by angle bin, and
// its text in the header's aggregate initialiser.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace statsim::tools {

/// Body-body data of a table, everything in the body frame.
struct BodyContactData {
  int dims = 3;  ///< D
  /// Mesh frame: body point = R (mesh point - c); R row by row, then c (D (D + 1) numbers).
  std::vector<double> mesh_frame;
  std::vector<double> pair_mean, pair_std;  ///< m, per h_coll spin ratio
  long long pair_flights = 0;
  int support_size = 0;
  std::vector<double> support;  ///< m, 6 S^2 values (2D: 4 S), layout of statsim::ContactView
  double support_bound = 0.0;   ///< m: the map never reads more than this above the hull's support
  /// Per face, largest first: outward unit normal, offset (m), packing ratio of the pairs whose
  /// hull contact is along it (statsim::face_values(D) numbers a face).
  std::vector<double> faces;
  std::vector<int> face_pairs;      ///< touching pairs per face
  std::vector<char> face_pooled;    ///< the face had too few pairs and took the pooled ratio
  int hull_faces = 0;           ///< faces (2D: edges) of the whole hull
  std::array<double, 3> packing_mean{{1, 1, 1}}, packing_std{{0, 0, 0}};
  std::array<int, 3> packing_pairs{};      ///< pairs touching along their line of centres, per angle bin
  std::array<bool, 3> packing_pooled{};    ///< the bin had too few pairs and took all pairs' statistics
  int total_pairs = 0;
  int piles = 0, bins = 0, asleep = 0;  ///< piles and bins run, and how many ended all asleep
  long long pile_steps = 0;             ///< reference steps over all piles and bins
  double pair_seconds = 0.0, packing_seconds = 0.0;
  std::size_t face_count() const { return faces.size() / static_cast<std::size_t>(dims + 2); }
};

/// An angle bin with fewer touching pairs than this takes the statistics of all pairs.
constexpr int kPackingMinPairs = 10;

/// The angle bin (0: 0-30, 1: 30-60, 2: 60-90 degrees) of a line of centres whose vertical
/// component is `up` over its length `length`.
int packing_bin(double up, double length);

/// A touching pair of a reference pile: d / the runtime's hull distance, and the candidate the
/// runtime's search names (0: the line of centres; else 1 + a face of either body, as
/// statsim::detail::hull_candidate numbers them for two bodies of one shape).
struct PackingSample {
  double ratio = 1.0;
  double up = 0.0;  ///< vertical component of the unit line of centres
  std::uint32_t witness = 0;
};

/// Fills the packing statistics of `c` (its faces already in place, ratio entries overwritten):
/// pairs touching along a face give that face's mean ratio, pairs touching along their line of
/// centres the angle bins' mean and sample standard deviation. A bin or face with fewer than
/// kPackingMinPairs pairs takes the pooled statistics of its kind (line or faces), or of all
/// pairs when its kind has too few too; 1 and 0 when there is no pair at all (the hulls' own
/// distance).
void packing_statistics(const std::vector<PackingSample>& samples, BodyContactData& c);

/// "ContactData<D, NH, S, K>" (or ContactDataQ16 when `i16`).
std::string contact_type(const BodyContactData& c, bool i16);

/// The two entries after the rest poses: the mesh frame and the body-body data "{ ... }," with
/// comments; the support map at 16 bits by statsim::quantize16 when `i16`, its largest
/// dequantisation error in `i16_error` (m).
std::string contact_entries(const BodyContactData& c, bool i16, double* i16_error = nullptr);

/// The packing line of a header: per bin the mean, standard deviation and pairs.
std::string packing_line(const BodyContactData& c);

}  // namespace statsim::tools
