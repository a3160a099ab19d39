// A fixed pool of host threads behind statsim's worker callbacks (`statsim::Workers`).
#pragma once

#include "statsim/world_def.hpp"

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace statsim::tools {

/// `threads` - 1 threads started once and kept waiting between tasks; the thread that calls
/// `FinishTaskCallback` works on the task too, so `threads` is the number of threads working.
/// One task at a time, as a world hands them out (enqueue, then finish at once). Items are taken
/// `min_range` at a time in any order: the world's results do not depend on which thread ran what.
class TaskPool {
public:
  explicit TaskPool(unsigned threads) : threads_(threads < 1 ? 1 : threads)
  {
    for (unsigned t = 1; t < threads_; ++t) pool_.emplace_back([this] { serve(); });
  }
  ~TaskPool()
  {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : pool_) t.join();
  }
  TaskPool(const TaskPool&) = delete;
  TaskPool& operator=(const TaskPool&) = delete;

  /// The callbacks for `WorldDef::workers`, splitting the work into `threads` parts.
  statsim::Workers workers()
  {
    statsim::Workers w;
    w.count = threads_;
    w.enqueue = &TaskPool::enqueue;
    w.finish = &TaskPool::finish;
    w.context = this;
    return w;
  }

private:
  static void* enqueue(statsim::TaskCallback* task, std::uint32_t count, std::uint32_t min_range, void* task_context,
                       void* user_context)
  {
    TaskPool& p = *static_cast<TaskPool*>(user_context);
    if (p.threads_ == 1 || count <= min_range) {
      task(0, count, task_context);
      return nullptr;
    }
    {
      std::lock_guard<std::mutex> lock(p.mutex_);
      p.task_ = task;
      p.context_ = task_context;
      p.count_ = count;
      p.range_ = min_range < 1 ? 1 : min_range;
      p.next_ = 0;
      p.done_ = 0;
      ++p.generation_;
    }
    p.wake_.notify_all();
    return &p;
  }

  static void finish(void* user_task, void* user_context)
  {
    (void)user_context;
    TaskPool& p = *static_cast<TaskPool*>(user_task);
    p.work();
    std::unique_lock<std::mutex> lock(p.mutex_);
    p.finished_.wait(lock, [&p] { return p.done_ == p.count_; });
  }

  // Takes ranges of the current task until none is left. The items are few (a world hands out
  // one per part), so each is taken under the lock.
  void work()
  {
    for (;;) {
      std::uint32_t begin, end;
      statsim::TaskCallback* task;
      void* context;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (next_ >= count_) return;
        begin = next_;
        end = count_ - begin > range_ ? begin + range_ : count_;
        next_ = end;
        task = task_;
        context = context_;
      }
      task(begin, end, context);
      std::lock_guard<std::mutex> lock(mutex_);
      done_ += end - begin;
      if (done_ == count_) finished_.notify_all();
    }
  }

  void serve()
  {
    std::uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
      }
      work();
    }
  }

  unsigned threads_;
  std::vector<std::thread> pool_;
  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  bool stop_ = false;
  std::uint64_t generation_ = 0;
  statsim::TaskCallback* task_ = nullptr;
  void* context_ = nullptr;
  std::uint32_t count_ = 0, range_ = 1, next_ = 0, done_ = 0;
};

}  // namespace statsim::tools
