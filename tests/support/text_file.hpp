// Whole-file reads and their lines, for the tests that read what the tools and the documentation
// wrote (tables, reports, measurement files, the .md files).
#pragma once

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace statsim::testing {

/// The whole content of a file ("" if it cannot be read).
inline std::string read_file(const std::filesystem::path& p)
{
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The whole content of a file that must be there: a failed REQUIRE names it.
inline std::string read_text(const std::filesystem::path& p)
{
  REQUIRE_MESSAGE(std::ifstream(p, std::ios::binary).good(), "cannot read " << p.string());
  return read_file(p);
}

/// The lines of a text, without their line feeds.
inline std::vector<std::string> lines_of(const std::string& text)
{
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace statsim::testing
