#pragma once
/// @file
/// What a world refuses because its step was compiled without a feature (statsim/features.hpp):
/// each refusal keeps false a runtime condition whose code the step left out, so that the world
/// steps bit for bit as it would with every feature.

#include "statsim/detail/slope.hpp"
#include "statsim/detail/world_data.hpp"
#include "statsim/features.hpp"
#include "statsim/status.hpp"
#include "statsim/world_def.hpp"

#include <cstdint>

namespace statsim {
namespace detail {

/// `not_compiled` when the parameters `def` need a feature the world `w` lacks: hull contacts
/// without `Features::hull_contacts`; without `Features::slopes`, a gravity that tilts one of
/// its planes (`is_tilted_plane`); else `ok`.
template <int D>
Status check_features(const WorldData<D>& w, const WorldDef<D>& def)
{
  if (def.body_contacts == BodyContacts::hulls && !includes(w.features, Features::hull_contacts))
    return Status::not_compiled;
  if (!includes(w.features, Features::slopes)) {
    Scalar gn;
    for (std::uint32_t p = 0; p < w.plane_count; ++p)
      if (is_tilted_plane(def.gravity, w.planes[p].normal, gn)) return Status::not_compiled;
  }
  return Status::ok;
}

/// `not_compiled` when a world `w` without `Features::statistical` would get a statistical
/// shape, else `ok`.
template <int D>
Status check_statistical(const WorldData<D>& w)
{
  return includes(w.features, Features::statistical) ? Status::ok : Status::not_compiled;
}

}  // namespace detail
}  // namespace statsim
