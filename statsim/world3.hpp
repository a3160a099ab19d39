#pragma once
/// @file
/// The 3D world (`World3`, `WorldDef3`, `BodyDef3`, ...): bodies with a position, a quaternion
/// orientation and angular velocity vectors. Up is +z. Declared in world.hpp with the 2D ones.

#include "statsim/world.hpp"
