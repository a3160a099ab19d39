// Progress reports for long host-tool runs, on stderr.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace statsim::tools {

/// Seconds of wall time since `t0` (the timings the tools report beside their results).
inline double seconds_since(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Reports "label: done/total (pct) elapsed 12.3s, ETA 45s" on stderr.
///
/// When stderr is a terminal, one line is rewritten in place (carriage return) at most ten
/// times a second; otherwise (a log file, CI) a plain line is printed at most every five
/// seconds. finish() (or the destructor) prints the final line. add() may be called from any
/// number of threads at once: the count is atomic and printing is serialised.
class Progress {
public:
  /// `total` is the number of units of work; `enabled = false` makes every call a no-op.
  Progress(std::string label, std::uint64_t total, bool enabled = true);
  /// Calls finish().
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Records `n` more units done (thread-safe, cheap: one atomic add and a clock read).
  void add(std::uint64_t n = 1);
  /// Prints the final line (once; later calls do nothing).
  void finish();
  /// Units done so far.
  std::uint64_t done() const { return done_.load(std::memory_order_relaxed); }
  /// Seconds since construction.
  double elapsed_seconds() const;

  /// Formats a duration for humans: "0.4s", "12.3s", "4m05s", "2h03m".
  static std::string format_duration(double seconds);

private:
  void print(bool final_line);

  std::string label_;
  std::uint64_t total_;
  bool enabled_;
  bool terminal_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::duration interval_;
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::int64_t> next_print_{0};  // steady_clock ticks since start_
  std::mutex print_mutex_;
  std::size_t last_width_ = 0;  // guarded by print_mutex_
  bool finished_ = false;       // guarded by print_mutex_
};

}  // namespace statsim::tools
