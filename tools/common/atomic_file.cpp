#include "common/atomic_file.hpp"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <system_error>

#include <unistd.h>

namespace statsim::tools {
namespace {

std::string errno_text(int err)
{
  return std::error_code(err, std::generic_category()).message();
}

// A temporary name next to `path`, unique within this process and across processes.
std::filesystem::path temporary_name(const std::filesystem::path& path)
{
  static std::atomic<unsigned long> counter{0};
  std::string name = "." + path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                     std::to_string(counter.fetch_add(1));
  return path.parent_path() / name;
}

}  // namespace

void write_file_atomic(const std::filesystem::path& path, std::string_view bytes)
{
  if (path.filename().empty()) {
    throw std::runtime_error("cannot write '" + path.string() + "': not a file name");
  }
  const std::filesystem::path tmp = temporary_name(path);
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) {
    throw std::runtime_error("cannot write '" + path.string() + "': " + errno_text(errno));
  }
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  int err = ok ? 0 : errno;
  if (std::fflush(f) != 0 && ok) {
    ok = false;
    err = errno;
  }
  if (std::fclose(f) != 0 && ok) {
    ok = false;
    err = errno;
  }
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    err = errno;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write '" + path.string() + "': " + errno_text(err));
  }
}

void ensure_writable_directory(const std::filesystem::path& dir)
{
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    throw std::runtime_error("cannot create directory '" + dir.string() + "': " + ec.message());
  }
  if (!std::filesystem::is_directory(dir, ec)) {
    throw std::runtime_error("'" + dir.string() + "' is not a directory");
  }
  // Permission bits do not tell the whole story (root, read-only mounts, ACLs): try it.
  const std::filesystem::path probe = dir / ".statsim-write-test";
  try {
    write_file_atomic(probe, "");
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("directory '" + dir.string() + "' is not writable (" + e.what() + ")");
  }
  std::filesystem::remove(probe, ec);
}

}  // namespace statsim::tools
