// Running the mesh module's parallel loops with the caller's thread count.
#pragma once

#include <tbb/task_arena.h>

#include <utility>

namespace dispex::mesh {

// Runs `work` in a TBB arena of `threads` workers, or in the current arena when threads <= 0
// (TBB's default: all available cores).
template <class Work>
void RunWithThreads(int threads, Work&& work) {
  if (threads > 0) {
    tbb::task_arena arena(threads);
    arena.execute(std::forward<Work>(work));
  } else {
    std::forward<Work>(work)();
  }
}

}  // namespace dispex::mesh
