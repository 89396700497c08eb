// Same block -> bit-identical output, whichever analyzer, thread or thread count computes it.
#include <gtest/gtest.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "block_generators.h"
#include "dispex/spectral.h"

namespace dispex {
namespace {

struct Result {
  int ulog2 = -1, vlog2 = -1;
  bool constant = false;
  std::vector<float> texels;
  SpectralFaceStats stats;
};

bool BitEqual(const Result& a, const Result& b) {
  auto same = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  return a.ulog2 == b.ulog2 && a.vlog2 == b.vlog2 && a.constant == b.constant &&
         a.texels.size() == b.texels.size() &&
         std::memcmp(a.texels.data(), b.texels.data(), a.texels.size() * sizeof(float)) == 0 &&
         same(a.stats.bound, b.stats.bound) &&
         same(a.stats.measured_error, b.stats.measured_error) &&
         a.stats.step_ups == b.stats.step_ups && a.stats.bound_ulog2 == b.stats.bound_ulog2 &&
         a.stats.bound_vlog2 == b.stats.bound_vlog2;
}

struct Block {
  int nx, ny;
  std::vector<float> samples;
  SpectralOptions options;
};

std::vector<Block> MakeBlocks() {
  std::mt19937 rng(4242);
  std::vector<Block> blocks;
  for (int k = 0; k < 300; ++k) {
    Block b;
    b.nx = 1 << std::uniform_int_distribution<int>(0, 6)(rng);
    b.ny = 1 << std::uniform_int_distribution<int>(0, 6)(rng);
    const auto kind = static_cast<spectral_test::BlockKind>(k % spectral_test::kBlockKinds);
    b.samples = spectral_test::RandomBlock(kind, b.nx, b.ny, 0.05, rng);
    b.options.tolerance = 0.05 * std::pow(10.0, -1 - (k % 5));
    b.options.rule = k % 11 == 0 ? ResolutionRule::kNonzero : ResolutionRule::kErrorBound;
    b.options.nonzero_threshold = 1e-3;
    blocks.push_back(std::move(b));
  }
  return blocks;
}

Result AnalyzeBlock(SpectralAnalyzer& analyzer, const Block& b) {
  auto face = analyzer.Analyze(b.samples, b.nx, b.ny, b.options);
  EXPECT_TRUE(face.ok());
  if (!face.ok()) return {};
  return {face->ulog2,
          face->vlog2,
          face->constant,
          {face->texels.begin(), face->texels.end()},
          face->stats};
}

TEST(DeterminismTest, SameOutputAcrossAnalyzersOrdersAndThreads) {
  const std::vector<Block> blocks = MakeBlocks();
  std::vector<Result> reference(blocks.size());
  {
    SpectralAnalyzer analyzer;
    for (std::size_t k = 0; k < blocks.size(); ++k)
      reference[k] = AnalyzeBlock(analyzer, blocks[k]);
  }
  {
    // A fresh analyzer, blocks in reverse order (plans made in another order).
    SpectralAnalyzer analyzer;
    for (std::size_t k = blocks.size(); k-- > 0;) {
      ASSERT_TRUE(BitEqual(AnalyzeBlock(analyzer, blocks[k]), reference[k])) << "block " << k;
    }
  }
  for (int threads : {1, 2, 4}) {
    tbb::enumerable_thread_specific<SpectralAnalyzer> analyzers;
    std::vector<Result> results(blocks.size());
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t k) {
        results[k] = AnalyzeBlock(analyzers.local(), blocks[k]);
      });
    });
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      ASSERT_TRUE(BitEqual(results[k], reference[k])) << threads << " threads, block " << k;
    }
  }
}

TEST(DeterminismTest, TotalsDoNotDependOnOrder) {
  const std::vector<Block> blocks = MakeBlocks();
  SpectralAnalyzer analyzer;
  std::vector<Result> results;
  for (const Block& b : blocks) results.push_back(AnalyzeBlock(analyzer, b));
  SpectralTotals forward, halves_a, halves_b;
  for (const Result& r : results) forward.Add(r.stats, r.ulog2, r.vlog2);
  for (std::size_t k = results.size(); k-- > 0;) {
    (k % 2 ? halves_a : halves_b).Add(results[k].stats, results[k].ulog2, results[k].vlog2);
  }
  halves_b.Merge(halves_a);
  EXPECT_EQ(forward.faces, 300);
  EXPECT_EQ(forward.faces, halves_b.faces);
  EXPECT_EQ(forward.constant_faces, halves_b.constant_faces);
  EXPECT_EQ(forward.stepped_up_faces, halves_b.stepped_up_faces);
  EXPECT_EQ(forward.step_ups, halves_b.step_ups);
  EXPECT_EQ(forward.texels_before, halves_b.texels_before);
  EXPECT_EQ(forward.texels_after, halves_b.texels_after);
  EXPECT_EQ(forward.max_bound, halves_b.max_bound);
  EXPECT_EQ(forward.max_measured_error, halves_b.max_measured_error);
  EXPECT_EQ(forward.ulog2_faces, halves_b.ulog2_faces);
  EXPECT_EQ(forward.vlog2_faces, halves_b.vlog2_faces);
  std::int64_t before = 0, after = 0;
  for (const Result& r : results) {
    before += r.stats.texels_before;
    after += static_cast<std::int64_t>(r.texels.size());
  }
  EXPECT_EQ(forward.texels_before, before);
  EXPECT_EQ(forward.texels_after, after);
}

}  // namespace
}  // namespace dispex
