// The output stage of `statsim gather2d`: the generated header (tables/NAME2d.hpp), the JSON
// summary and the summary on stdout, all from a Gather2dResult and nothing else.
#pragma once

#include <string>

namespace statsim::tools {

struct Gather2dResult;

/// The generated header. `command` is the command line recorded in it.
std::string gather2d_header(const Gather2dResult& result, const std::string& command);

/// A JSON summary (statistics, counts and timings).
std::string gather2d_json(const Gather2dResult& result, const std::string& command);

/// A human-readable summary.
std::string gather2d_summary(const Gather2dResult& result);

/// Quotes `s` for a POSIX shell when needed.
std::string shell_quote(const std::string& s);

}  // namespace statsim::tools
