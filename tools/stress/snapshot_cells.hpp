// The stress matrix's snapshot scene (`statsim stress --scenes snapshot`): statsim only.
#pragma once

#include <functional>
#include <string>

namespace statsim::tools {

/// Receives one cell: scene, method, pass, figure, criterion.
using AddCell = std::function<void(const std::string&, const std::string&, bool, const std::string&, const std::string&)>;

/// A pile (300 bunnies in 3D, 200 squares in 2D) saved at several steps while it settles and
/// loaded into a second world, the two stepped on side by side; a cell per statsim method wanted.
void snapshot_cells(bool want3, bool want2, bool hull_contacts, const AddCell& add);

}  // namespace statsim::tools
