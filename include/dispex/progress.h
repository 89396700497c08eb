// How far long work is, for a program that shows progress its own way (the Python module's
// progress callback): the library counts into it from its worker threads, the program reads
// it from any thread. ExtractOptions::progress_counter.
#pragma once

#include <atomic>
#include <cstdint>

namespace dispex {

struct ProgressCounter {
  std::atomic<std::uint64_t> done{0};   // units finished (Ptex faces)
  std::atomic<std::uint64_t> total{0};  // units of the phase running; 0 before it starts
};

}  // namespace dispex
