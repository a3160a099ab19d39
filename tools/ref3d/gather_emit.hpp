// The output stage of `statsim gather`: the generated header (tables/NAME.hpp), the JSON dump
// and the summary on stdout, all from a GatherResult and nothing else.
#pragma once

#include "common/stored_values.hpp"

#include <Eigen/Core>

#include <string>

namespace statsim::tools::ref3d {

struct GatherResult;

/// The generated header. `command` is the command line recorded in it.
std::string header_text(const GatherResult& r, const std::string& command);
/// The JSON dump (pretty-printed, 2-space indent, trailing newline).
std::string json_text(const GatherResult& r, const std::string& command);
/// A short human summary for stdout.
std::string summary_text(const GatherResult& r);

/// "(x, y, z)", each by printf's `f`.
std::string vec3(const Eigen::Vector3d& v, const char* f = "%.6g");

}  // namespace statsim::tools::ref3d
