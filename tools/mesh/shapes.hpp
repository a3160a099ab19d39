#pragma once
/// @file
/// The analytic shapes of the signature tables and tests: the box, the paper's L-shape, the wedge
/// and the hexagonal nut.
///
/// The paper does not give the L-shape's dimensions. Ours is an L profile extruded 0.05 m: a
/// 0.20 x 0.05 x 0.05 m bar (the foot, along x) with a 0.05 x 0.10 x 0.05 m bar standing on one
/// end of it (the upright, along y), so the L is 0.20 m wide and 0.15 m tall, 0.05 m thick
/// everywhere. It is placed with its centre of mass at the origin (the foot has twice the upright's
/// volume). In Bullet it is a btCompoundShape of the two boxes `lshape_boxes()`.

#include "mesh/mesh.hpp"

#include <Eigen/Core>

#include <array>

namespace statsim::tools {

/// A box of a compound: its centre and half extents (axis-aligned in the shape's frame).
struct BoxPart {
  Eigen::Vector3d centre;
  Eigen::Vector3d half_extents;
};

/// The L-shape's two boxes: the foot (centre (0.025, -0.025, 0), half extents (0.1, 0.025,
/// 0.025)) and the upright (centre (-0.05, 0.05, 0), half extents (0.025, 0.05, 0.025)), metres.
std::array<BoxPart, 2> lshape_boxes();

/// A closed box of the given full size centred at the origin: 8 vertices, 12 triangles.
TriMesh make_box(const Eigen::Vector3d& size);

/// A wedge (a right triangular prism): the right triangle with legs `leg_x` along x and `leg_y`
/// along y, extruded `depth` along z, with its centre of mass (the triangle's centroid, mid-depth)
/// at the origin; 6 vertices, 8 triangles. Metres. Used as a shape none of the tables were tuned on.
TriMesh make_wedge(double leg_x, double leg_y, double depth);

/// A hexagonal nut: a regular hexagonal prism `across_corners` wide between opposite corners
/// (across the flats: sqrt(3)/2 of that), `thickness` along z, with a round hole of
/// `hole_diameter` along z (a regular polygon of `hole_segments` vertices on that circle, a
/// multiple of 12), centred (its centre of mass) at the origin, a corner on +x. Metres. Used as a
/// shape with six equivalent side poses. Needs hole_diameter < across_corners sqrt(3)/2.
TriMesh make_nut(double across_corners, double thickness, double hole_diameter, int hole_segments);

/// The L-shape as one closed surface (the two boxes' union, without the shared face): the L
/// profile in the xy plane extruded along z; 12 vertices, 20 triangles.
TriMesh make_lshape();

}  // namespace statsim::tools
