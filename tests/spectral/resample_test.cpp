// DCT-domain resampling: exact at the new texel centres for the kept band.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "block_generators.h"
#include "dct_reference.h"
#include "dispex/spectral.h"
#include "spectral/analyzer_steps.h"

namespace dispex {
namespace {

using spectral_test::CosineBlock;
using spectral_test::CosineTerm;
using spectral_test::CosineValue;

TEST(ResampleTest, BandLimitedBlockIsExactAtNewTexelCentres) {
  const std::vector<CosineTerm> terms = {{0, 0, 0.5}, {1, 0, 0.25}, {7, 3, -0.125}, {2, 6, 0.1}};
  const std::vector<float> block = CosineBlock(64, 32, terms);
  SpectralAnalyzer analyzer;
  // Every resolution holding u <= 7, v <= 6, including enlargements beyond the samples.
  for (int lu = 3; lu <= 8; ++lu) {
    for (int lv = 3; lv <= 7; ++lv) {
      const int rx = 1 << lu, ry = 1 << lv;
      std::vector<float> texels(rx * ry);
      ASSERT_TRUE(spectral::AnalyzerSteps::Resample(analyzer, block, 64, 32, lu, lv, texels).ok());
      for (int j = 0; j < ry; ++j) {
        for (int i = 0; i < rx; ++i) {
          ASSERT_NEAR(texels[j * rx + i], CosineValue(terms, (i + 0.5) / rx, (j + 0.5) / ry), 1e-6)
              << rx << " x " << ry << " texel (" << i << ", " << j << ")";
        }
      }
    }
  }
}

TEST(ResampleTest, TruncationMatchesTheTruncatedSeries) {
  // A block with a full spectrum resampled below its band equals the truncated series.
  std::mt19937 rng(12);
  const std::vector<float> block =
      spectral_test::RandomBlock(spectral_test::BlockKind::kGaussians, 32, 32, 1.0, rng);
  const std::vector<double> f = spectral_test::NaiveDct(spectral_test::ToDouble(block), 32, 32);
  SpectralAnalyzer analyzer;
  for (auto [lu, lv] : {std::pair{2, 3}, std::pair{4, 4}, std::pair{0, 5}, std::pair{1, 1}}) {
    const int rx = 1 << lu, ry = 1 << lv;
    std::vector<float> texels(rx * ry);
    ASSERT_TRUE(spectral::AnalyzerSteps::Resample(analyzer, block, 32, 32, lu, lv, texels).ok());
    for (int j = 0; j < ry; ++j) {
      for (int i = 0; i < rx; ++i) {
        ASSERT_NEAR(
            texels[j * rx + i],
            spectral_test::EvaluateSeries(f, 32, 32, rx, ry, (i + 0.5) / rx, (j + 0.5) / ry), 1e-5);
      }
    }
  }
}

TEST(ResampleTest, FullResolutionIsTheSamplesAndOneTexelIsTheMean) {
  const std::vector<float> block = spectral_test::UniformNoise(16 * 64, 3.0f, 4);
  SpectralAnalyzer analyzer;
  std::vector<float> same(block.size());
  ASSERT_TRUE(spectral::AnalyzerSteps::Resample(analyzer, block, 16, 64, 4, 6, same).ok());
  EXPECT_EQ(same, block);
  std::vector<float> one(1);
  ASSERT_TRUE(spectral::AnalyzerSteps::Resample(analyzer, block, 16, 64, 0, 0, one).ok());
  double mean = 0;
  for (float v : block) mean += v;
  EXPECT_FLOAT_EQ(one[0], static_cast<float>(mean / block.size()));
}

TEST(ResampleTest, RejectsBadResolutions) {
  SpectralAnalyzer analyzer;
  std::vector<float> block(64), texels(4);
  EXPECT_EQ(spectral::AnalyzerSteps::Resample(analyzer, block, 8, 8, 10, 0, texels).message(),
            "resolution log2 10 x 0: 10 is outside 0..9");
  EXPECT_EQ(spectral::AnalyzerSteps::Resample(analyzer, block, 8, 8, 1, 2, texels).message(),
            "texels holds 4 values, a 2 x 4 block needs 8");
}

}  // namespace
}  // namespace dispex
