// Running a module's parallel loops with the caller's thread count.
#pragma once

#include <tbb/task_arena.h>

#include <utility>

namespace dispex {

// Runs `work` in a TBB arena of `threads` workers, or in the current arena when threads <= 0
// (TBB's default: all available cores) or when the current arena already has that many. A
// nested arena of the same size is not free: when `work` runs in a task while another thread
// of the current arena waits on it (extract reads the sculpt so), that thread cannot enter the
// nested arena, and under a tbb::global_control of `threads` no other worker can either -- the
// loops ran on one thread, and `extract --threads 2` read the sculpt in 1.7x the time.
template <class Work>
decltype(auto) RunWithThreads(int threads, Work&& work) {
  if (threads > 0 && threads != tbb::this_task_arena::max_concurrency()) {
    tbb::task_arena arena(threads);
    return arena.execute(std::forward<Work>(work));
  }
  return std::forward<Work>(work)();
}

}  // namespace dispex
