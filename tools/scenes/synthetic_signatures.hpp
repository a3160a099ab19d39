#pragma once
// Hand-made signatures for runtime tests that must not depend on gathered tables: a unit square
// (2D) and a cube of side 0.2 m (3D), with the heights and rest poses geometry gives them and
// plausible responses (spin kept with its sense but damped, small velocity offsets). The fuzzers
// use them too.
#include "statsim/signature.hpp"

namespace statsim::testing {

inline constexpr Signature<2, 3, 3, 3, 2, 1, 4> square2d_synthetic = {
    "square2d_synthetic",
    0.70710678f,  // L: half diagonal of the unit square
    0.70710678f,
    1.0f,
    {1.0f / 6, 0, 0},  // (1^2 + 1^2) / 12
    Material{0.3f, 0.5f, 0.05f},
    1.0f,
    ResponseLayout::with_speed,
    ResponseModel::independent_gaussian,
    3,
    {0, 2, 8},                   // spin ratio
    {0.635f, 0.66f, 0.70f},      // h_coll mean
    {0.06f, 0.04f, 0.01f},
    {0.2f, 0.6f, 1.0f},          // cos theta
    {-4, 0, 4},                  // signed spin ratio
    {1, 10},                     // speed
    {0},
    // 18 cells x (w L/|v|, dv_x/|v|, dv_y/|v|): spin keeps its sense at a third, offsets small.
    {-1.3f, 0.02f, 0.05f, -1.3f, 0.02f, 0.05f, 0, 0.02f, 0.05f, 0, 0.02f, 0.05f, 1.3f, 0.02f, 0.05f, 1.3f, 0.02f, 0.05f,
     -1.3f, 0.02f, 0.05f, -1.3f, 0.02f, 0.05f, 0, 0.02f, 0.05f, 0, 0.02f, 0.05f, 1.3f, 0.02f, 0.05f, 1.3f, 0.02f, 0.05f,
     -1.3f, 0.02f, 0.05f, -1.3f, 0.02f, 0.05f, 0, 0.02f, 0.05f, 0, 0.02f, 0.05f, 1.3f, 0.02f, 0.05f, 1.3f, 0.02f, 0.05f},
    {0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f,
     0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f,
     0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f, 0.4f, 0.05f, 0.05f},
    {0, 1, 1, 0, 0, -1, -1, 0},  // the four sides
    {0.5f, 0.5f, 0.5f, 0.5f},
    {0.25f, 0.25f, 0.25f, 0.25f},
};

/// Cube of side 0.2 m: 6 rest poses at height 0.1, scaled layout (cos theta, cos phi, spin ratio).
inline constexpr Signature<3, 2, 2, 2, 2, 1, 6> cube_synthetic = {
    "cube_synthetic",
    0.17320508f,  // half the space diagonal
    0.17320508f,
    8.0f,
    {0.04f / 6, 0.04f / 6, 0.04f / 6},
    Material{0.3f, 0.5f, 0.05f},
    0.5f,
    ResponseLayout::scaled,
    ResponseModel::independent_gaussian,
    3,
    {0, 6},
    {0.14f, 0.16f},
    {0.02f, 0.01f},
    {0.2f, 1.0f},
    {-1, 1},
    {0, 4},
    {0},
    // 8 cells x (w_xyz L/|v|, dv_xyz/|v|): zero means, spread in spin and a little in velocity.
    {0, 0, 0, 0, 0, 0.05f, 0, 0, 0, 0, 0, 0.05f, 0, 0, 0, 0, 0, 0.05f, 0, 0, 0, 0, 0, 0.05f,
     0, 0, 0, 0, 0, 0.05f, 0, 0, 0, 0, 0, 0.05f, 0, 0, 0, 0, 0, 0.05f, 0, 0, 0, 0, 0, 0.05f},
    {0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f, 0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f,
     0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f, 0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f,
     0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f, 0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f,
     0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f, 0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f},
    {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1},
    {0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f},
    {1.0f / 6, 1.0f / 6, 1.0f / 6, 1.0f / 6, 1.0f / 6, 1.0f / 6},
};

namespace detail {
/// `cube_synthetic` with another response model: its means, and `spread_of_cell(cell, values)`
/// writing the S spread values of each of its 8 cells.
template <std::uint32_t S, class F>
constexpr Signature<3, 2, 2, 2, 2, 1, 6, S> cube_with_model(ResponseModel model, F spread_of_cell)
{
  const auto& c = cube_synthetic;
  Signature<3, 2, 2, 2, 2, 1, 6, S> s{c.name,        c.length,        c.bounding_radius, c.mass,
                                      c.unit_inertia, c.material,     c.restitution_threshold, c.layout,
                                      model,          c.axis_count,   c.height_axis,     c.height_mean,
                                      c.height_stddev, c.axis0,       c.axis1,           c.axis2,
                                      c.axis3,        c.response_mean, {},               c.rest_normals,
                                      c.rest_heights, c.rest_frequencies};
  for (std::uint32_t cell = 0; cell < 8; ++cell) spread_of_cell(cell, s.response_spread.data() + cell * S);
  return s;
}
}  // namespace detail

/// The cube with the correlated model: the spreads of `cube_synthetic` (0.5 for the spin
/// components, 0.05 for the velocity offsets) and a correlation of -0.6 between w_x and dv_z
/// (an impact that gains spin loses rebound): Cholesky factor rows L_00 = 0.5, L_50 = -0.6 * 0.05,
/// L_55 = 0.8 * 0.05 (0.8 = sqrt(1 - 0.6^2)).
inline constexpr auto cube_correlated_synthetic =
    detail::cube_with_model<21>(ResponseModel::correlated_gaussian, [](std::uint32_t, Scalar* l) {
      for (std::uint32_t k = 0; k < 21; ++k) l[k] = 0;
      for (std::uint32_t i = 0; i < 6; ++i) l[i * (i + 1) / 2 + i] = i < 3 ? 0.5f : 0.05f;
      l[15] = -0.6f * 0.05f;  // row 5 starts at 5 * 6 / 2 = 15: L_50
      l[20] = 0.8f * 0.05f;   // L_55
    });

/// The cube with the empirical model, 4 outcomes a cell and none near the mean: spin about x or
/// about y (+-0.6, sign and axis by outcome) with the velocity offset dv_z +0.04 for the x spins
/// and -0.04 for the y spins; scaled by 1 + cell / 8, so that neighbouring cells differ.
inline constexpr auto cube_empirical_synthetic =
    detail::cube_with_model<24>(ResponseModel::empirical, [](std::uint32_t cell, Scalar* o) {
      const Scalar f = 1 + Scalar(cell) / 8;
      for (std::uint32_t k = 0; k < 24; ++k) o[k] = 0;
      o[0 * 6 + 0] = 0.6f * f;
      o[0 * 6 + 5] = 0.04f * f;
      o[1 * 6 + 0] = -0.6f * f;
      o[1 * 6 + 5] = 0.04f * f;
      o[2 * 6 + 1] = 0.6f * f;
      o[2 * 6 + 5] = -0.04f * f;
      o[3 * 6 + 1] = -0.6f * f;
      o[3 * 6 + 5] = -0.04f * f;
    });

/// The cube's table on a body of unequal moments, its spin measured by energy (format 2.5,
/// `ResponseSpin::energy`): the tables of `cube_synthetic` and the moments over mass of a
/// 0.1 x 0.2 x 0.4 m box, (b^2 + c^2) / 12 and so on, whose ratio 4 between largest and
/// smallest makes the lookup's |K W-| L / (k |V-|) and the draw's R diag(sqrt(m / I_k)) R^T
/// differ from the paper's by the body's orientation.
inline constexpr auto cube_energy_synthetic = [] {
  auto s = cube_synthetic;
  s.name = "cube_energy_synthetic";
  s.unit_inertia = {0.2f / 12, 0.17f / 12, 0.05f / 12};
  s.spin = ResponseSpin::energy;
  return s;
}();

}  // namespace statsim::testing
