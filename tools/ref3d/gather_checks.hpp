// The checks of the 3D reference that `statsim gather` runs on request (--speed-check,
// --step-check, --settings-check): markdown reports on whether its trials measure what the
// signature assumes, not parts of a table.
#pragma once

#include "ref3d/gather_options.hpp"

#include <string>
#include <vector>

namespace statsim::tools::ref3d {

/// `gather --speed-check`: normalised response means at several |V-| for a few cells (markdown).
std::string speed_check_report(const GatherOptions& o, const std::vector<double>& speeds, int trials);
/// `gather --step-check`: the statistics of a small gathering at dt and dt/2 (markdown).
std::string step_check_report(const GatherOptions& o);
/// The reference-settings check: a face-down cube at normal incidence, Bullet's defaults vs ours.
std::string settings_check_report(const GatherOptions& o);

}  // namespace statsim::tools::ref3d
