// How a parallel stage of an extraction stops: with the error of the lowest face id (so the
// message does not depend on scheduling), or because cancellation was requested.
#pragma once

#include <fmt/format.h>

#include <atomic>
#include <mutex>
#include <optional>

#include "core/cancel.h"
#include "dispex/status.h"

namespace dispex {

class FirstError {
 public:
  void Record(int face, Status status) {
    std::lock_guard lock(mutex_);
    if (!face_ || face < *face_) {
      face_ = face;
      status_ = std::move(status);
    }
    failed_.store(true);
  }
  bool failed() const { return failed_.load(std::memory_order_relaxed); }
  Status status() const { return status_; }

 private:
  std::mutex mutex_;
  std::optional<int> face_;
  Status status_;
  std::atomic<bool> failed_{false};
};

inline Status Cancelled() {
  int sig = CancelSignal();
  return Status::Error(sig ? fmt::format("interrupted by signal {}", sig) : "interrupted");
}

}  // namespace dispex
