#pragma once
/// @file
/// What a world's scene uses, fixed in its type: the code of a feature left out is not compiled
/// into the step, and a call that would need it is refused with `Status::not_compiled`.
/// Presets: `spheres`, `paper`, `piles`, `all` (the default); or any `|` of the bits.
///
/// `World<..., Features F>` names the set; the step is compiled once per set (`detail::FeatureSet`),
/// and each decision point of the step tests the set with `if constexpr`. A world never behaves
/// differently for carrying more features than its scene uses: every scene steps bit for bit the
/// same under the full set and under any set that covers it, because a feature left out is one
/// whose runtime condition the world's refusals keep false. Two more parts of the step follow
/// from the world's capacities instead: the grid broad phase (`World`'s `Phases`) and impact
/// events (`MaxImpacts` above 0).

#include <cstdint>

namespace statsim {

/// The features a world's step is compiled with, as bits; combine them with `|`.
enum class Features : std::uint32_t {
  /// Plain spheres on level ground and walls: the particle response only.
  spheres = 0,
  /// Statistical shapes (`add_shape(SignatureView)`): the paper's collision radii, sampled
  /// responses, rest conditions and pile rest. Without it `add_shape(SignatureView)` is refused.
  statistical = 1u << 0,
  /// Body-body contacts at the hulls (`BodyContacts::hulls`): the hull search, tipping over
  /// edges, the supports of the shock pass, worker threads for them. Without it `configure`
  /// refuses `BodyContacts::hulls`.
  hull_contacts = 1u << 1,
  /// Tilted planes (`detail::is_tilted_plane`: gravity pulls along a plane that carries weight):
  /// statistical bodies roll and tumble down them at their hulls, and plain spheres meet them as
  /// on any plane; with `WorldDef::ground_hulls`, level ground after a body's first impact and
  /// slow landings too.
  /// Without it `add_plane` refuses a tilted plane, and `configure` a gravity that tilts a plane
  /// already added or ground hulls.
  slopes = 1u << 2,
  /// Ray casts and sphere overlaps (statsim/queries.hpp), which search the broad phase's records
  /// that each step then widens by how far bodies moved. Without it the queries return
  /// `not_compiled` and the step keeps no such bound.
  queries = 1u << 3,
  /// The paper's method: statistical shapes on level ground and walls.
  paper = statistical,
  /// Piles of statistical shapes with hull contacts, on level ground and walls.
  piles = statistical | hull_contacts,
  /// Everything (the default).
  all = statistical | hull_contacts | slopes | queries,
};

constexpr Features operator|(Features a, Features b) { return Features(std::uint32_t(a) | std::uint32_t(b)); }
constexpr Features operator&(Features a, Features b) { return Features(std::uint32_t(a) & std::uint32_t(b)); }
/// True when every feature of `part` is in `set`.
constexpr bool includes(Features set, Features part) { return (set & part) == part; }

namespace detail {
/// The parts of the step a world compiles: its `Features`, and the grid and impact events its
/// capacities allow. The step's functions take it as a template parameter (`class FS`).
template <Features F, bool Grid, bool Events>
struct FeatureSet {
  static constexpr Features features = F;
  static constexpr bool statistical = includes(F, Features::statistical);
  static constexpr bool hull_contacts = includes(F, Features::hull_contacts);
  static constexpr bool slopes = includes(F, Features::slopes);
  static constexpr bool queries = includes(F, Features::queries);
  static constexpr bool grid = Grid;
  static constexpr bool events = Events;
};
/// Every part: what code outside the step (queries, snapshots, tools) assumes.
using AllFeatures = FeatureSet<Features::all, true, true>;
}  // namespace detail

}  // namespace statsim
