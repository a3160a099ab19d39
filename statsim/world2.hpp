#pragma once
/// @file
/// The 2D world: bodies with a position in the plane, an orientation `Rot2` and a scalar angular
/// velocity (counter-clockwise positive). Up is +y; planes are lines.

#include "statsim/world.hpp"

namespace statsim {

using BodyDef2 = BodyDef<2>;
using WorldDef2 = WorldDef<2>;
using Body2 = Body<2>;
using Plane2 = Plane<2>;
using WorldCore2 = WorldCore<2>;

/// A 2D world; see `World` for the capacities.
template <std::uint32_t MaxBodies, std::uint32_t MaxPlanes = 8, std::uint32_t MaxPairs = 6 * MaxBodies,
          std::uint32_t MaxShapes = 8>
using World2 = World<2, MaxBodies, MaxPlanes, MaxPairs, MaxShapes>;

}  // namespace statsim
