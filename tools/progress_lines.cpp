#include "progress_lines.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <utility>

namespace dispex::cli {

std::string ProgressLines::Format(const std::string& phase, std::uint64_t done,
                                  std::uint64_t total) {
  return fmt::format("progress {} {}/{}\n", phase, done, total);
}

ProgressLines::ProgressLines(std::string phase, bool enabled)
    : phase_(std::move(phase)), enabled_(enabled) {
  if (!enabled_) return;
  thread_ = std::thread([this] {
    std::unique_lock lock(mutex_);
    while (!wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return stop_; })) {
      PrintIfMoved();
    }
  });
}

ProgressLines::~ProgressLines() {
  Finish();
}

void ProgressLines::Finish() {
  if (!enabled_ || finished_) return;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  PrintIfMoved();
  finished_ = true;
}

void ProgressLines::PrintIfMoved() {
  // The total first: the library sets done to 0 before it sets a new phase's total, so done
  // read after it is never a finished phase's count over a new, smaller total (and is clamped
  // should it be).
  const std::uint64_t total = counter_.total.load();
  const std::uint64_t done = std::min(counter_.done.load(), total);
  if (total == 0) return;  // no phase started yet
  if (done == printed_done_ && total == printed_total_) return;
  const std::string line = Format(phase_, done, total);
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
  printed_done_ = done;
  printed_total_ = total;
}

}  // namespace dispex::cli
