// The guarantee on thousands of random smooth, sharp and noisy blocks (seeded, deterministic):
// the bilinear read-back of the stored texels is within the tolerance at every sample.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "block_generators.h"
#include "dct_reference.h"
#include "dispex/spectral.h"
#include "spectral/analyzer_steps.h"

namespace dispex {
namespace {

using spectral_test::BlockKind;

struct Draw {
  BlockKind kind;
  int nx, ny;
  double amplitude, tolerance;
};

Draw RandomDraw(std::mt19937& rng) {
  Draw d;
  d.kind = static_cast<BlockKind>(
      std::uniform_int_distribution<int>(0, spectral_test::kBlockKinds - 1)(rng));
  // Mostly up to 32 (fast under sanitizers), many 64 and 128, some with a side of 1 or 2.
  auto side = [&] {
    const int r = std::uniform_int_distribution<int>(0, 99)(rng);
    if (r < 5) return 1;
    if (r < 10) return 2;
    if (r < 70) return 1 << std::uniform_int_distribution<int>(2, 5)(rng);
    if (r < 90) return 64;
    return 128;
  };
  d.nx = side();
  d.ny = side();
  d.amplitude = std::pow(10.0, std::uniform_real_distribution<double>(-3, 1)(rng));
  d.tolerance =
      d.amplitude * std::pow(10.0, std::uniform_real_distribution<double>(-3.5, -0.3)(rng));
  return d;
}

TEST(RandomBlocksTest, MeasuredErrorNeverExceedsTolerance) {
  std::mt19937 rng(20240611);
  SpectralAnalyzer analyzer;
  std::array<int, 3> outcome{};  // constant, reduced, full
  int stepped = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Draw d = RandomDraw(rng);
    const std::vector<float> block =
        spectral_test::RandomBlock(d.kind, d.nx, d.ny, d.amplitude, rng);
    SpectralOptions options;
    options.tolerance = d.tolerance;
    auto face = analyzer.Analyze(block, d.nx, d.ny, options);
    ASSERT_TRUE(face.ok()) << face.status().message();
    SCOPED_TRACE(testing::Message() << "trial " << trial << " " << BlockKindName(d.kind) << " "
                                    << d.nx << "x" << d.ny << " tolerance " << d.tolerance);
    const int rx = 1 << face->ulog2, ry = 1 << face->vlog2;
    ASSERT_LE(rx, d.nx);
    ASSERT_LE(ry, d.ny);
    ASSERT_EQ(face->texels.size(), static_cast<std::size_t>(rx) * ry);
    ASSERT_EQ(face->stats.texels_after, rx * ry);
    ASSERT_EQ(face->stats.texels_before, d.nx * d.ny);
    ASSERT_EQ(face->constant, rx * ry == 1);
    ASSERT_LE(face->stats.measured_error, d.tolerance);
    const std::vector<float> texels(face->texels.begin(), face->texels.end());
    ASSERT_LE(spectral_test::ReferenceReadBackError(texels, rx, ry, block, d.nx, d.ny),
              d.tolerance + 1e-12 * d.amplitude);
    if (face->constant) {
      ++outcome[0];
      continue;
    }
    ASSERT_EQ(face->ulog2 + face->vlog2,
              face->stats.bound_ulog2 + face->stats.bound_vlog2 + face->stats.step_ups);
    ASSERT_LE(face->stats.bound_ulog2, face->ulog2);
    ASSERT_LE(face->stats.bound_vlog2, face->vlog2);
    stepped += face->stats.step_ups > 0;
    if (rx == d.nx && ry == d.ny) {
      ++outcome[2];
      ASSERT_EQ(texels, block);
      ASSERT_EQ(face->stats.measured_error, 0.0);
    } else {
      ++outcome[1];
    }
  }
  // The draw covers every outcome (else the test would prove little).
  EXPECT_GT(outcome[0], 50);
  EXPECT_GT(outcome[1], 500);
  EXPECT_GT(outcome[2], 500);
  EXPECT_GT(stepped, 200);
  std::printf("constant %d, reduced %d, full %d, stepped up %d\n", outcome[0], outcome[1],
              outcome[2], stepped);
}

TEST(RandomBlocksTest, BoundHoldsForTheBandLimitedSeries) {
  // Without verification the bound alone decides; the series truncated to the chosen band,
  // evaluated back at the samples (zero-padded resampling to the sample grid), stays within
  // the reported bound, which is within the tolerance.
  std::mt19937 rng(99);
  SpectralAnalyzer analyzer;
  for (int trial = 0; trial < 500; ++trial) {
    const Draw d = RandomDraw(rng);
    const std::vector<float> block =
        spectral_test::RandomBlock(d.kind, d.nx, d.ny, d.amplitude, rng);
    SpectralOptions options;
    options.tolerance = d.tolerance;
    options.verify = false;
    auto face = analyzer.Analyze(block, d.nx, d.ny, options);
    ASSERT_TRUE(face.ok());
    ASSERT_EQ(face->stats.step_ups, 0);
    ASSERT_LE(face->stats.bound, d.tolerance);
    if (face->constant) continue;
    const std::vector<float> texels(face->texels.begin(), face->texels.end());
    std::vector<float> series(block.size());
    ASSERT_TRUE(
        spectral::AnalyzerSteps::Resample(analyzer, texels, 1 << face->ulog2, 1 << face->vlog2,
                                          std::countr_zero(static_cast<unsigned>(d.nx)),
                                          std::countr_zero(static_cast<unsigned>(d.ny)), series)
            .ok());
    double worst = 0;
    for (std::size_t k = 0; k < block.size(); ++k) {
      worst = std::max(worst, std::fabs(double(series[k]) - block[k]));
    }
    // Float rounding of the transforms: a few ulps of the block's magnitude.
    ASSERT_LE(worst, face->stats.bound + 1e-5 * d.amplitude)
        << "trial " << trial << " " << BlockKindName(d.kind) << " " << d.nx << "x" << d.ny;
  }
}

}  // namespace
}  // namespace dispex
