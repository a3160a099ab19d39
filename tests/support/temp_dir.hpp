// Test fixtures for the tests of the host tools: a fresh temporary directory (and, through
// text_file.hpp, whole-file reads).
// Tests only (the doctest REQUIRE in the constructor).
#pragma once

#include "text_file.hpp"  // beside this file

#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include <stdlib.h>  // mkdtemp

namespace statsim::testing {

/// A fresh directory under the system's temporary directory, named `statsim-test-NAME-XXXXXX`
/// (unique: mkdtemp), removed with its contents at scope exit.
struct TempDir {
  std::filesystem::path path;

  explicit TempDir(const std::string& name)
  {
    std::string tmpl = (std::filesystem::temp_directory_path() / ("statsim-test-" + name + "-XXXXXX")).string();
    const char* p = ::mkdtemp(tmpl.data());
    REQUIRE(p != nullptr);
    path = p;
  }
  ~TempDir()
  {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  /// The path of `name` in the directory (the file need not exist).
  std::string file(const std::string& name) const { return (path / name).string(); }
  /// Writes `content` to `name` in the directory; returns its path.
  std::string write(const std::string& name, const std::string& content) const
  {
    std::ofstream(path / name, std::ios::binary) << content;
    return file(name);
  }
  /// Names of the directory's entries, sorted.
  std::vector<std::string> entries() const
  {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
};

}  // namespace statsim::testing
