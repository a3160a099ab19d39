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

/// `not_compiled` when a plane of unit normal `n` is tilted under gravity `g` (`is_tilted_plane`)
/// in a world of features `f` without `Features::slopes`, else `ok`.
template <class Vec>
Status check_plane_features(Features f, const Vec& g, const Vec& n)
{
  Scalar gn;
  return !includes(f, Features::slopes) && is_tilted_plane(g, n, gn) ? Status::not_compiled : Status::ok;
}

/// `not_compiled` when parameters `def` ask for hull contacts of a world of features `f` without
/// `Features::hull_contacts`, or for ground hulls (`WorldDef::ground_hulls`, the slopes' contact)
/// without `Features::slopes`, else `ok`.
template <int D>
Status check_def_features(Features f, const WorldDef<D>& def)
{
  if (def.body_contacts == BodyContacts::hulls && !includes(f, Features::hull_contacts)) return Status::not_compiled;
  return def.ground_hulls && !includes(f, Features::slopes) ? Status::not_compiled : Status::ok;
}

/// `not_compiled` when the parameters `def` need a feature the world `w` lacks: hull contacts, or
/// a gravity that tilts one of its planes; else `ok`.
template <int D>
Status check_features(const WorldData<D>& w, const WorldDef<D>& def)
{
  Status s = check_def_features(w.features, def);
  for (std::uint32_t p = 0; p < w.plane_count && s == Status::ok; ++p)
    s = check_plane_features(w.features, def.gravity, w.planes[p].normal);
  return s;
}

}  // namespace detail
}  // namespace statsim
