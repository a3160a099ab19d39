// Whole-file writes that never leave a half-written file behind.
#pragma once

#include <filesystem>
#include <string_view>

namespace statsim::tools {

/// Writes `bytes` to `path` atomically: the data goes to a temporary file next to `path`, which
/// is then renamed over `path` (rename is atomic on POSIX file systems). On any failure the
/// temporary file is removed, `path` is left as it was, and std::runtime_error is thrown with a
/// message naming the file and the system error. The parent directory must exist.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);

/// Throws std::runtime_error unless `dir` is (or can be created as) a directory in which files
/// can be written. Call it before a long computation whose results go to `dir`.
void ensure_writable_directory(const std::filesystem::path& dir);

}  // namespace statsim::tools
