// Test fixture: the numbers of a generated signature table (tables/NAME.hpp, as the gatherers
// write it), read back from its text, to compare with what the gatherer or a loader holds.
// Tests only (doctest REQUIRE).
#pragma once

#include <doctest/doctest.h>

#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

namespace statsim::testing {

/// The numbers of a generated header's initializer, in order: hex floats (`floats`), and the
/// integers (`ints`: the axis count, and the values of i16 tables).
struct HeaderNumbers {
  std::vector<double> floats;
  std::vector<long> ints;
};

inline HeaderNumbers header_numbers(const std::string& text)
{
  HeaderNumbers n;
  const std::size_t start = text.find("= {");
  REQUIRE(start != std::string::npos);
  const std::string body = std::regex_replace(text.substr(start), std::regex("//[^\n]*"), "");  // no comments
  const std::regex token("(-?0x[0-9a-fA-Fp.+-]+)f|(-?[0-9]+)u?");
  for (auto it = std::sregex_iterator(body.begin(), body.end(), token); it != std::sregex_iterator(); ++it) {
    if ((*it)[1].matched) n.floats.push_back(std::strtod((*it)[1].str().c_str(), nullptr));
    else n.ints.push_back(std::strtol((*it)[2].str().c_str(), nullptr, 10));
  }
  return n;
}

}  // namespace statsim::testing
