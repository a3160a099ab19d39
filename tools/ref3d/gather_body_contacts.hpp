// The body-body stage of `statsim gather` (item 4 of the gathering, statsim::ContactView): pair
// distances at first contact, the support map, the largest hull faces and the packing ratios
// measured in Bullet piles and bins on the table's own data.
#pragma once

namespace statsim::tools::ref3d {

struct GatherResult;

/// Packing bins are as wide as gather-pairs' `--bin 2.2`: walls 4.4 L apart, 2 x 2 bodies a layer.
constexpr double kPackingBinHalfWidth = 2.2;

/// Fills `r.contact` for `r.options` and `r.model`.
void gather_body_contacts(GatherResult& r);

}  // namespace statsim::tools::ref3d
