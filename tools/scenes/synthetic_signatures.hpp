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

}  // namespace statsim::testing
