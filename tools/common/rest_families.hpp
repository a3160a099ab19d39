// Which rest poses a gatherer keeps (statsim gather, statsim gather2d).
//
// A shape with many equivalent poses (a hexagonal nut's six side faces, a die's faces) spreads
// its drops over them: each is rare, together they are common. Cutting poses one by one at a
// frequency would drop them all, and every simulated body would then end in a pose the shape
// rarely takes. So the poses are first grouped into families of poses equivalent under the
// shape's symmetry, and the cut is applied to a family's summed frequency:
//
//  1. Families. Two poses are equivalent when their geometric descriptors agree within a small
//     tolerance: a symmetry of the shape fixes its centre of mass and maps one support face onto
//     the other, so it preserves the rest height, the support face's shape and where the centre
//     projects in it, the moment of inertia about the up axis and the heights of all hull
//     vertices above the ground. Each gatherer computes these from its convex hull (no
//     shape-specific rule). A pose without a descriptor (not on a hull face) is a family of its
//     own.
//  2. Every member of a family whose summed frequency exceeds `min_frequency` is kept.
//  3. Then, while the dropped share (the fraction of the settled drops whose pose is not kept)
//     exceeds `max_dropped`, the most frequent remaining family is kept too, if it was seen in at
//     least `min_count` drops (fewer are no measurement of a frequency).
//  4. Never more than `max_poses` poses in all (the runtime's limit): a family that does not fit
//     whole is not kept.
#pragma once

#include <cstddef>
#include <vector>

namespace statsim::tools {

/// One rest-pose cluster as the selection sees it.
struct RestCandidate {
  double frequency = 0.0;  ///< fraction of the settled drops
  int count = 0;           ///< drops
  /// Geometric invariants, lengths in units of the bounding radius (empty: not on a hull face,
  /// a family of its own). Equal length and every entry within the tolerance: equivalent.
  std::vector<double> descriptor;
};

struct RestSelectionOptions {
  double min_frequency = 0.05;  ///< families above this summed frequency are kept
  double max_dropped = 1.0;     ///< then families are added while the dropped share exceeds this
  /// Fewest drops of a family added by the dropped-share rule: with fewer, a frequency is not
  /// measured (its relative standard error is above 1/sqrt(5), about 45%).
  int min_count = 5;
  std::size_t max_poses = 32;   ///< most poses kept in all (statsim::max_rest_poses)
  /// Descriptors' largest difference within a family, in units of the bounding radius: far above
  /// the rounding of a mesh read from decimal text and of the transform to the body frame (1e-9
  /// and below), far below any difference one could see (0.1 mm on a 0.1 m body).
  double tolerance = 1e-3;
};

struct RestSelection {
  /// Per candidate, its family: 0 is the most frequent family (ties: the one holding the earliest
  /// candidate).
  std::vector<int> family;
  std::vector<double> family_frequency;  ///< per family, the summed frequency
  std::vector<char> kept;                ///< per candidate
  double dropped = 0.0;                  ///< share of the settled drops in poses not kept
};

/// Groups the candidates into families (deterministic: each candidate joins the family of the
/// first earlier candidate equivalent to it).
std::vector<int> rest_families(const std::vector<RestCandidate>& candidates, double tolerance);

/// Applies the rule of the file comment.
RestSelection select_rest_poses(const std::vector<RestCandidate>& candidates, const RestSelectionOptions& options);

}  // namespace statsim::tools
