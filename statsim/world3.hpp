#pragma once
/// @file
/// The 3D world: bodies with a position, a quaternion orientation and angular velocity vectors.
/// Up is +z.

#include "statsim/world.hpp"

namespace statsim {

using BodyDef3 = BodyDef<3>;
using WorldDef3 = WorldDef<3>;
using Body3 = Body<3>;
using Plane3 = Plane<3>;
using WorldCore3 = WorldCore<3>;

/// A 3D world; see `World` for the capacities.
template <std::uint32_t MaxBodies, std::uint32_t MaxPlanes = 8, std::uint32_t MaxPairs = 6 * MaxBodies,
          std::uint32_t MaxShapes = 8>
using World3 = World<3, MaxBodies, MaxPlanes, MaxPairs, MaxShapes>;

}  // namespace statsim
