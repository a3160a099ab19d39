// Charts through matplotlib: a host tool writes its data (CSV, JSON) and runs a script of
// tools/plot on it, which draws the chart as PNG and SVG (see tools/plot/style.py).
//
// Usage:
//   plot::run_script("fig3.py", {"out/fig3.csv", "--out", "out/fig3.png"});    // a data file
//   plot::run_script_on("bench.py", bench_csv(r), ".csv", {"--out", "bench.png"});  // data in memory
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace statsim::tools::plot {

/// The directory of the plotting scripts: the source tree's tools/plot, whose absolute path
/// CMake compiles in (so the tools find it from the build tree and after an install alike).
std::filesystem::path script_dir();

/// The Python interpreter that runs the scripts: $STATSIM_PYTHON when set, else the first of
/// `python3` on PATH and /usr/bin/python3 (Debian's, which python3-matplotlib installs for) that
/// can import matplotlib. Throws std::runtime_error naming tools/setup.sh when none can. Call it
/// before a long run whose results end in a chart, so that a missing matplotlib fails early.
std::string find_python();

/// Runs the script `script` of script_dir() with `args` and waits for it; what it prints goes
/// to stdout and stderr. Throws std::runtime_error with the script's error message if it fails
/// (a missing or malformed input, an unwritable output), or as find_python() does.
void run_script(const std::string& script, const std::vector<std::string>& args);

/// As run_script(), with `data` first written to a temporary file whose name ends in `suffix`
/// (".csv", ".json") and passed as the script's first argument; the file is removed afterwards.
void run_script_on(const std::string& script, std::string_view data, const std::string& suffix,
                   const std::vector<std::string>& args);

/// The SVG that the scripts write next to a PNG: `png` with the extension .svg.
std::filesystem::path svg_of(const std::filesystem::path& png);

}  // namespace statsim::tools::plot
