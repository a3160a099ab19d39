// 2D shapes for the Box2D reference: simple polygons (concave allowed), their exact mass
// properties, and their split into convex pieces that Box2D can use as fixtures.
#pragma once

#include <string>
#include <vector>

namespace statsim::tools {

struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

/// A simple polygon in its body frame: the origin is the centroid (centre of mass at uniform
/// density), vertices counter-clockwise.
struct Shape2 {
  std::string name;                         ///< "square", "lshape" or "polygon"
  std::string description;                  ///< one line for humans (dimensions)
  std::vector<Point2> outline;              ///< body frame, counter-clockwise, no collinear vertices
  std::vector<std::vector<Point2>> pieces;  ///< convex pieces (CCW, 3..8 vertices) tiling the outline
  std::vector<Point2> hull;                 ///< convex hull of the outline, CCW
  Point2 offset;                            ///< outline = input vertices - offset (the input's centroid)
  double area = 0.0;                        ///< m^2 (= mass in kg at density 1)
  double polar_inertia = 0.0;               ///< about the centroid, per unit density, m^4
  double bounding_radius = 0.0;             ///< farthest vertex from the centroid, m
  double inradius_min = 0.0;                ///< smallest distance from the centroid to a hull edge line, m

  /// Support height of the core shape resting with body-frame up vector `up` (unit): the height
  /// of the centroid above the ground, max over vertices of -(vertex . up).
  double support_height(Point2 up) const;
};

/// The largest number of vertices of a convex piece (Box2D's b2_maxPolygonVertices).
constexpr int kMaxPieceVertices = 8;

/// The 1 x 1 m square (side 1, centred).
Shape2 square_shape();

/// The 2D L: a 1.0 x 0.25 m foot along x and a 0.25 x 0.75 m upright standing on its left end,
/// so both arms are 1 m long and 0.25 m thick (outline (0,0) (1,0) (1,0.25) (0.25,0.25) (0.25,1)
/// (0,1) before centring).
Shape2 lshape_shape();

/// Parses "x1,y1 x2,y2 ..." (whitespace between vertices, a comma inside each). Throws
/// std::invalid_argument with a readable message on bad syntax or non-finite numbers.
std::vector<Point2> parse_polygon(const std::string& spec);

/// Validates a simple polygon (>= 3 vertices, finite, non-zero area, no repeated vertices, not
/// self-intersecting), orients it counter-clockwise, drops collinear vertices, moves the
/// centroid to the origin, computes the mass properties and splits it into convex pieces (ear
/// clipping, then merging neighbouring pieces while they stay convex with <= 8 vertices).
/// Throws std::invalid_argument with a readable message when the polygon is unusable
/// (including pieces too thin for Box2D, whose vertex weld distance is 0.0025 m).
Shape2 make_shape(std::vector<Point2> vertices, std::string name, std::string description);

/// The vertices as "x1,y1 x2,y2 ..." with shortest round-trip decimals.
std::string format_polygon(const std::vector<Point2>& vertices);

}  // namespace statsim::tools
