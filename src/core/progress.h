// A progress bar for long work: "extract  [#####     ]  1234/5678 faces  812/s  ETA 5s".
//
// Worker threads call Advance() (one relaxed atomic add); a separate thread redraws the line on
// stderr ten times a second. Nothing is drawn unless `enabled` (the CLI enables it only when
// stderr is a terminal, CI is unset and --quiet is off), so piped and CI output stays clean.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "dispex/progress.h"

namespace dispex {

class Progress {
 public:
  // `counter`, when given, is set to 0 of `total` and counts along (drawn or not).
  Progress(std::string label, std::uint64_t total, std::string unit, bool enabled,
           ProgressCounter* counter = nullptr);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void Advance(std::uint64_t n = 1) {
    done_.fetch_add(n, std::memory_order_relaxed);
    if (counter_ != nullptr) counter_->done.fetch_add(n, std::memory_order_relaxed);
  }
  std::uint64_t done() const { return done_.load(std::memory_order_relaxed); }
  // Draws the final state and stops the redraw thread (also done by the destructor).
  void Finish();

  // The line as drawn for `done` of `total` after `seconds` (exposed for tests).
  static std::string Format(const std::string& label, std::uint64_t done, std::uint64_t total,
                            const std::string& unit, double seconds, int width = 30);

 private:
  void Draw(bool final_line);

  std::string label_;
  std::uint64_t total_;
  std::string unit_;
  bool enabled_;
  ProgressCounter* counter_;
  std::atomic<std::uint64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool finished_ = false;
  std::thread thread_;
};

}  // namespace dispex
