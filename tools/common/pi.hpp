// Pi for the host tools, defined once: M_PI is POSIX, not C++17, and a constant per file would
// clash when the tool libraries are compiled as one unit.
#pragma once

namespace statsim::tools {

constexpr double kPi = 3.14159265358979323846;

}  // namespace statsim::tools
