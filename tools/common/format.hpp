// Numbers as text for the host tools' reports, comments of generated files and recorded options.
#pragma once

#include <string>
#include <vector>

namespace statsim::tools {

/// `x` formatted by printf's `format`, which must hold exactly one conversion of a double
/// ("%.6g", "%+.4f"...).
std::string fmt(const char* format, double x);

/// printf's `format` with any arguments, as a string (at most 511 characters: a line of a report).
#if defined(__GNUC__)
__attribute__((format(printf, 1, 2)))
#endif
std::string printf_string(const char* format, ...);

/// The shortest decimal that reads back to the same double ("0.05", "1e-07"); integers below
/// 1e15 in full ("1000", not "1e+03"), and zero of either sign as "0".
std::string num(double x);

/// The items of a comma-separated option value, empty ones included ("a,,b": "a", "", "b"), so
/// that a caller giving one label per column keeps the columns in place.
std::vector<std::string> split_list(const std::string& s);

}  // namespace statsim::tools
