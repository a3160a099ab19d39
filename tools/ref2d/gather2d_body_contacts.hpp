// The body-body stage of `statsim gather2d` (item 4 of the gathering, statsim::ContactView): pair
// distances at first contact, the support map, the longest hull edges and the packing ratios
// measured in the Box2D piles of `statsim compare2d` on the table's own data.
#pragma once

#include "ref2d/gather2d_trials.hpp"

namespace statsim::tools {

struct Gather2dResult;

/// Fills `r.contact` for `r.options` and the context's shape.
void body_contacts_experiment(const Gather2dContext& ctx, Gather2dResult& r);

}  // namespace statsim::tools
