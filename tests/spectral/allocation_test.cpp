// Steady-state analysis allocates nothing: once an analyzer has seen a size, analysing more
// faces of that size does not touch the heap (counted with a replaced global operator new).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <random>
#include <vector>

#include "block_generators.h"
#include "dispex/spectral.h"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// GCC 12 flags free() in a replaced operator delete once it inlines both into one caller
// (-Wmismatched-new-delete): a false positive for a malloc-based replacement pair.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace dispex {
namespace {

TEST(AllocationTest, SteadyStateAnalysisAllocatesNothing) {
  {
    // The counter sees heap allocations (so a zero below means something).
    const long start = g_allocations.load();
    auto probe = std::make_unique<std::vector<float>>(100);
    EXPECT_EQ(g_allocations.load() - start, 2);
  }
  std::mt19937 rng(3);
  std::vector<std::vector<float>> blocks;
  for (int k = 0; k < 70; ++k) {
    blocks.push_back(spectral_test::RandomBlock(
        static_cast<spectral_test::BlockKind>(k % spectral_test::kBlockKinds), 64, 64, 0.01, rng));
  }
  SpectralOptions options;
  options.tolerance = 1e-5;
  SpectralAnalyzer analyzer;
  // Warm-up: plans and buffers for every size this block size can lead to.
  for (const auto& b : blocks) ASSERT_TRUE(analyzer.Analyze(b, 64, 64, options).ok());
  const long before = g_allocations.load();
  long step_ups = 0;
  for (int pass = 0; pass < 3; ++pass) {
    for (const auto& b : blocks) {
      auto face = analyzer.Analyze(b, 64, 64, options);
      ASSERT_TRUE(face.ok());
      step_ups += face->stats.step_ups;
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(step_ups, 0);  // the verification path was exercised
}

}  // namespace
}  // namespace dispex
