// The first error of a parallel loop by element index (a face, a block, a record), so that the
// message a user reads does not depend on scheduling or thread count.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <utility>

#include "dispex/status.h"

namespace dispex {

class FirstError {
 public:
  // Keeps `status` when `index` is lower than every index recorded so far.
  void Record(std::int64_t index, Status status) {
    std::lock_guard lock(mutex_);
    if (!index_ || index < *index_) {
      index_ = index;
      status_ = std::move(status);
    }
    failed_.store(true, std::memory_order_relaxed);
  }
  // Cheap enough to poll in a loop that stops early once something failed.
  bool failed() const { return failed_.load(std::memory_order_relaxed); }
  Status status() const {
    std::lock_guard lock(mutex_);
    return status_;
  }

 private:
  mutable std::mutex mutex_;
  std::optional<std::int64_t> index_;
  Status status_;
  std::atomic<bool> failed_{false};
};

}  // namespace dispex
