// A RigidState's pose as Bullet's btTransform, for the 3D reference's worlds (reference.cpp) and
// the pair flights of gather-pairs (pairs.cpp).
#pragma once

#include "bullet/bullet.hpp"
#include "ref3d/model.hpp"

namespace statsim::tools::ref3d {

inline btTransform to_bt(const RigidState& s)
{
  return btTransform(btQuaternion(s.orientation.x(), s.orientation.y(), s.orientation.z(), s.orientation.w()),
                     bullet::to_bt(s.position));
}

}  // namespace statsim::tools::ref3d
