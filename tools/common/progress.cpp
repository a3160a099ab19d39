#include "common/progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include <unistd.h>

namespace statsim::tools {

Progress::Progress(std::string label, std::uint64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      terminal_(enabled && ::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()),
      interval_(terminal_ ? std::chrono::steady_clock::duration(std::chrono::milliseconds(100))
                          : std::chrono::steady_clock::duration(std::chrono::seconds(5)))
{
  next_print_.store(interval_.count(), std::memory_order_relaxed);
}

Progress::~Progress()
{
  finish();
}

double Progress::elapsed_seconds() const
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::add(std::uint64_t n)
{
  done_.fetch_add(n, std::memory_order_relaxed);
  if (!enabled_) {
    return;
  }
  const std::int64_t now = (std::chrono::steady_clock::now() - start_).count();
  if (now < next_print_.load(std::memory_order_relaxed)) {
    return;
  }
  // Whoever gets the lock prints; the others carry on computing.
  std::unique_lock<std::mutex> lock(print_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_ || now < next_print_.load(std::memory_order_relaxed)) {
    return;
  }
  next_print_.store(now + interval_.count(), std::memory_order_relaxed);
  print(false);
}

void Progress::finish()
{
  if (!enabled_) {
    return;
  }
  std::lock_guard<std::mutex> lock(print_mutex_);
  if (finished_) {
    return;
  }
  finished_ = true;
  print(true);
}

std::string Progress::format_duration(double seconds)
{
  char buf[32];
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) {
    return "?";
  }
  if (seconds < 60.0) {
    std::snprintf(buf, sizeof buf, "%.1fs", seconds);
  } else if (seconds < 3600.0) {
    const long s = std::lround(seconds);
    std::snprintf(buf, sizeof buf, "%ldm%02lds", s / 60, s % 60);
  } else {
    const long m = std::lround(seconds / 60.0);
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", m / 60, m % 60);
  }
  return buf;
}

// Called with print_mutex_ held.
void Progress::print(bool final_line)
{
  const std::uint64_t done = done_.load(std::memory_order_relaxed);
  const double elapsed = elapsed_seconds();
  const double fraction =
      total_ == 0 ? 1.0 : static_cast<double>(done) / static_cast<double>(total_);
  char line[256];
  int len = std::snprintf(line, sizeof line, "%s: %llu/%llu (%.1f%%) elapsed %s", label_.c_str(),
                          static_cast<unsigned long long>(done),
                          static_cast<unsigned long long>(total_), 100.0 * fraction,
                          format_duration(elapsed).c_str());
  if (!final_line && len > 0 && static_cast<std::size_t>(len) < sizeof line) {
    const std::string eta =
        done == 0 ? std::string("?")
                  : format_duration(elapsed * static_cast<double>(total_ - std::min(done, total_)) /
                                    static_cast<double>(done));
    len += std::snprintf(line + len, sizeof line - static_cast<std::size_t>(len), ", ETA %s",
                         eta.c_str());
  }
  std::string text(line, len < 0 ? 0 : std::min<std::size_t>(static_cast<std::size_t>(len), sizeof line - 1));
  if (terminal_) {
    // Pad with blanks to erase the tail of a longer previous line.
    const std::size_t width = text.size();
    if (width < last_width_) {
      text.append(last_width_ - width, ' ');
    }
    last_width_ = width;
    text.insert(text.begin(), '\r');
    if (final_line) {
      text.push_back('\n');
    }
  } else {
    text.push_back('\n');
  }
  std::fputs(text.c_str(), stderr);
  std::fflush(stderr);
}

}  // namespace statsim::tools
