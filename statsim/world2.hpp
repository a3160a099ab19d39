#pragma once
/// @file
/// The 2D world (`World2`, `WorldDef2`, `BodyDef2`, ...): bodies with a position in the plane, an
/// orientation `Rot2` and a scalar angular velocity (counter-clockwise positive). Up is +y; planes
/// are lines. Declared in world.hpp with the 3D ones.

#include "statsim/world.hpp"
