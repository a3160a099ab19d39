// Bullet reference objects for `statsim gather`'s worker threads: a task borrows one and gives
// it back, so that a run builds one per worker at most instead of one per trial.
#pragma once

#include "ref3d/model.hpp"
#include "ref3d/reference.hpp"

#include <memory>
#include <mutex>
#include <vector>

namespace statsim::tools::ref3d {

// A pool of Reference objects, one per worker at most: a task borrows one and gives it back.
// Trials build a fresh Bullet world each, so which object runs a trial does not matter.
class ReferencePool {
public:
  ReferencePool(const ShapeModel& m, const ReferenceSettings& s) : model_(m), settings_(s) {}
  template <class F>
  auto with(F&& f)
  {
    std::unique_ptr<Reference> ref;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!free_.empty()) {
        ref = std::move(free_.back());
        free_.pop_back();
      }
    }
    if (!ref) ref = std::make_unique<Reference>(model_, settings_);
    struct Return {
      ReferencePool& pool;
      std::unique_ptr<Reference>& ref;
      ~Return()
      {
        std::lock_guard<std::mutex> lock(pool.mutex_);
        pool.free_.push_back(std::move(ref));
      }
    } give_back{*this, ref};
    return f(*ref);
  }

private:
  const ShapeModel& model_;
  ReferenceSettings settings_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<Reference>> free_;
};

}  // namespace statsim::tools::ref3d
