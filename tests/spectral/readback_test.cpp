// The bilinear read-back against a point-wise Ptex lookup written independently.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "dct_reference.h"
#include "dispex/spectral.h"
#include "spectral/bilinear_readback.h"

namespace dispex {
namespace {

TEST(ReadBackTest, MatchesPointwisePtexLookup) {
  for (int lu = 0; lu <= 7; ++lu) {
    for (int lv : {0, 1, 3, 6}) {
      const int rx = 1 << lu, ry = 1 << lv;
      const std::vector<float> texels =
          spectral_test::UniformNoise(rx * ry, 1.0f, 3u + lu * 8 + lv);
      for (auto [nx, ny] : {std::pair{64, 64}, std::pair{1, 8}, std::pair{128, 16}}) {
        std::vector<float> out(nx * ny);
        ASSERT_TRUE(spectral::BilinearReadBack(texels, lu, lv, nx, ny, out).ok());
        for (int j = 0; j < ny; ++j) {
          for (int i = 0; i < nx; ++i) {
            const double want =
                spectral_test::PtexBilinear(texels.data(), rx, ry, (i + 0.5) / nx, (j + 0.5) / ny);
            ASSERT_NEAR(out[j * nx + i], want, 1e-6)
                << rx << "x" << ry << " at " << nx << "x" << ny << " (" << i << "," << j << ")";
          }
        }
      }
    }
  }
}

TEST(ReadBackTest, LinearFieldIsExactInsideAndClampedAtTheBorder) {
  // Texels of f(s) = s at their centres read back f exactly between the outermost centres,
  // and the edge texel's value beyond them.
  const int rx = 8, nx = 64;
  std::vector<float> texels(rx);
  for (int k = 0; k < rx; ++k) texels[k] = (k + 0.5f) / rx;
  std::vector<float> out(nx);
  ASSERT_TRUE(spectral::BilinearReadBack(texels, 3, 0, nx, 1, out).ok());
  for (int i = 0; i < nx; ++i) {
    const double s = (i + 0.5) / nx;
    const double want = std::clamp(s, 0.5 / rx, 1 - 0.5 / rx);
    EXPECT_NEAR(out[i], want, 1e-7) << i;
  }
}

TEST(ReadBackTest, FullResolutionReadsTheTexelsThemselves) {
  const std::vector<float> texels = spectral_test::UniformNoise(32 * 16, 5.0f, 9);
  std::vector<float> out(texels.size());
  ASSERT_TRUE(spectral::BilinearReadBack(texels, 5, 4, 32, 16, out).ok());
  EXPECT_EQ(out, texels);
  auto err = spectral::MaxBilinearError(texels, 5, 4, texels, 32, 16);
  ASSERT_TRUE(err.ok());
  EXPECT_EQ(*err, 0.0);
}

TEST(ReadBackTest, MaxErrorMatchesReference) {
  for (int trial = 0; trial < 20; ++trial) {
    const int lu = trial % 6, lv = (trial * 7) % 6;
    const int nx = 1 << (trial % 7), ny = 64;
    const std::vector<float> texels = spectral_test::UniformNoise(1 << (lu + lv), 1.0f, trial);
    const std::vector<float> samples = spectral_test::UniformNoise(nx * ny, 1.0f, 100 + trial);
    auto err = spectral::MaxBilinearError(texels, lu, lv, samples, nx, ny);
    ASSERT_TRUE(err.ok());
    EXPECT_NEAR(*err,
                spectral_test::ReferenceReadBackError(texels, 1 << lu, 1 << lv, samples, nx, ny),
                1e-12);
  }
}

TEST(ReadBackTest, RejectsBadSizes) {
  std::vector<float> texels(16), out(64);
  EXPECT_EQ(spectral::BilinearReadBack(texels, 2, 2, 8, 4, out).message(),
            "read-back output holds 64 values, a 8 x 4 block needs 32");
  EXPECT_EQ(spectral::BilinearReadBack(texels, 3, 0, 8, 8, out).message(),
            "texels holds 16 values, a 8 x 1 block needs 8");
  EXPECT_EQ(spectral::BilinearReadBack(texels, -1, 2, 8, 8, out).message(),
            "resolution log2 -1 x 2: -1 is outside 0..9");
  EXPECT_EQ(spectral::MaxBilinearError(texels, 2, 2, out, 8, 3).status().message(),
            "block size 8 x 3: 3 is not a power of two in 1..512");
}

}  // namespace
}  // namespace dispex
