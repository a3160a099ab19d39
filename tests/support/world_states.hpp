// Test fixture: comparing the bodies of two 3D statsim worlds bit for bit.
#pragma once

#include "statsim/world3.hpp"

#include <cstdint>

namespace statsim::testing {

/// True when both worlds hold the same number of bodies and each body has the same position and
/// orientation in both, bit for bit.
inline bool same_body_states(const WorldCore3& x, const WorldCore3& y)
{
  if (x.body_count() != y.body_count()) return false;
  for (std::uint32_t i = 0; i < x.body_count(); ++i)
    if (x.body(i).position != y.body(i).position || x.body(i).orientation.coeffs() != y.body(i).orientation.coeffs())
      return false;
  return true;
}

}  // namespace statsim::testing
