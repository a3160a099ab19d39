// A deterministic parallel-for for the host tools.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace statsim::tools {

/// The number of worker threads to use when `requested` are asked for: `requested` itself, or
/// std::thread::hardware_concurrency() when `requested` is 0 (at least 1 either way).
inline unsigned resolve_thread_count(unsigned requested)
{
  if (requested != 0) {
    return requested;
  }
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : hw;
}

/// Calls `body(i)` exactly once for every i in [0, n), on up to `threads` threads
/// (0 = hardware concurrency; 1 = inline on the calling thread, no thread is started).
///
/// Indices are handed out dynamically, so the order and the thread an index runs on vary from
/// run to run. Results stay deterministic when each `body(i)` depends only on `i` and writes
/// only its own result slot (e.g. `out[i] = f(i)`): then nothing depends on the thread count.
/// `body` must be safe to call concurrently for different indices.
///
/// If some `body(i)` throws, no new indices are started, the running ones finish, and the
/// exception thrown by the lowest index among those that ran is rethrown on the calling thread.
template <class Body>
void parallel_for(std::size_t n, Body&& body, unsigned threads = 0)
{
  const std::size_t workers = std::min<std::size_t>(resolve_thread_count(threads), n);
  if (workers <= 1) {
    for (std::size_t i = 0; i < n; ++i) {
      body(i);
    }
    return;
  }

  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex error_mutex;
  std::exception_ptr error;
  std::size_t error_index = n;

  auto work = [&]() {
    while (!stop.load(std::memory_order_relaxed)) {
      const std::size_t i = next.fetch_add(1, std::memory_order_relaxed);
      if (i >= n) {
        return;
      }
      try {
        body(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (i < error_index) {
          error_index = i;
          error = std::current_exception();
        }
        stop.store(true, std::memory_order_relaxed);
      }
    }
  };

  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  try {
    for (std::size_t t = 1; t < workers; ++t) {
      pool.emplace_back(work);
    }
  } catch (...) {
    // Could not start a thread: let the ones already running (and this one) do the work.
    (void)0;
  }
  work();
  for (std::thread& th : pool) {
    th.join();
  }
  if (error) {
    std::rethrow_exception(error);
  }
}

/// Returns the vector {fn(0), fn(1), ..., fn(n-1)}, computed with parallel_for() (same rules:
/// `fn(i)` must depend only on `i`). The result type must be default-constructible and
/// move-assignable, and not bool (std::vector<bool> packs bits, so its slots are not separate).
template <class Fn>
auto parallel_map(std::size_t n, Fn&& fn, unsigned threads = 0)
    -> std::vector<std::decay_t<std::invoke_result_t<Fn&, std::size_t>>>
{
  static_assert(!std::is_same_v<std::decay_t<std::invoke_result_t<Fn&, std::size_t>>, bool>,
                "parallel_map: std::vector<bool> slots are not independent; return char or int");
  std::vector<std::decay_t<std::invoke_result_t<Fn&, std::size_t>>> out(n);
  parallel_for(
      n, [&](std::size_t i) { out[i] = fn(i); }, threads);
  return out;
}

}  // namespace statsim::tools
