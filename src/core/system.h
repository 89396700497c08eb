// Facts about the running process and machine that reports and resource checks need.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace dispex {

// Peak resident set size of this process so far, in bytes (VmHWM), or 0 if unknown.
std::uint64_t PeakResidentBytes();
// Memory the machine can give without swapping (MemAvailable, bounded by a cgroup limit when
// one is set), in bytes, or 0 if unknown.
std::uint64_t AvailableMemoryBytes();

// Wall-clock stopwatch.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  void Reset() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace dispex
