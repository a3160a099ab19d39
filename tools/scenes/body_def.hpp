// A scene's initial body state (scenes.hpp, double precision) as the runtime's BodyDef, the one
// conversion every tool that runs statsim on a scene makes: positions and velocities rounded to
// Scalar, the orientation normalised after rounding. Shape, mass and the rest are the caller's.
#pragma once

#include "scenes/scenes.hpp"
#include "statsim/world.hpp"

#include <cmath>

namespace statsim::tools::scenes {

inline BodyDef3 body_def(const BodyState3& s)
{
  BodyDef3 b;
  b.position = s.position.cast<Scalar>();
  b.orientation = s.orientation.cast<Scalar>().normalized();
  b.linear_velocity = s.linear_velocity.cast<Scalar>();
  b.angular_velocity = s.angular_velocity.cast<Scalar>();
  return b;
}

inline BodyDef2 body_def(const BodyState2& s)
{
  BodyDef2 b;
  b.position = s.position.cast<Scalar>();
  b.orientation = Rot2{static_cast<Scalar>(std::cos(s.angle)), static_cast<Scalar>(std::sin(s.angle))};
  b.linear_velocity = s.linear_velocity.cast<Scalar>();
  b.angular_velocity = static_cast<Scalar>(s.angular_velocity);
  return b;
}

}  // namespace statsim::tools::scenes
