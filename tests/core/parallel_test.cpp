#include "core/parallel.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace dispex {
namespace {

// True when the two tasks of a parallel_invoke in `threads` ran at the same time: each waits
// (up to `wait`) for the other to start, which only another thread can do.
bool TwoTasksRanTogether(int threads, std::chrono::milliseconds wait) {
  std::atomic<int> started{0};
  std::atomic<int> saw_both{0};
  const auto task = [&] {
    started.fetch_add(1);
    const auto deadline = std::chrono::steady_clock::now() + wait;
    while (started.load() < 2 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::yield();
    }
    if (started.load() == 2) saw_both.fetch_add(1);
  };
  RunWithThreads(threads, [&] { tbb::parallel_invoke(task, task); });
  return saw_both.load() == 2;
}

constexpr std::chrono::milliseconds kLong{10000}, kShort{200};

// `extract` limits TBB to its thread count (a global_control) and runs in an arena of that
// size; it reads the sculpt in a task while the calling thread builds the base, and the
// reader asks for the same count. A nested arena there ran the reader's loops on the task's
// thread alone: the calling thread, waiting on the task in the outer arena, cannot enter it.
TEST(RunWithThreads, SameCountInATaskOfALimitedArenaKeepsBothThreads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
  tbb::task_arena arena(2);
  for (const int threads : {2, 0}) {
    bool taken = false, together = false;
    arena.execute([&] {
      std::atomic<bool> started{false};
      tbb::task_group group;
      group.run([&] {
        started.store(true);
        together = TwoTasksRanTogether(threads, kLong);
      });
      // Wait until the worker has the task: the calling thread only runs it inside wait().
      const auto deadline = std::chrono::steady_clock::now() + kLong;
      while (!started.load() && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::yield();
      }
      taken = started.load();
      group.wait();
    });
    ASSERT_TRUE(taken) << "the arena's worker never started";
    EXPECT_TRUE(together) << "threads " << threads;
  }
}

TEST(RunWithThreads, ASmallerCountLimitsTheLoop) {
  EXPECT_FALSE(TwoTasksRanTogether(1, kShort));
  tbb::task_arena arena(2);
  arena.execute([&] { EXPECT_FALSE(TwoTasksRanTogether(1, kShort)); });
}

TEST(RunWithThreads, ReturnsTheWorksResult) {
  EXPECT_EQ(RunWithThreads(1, [] { return 7; }), 7);
  EXPECT_EQ(RunWithThreads(0, [] { return 8; }), 8);
  tbb::task_arena arena(2);
  EXPECT_EQ(arena.execute([] { return RunWithThreads(2, [] { return 9; }); }), 9);
}

}  // namespace
}  // namespace dispex
