// Facts about the running process and machine that reports and resource checks need.
#pragma once

#include <time.h>

#include <chrono>
#include <cstdint>
#include <string>

namespace dispex {

// Peak resident set size of this process so far, in bytes (VmHWM), or 0 if unknown.
std::uint64_t PeakResidentBytes();
// Memory the machine can give without swapping (MemAvailable), bounded by this process's
// cgroup limit when one is set and by what an address-space limit (RLIMIT_AS, `ulimit -v`)
// leaves beyond what the process has mapped already (VmSize) and will reserve unused (Embree's
// device, the stacks and heaps of `threads` threads, 0: one per core); in bytes, or 0 if
// unknown.
std::uint64_t AvailableMemoryBytes(int threads = 0);

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

// CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID): unlike wall intervals, it does
// not count the time a thread waits or is descheduled, so per-thread sums are CPU seconds
// whatever the thread count. Must be read on the thread that started it.
class ThreadCpuStopwatch {
 public:
  ThreadCpuStopwatch() : start_(Now()) {}
  double seconds() const { return Now() - start_; }
  void Reset() { start_ = Now(); }

 private:
  static double Now() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  double start_;
};

}  // namespace dispex
