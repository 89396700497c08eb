// The FFTW-based orthonormal DCT against direct sums written from the definition.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "dct_reference.h"
#include "dispex/spectral.h"
#include "spectral/analyzer_steps.h"

namespace dispex {
namespace {

using spectral_test::NaiveDct;
using spectral_test::NaiveInverseDct;
using spectral_test::SeparableDct;
using spectral_test::ToDouble;
using spectral_test::UniformNoise;

double MaxAbs(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m = std::max(m, std::fabs(v));
  return m;
}

// max |got - want| / max |want|
double RelativeError(const std::vector<float>& got, const std::vector<double>& want) {
  double worst = 0;
  for (std::size_t k = 0; k < want.size(); ++k)
    worst = std::max(worst, std::fabs(got[k] - want[k]));
  return worst / MaxAbs(want);
}

std::vector<std::pair<int, int>> SmallShapes() {
  std::vector<std::pair<int, int>> shapes;
  for (int nx = 1; nx <= 32; nx *= 2) {
    for (int ny = 1; ny <= 32; ny *= 2) shapes.emplace_back(nx, ny);
  }
  return shapes;
}

TEST(DctTest, ForwardMatchesDirectSumUpTo32) {
  SpectralAnalyzer analyzer;
  for (auto [nx, ny] : SmallShapes()) {
    const std::vector<float> x = UniformNoise(nx * ny, 1.0f, 17u + nx * 64 + ny);
    std::vector<float> f(x.size());
    ASSERT_TRUE(spectral::AnalyzerSteps::ForwardDct(analyzer, x, nx, ny, f).ok());
    EXPECT_LE(RelativeError(f, NaiveDct(ToDouble(x), nx, ny)), 1e-5) << nx << " x " << ny;
  }
}

TEST(DctTest, ForwardMatchesSeparableSumUpTo512) {
  SpectralAnalyzer analyzer;
  const std::vector<std::pair<int, int>> shapes = {{64, 64},  {128, 128}, {256, 256}, {512, 512},
                                                   {512, 4},  {4, 512},   {1, 512},   {512, 1},
                                                   {64, 256}, {256, 32},  {128, 2}};
  for (auto [nx, ny] : shapes) {
    const std::vector<float> x = UniformNoise(nx * ny, 1.0f, 5u + nx * 1024 + ny);
    std::vector<float> f(x.size());
    ASSERT_TRUE(spectral::AnalyzerSteps::ForwardDct(analyzer, x, nx, ny, f).ok());
    EXPECT_LE(RelativeError(f, SeparableDct(ToDouble(x), nx, ny)), 1e-5) << nx << " x " << ny;
  }
}

TEST(DctTest, SeparableReferenceAgreesWithDirectSum) {
  // The O(N^3) reference used for the big sizes is itself checked against the O(N^4) one.
  for (auto [nx, ny] : SmallShapes()) {
    const std::vector<double> x = ToDouble(UniformNoise(nx * ny, 1.0f, 99u + nx + ny));
    const std::vector<double> a = NaiveDct(x, nx, ny);
    const std::vector<double> b = SeparableDct(x, nx, ny);
    for (std::size_t k = 0; k < a.size(); ++k) ASSERT_NEAR(a[k], b[k], 1e-12);
  }
}

TEST(DctTest, InverseMatchesDirectSumAndUndoesForward) {
  SpectralAnalyzer analyzer;
  for (auto [nx, ny] : SmallShapes()) {
    const std::vector<float> f = UniformNoise(nx * ny, 2.0f, 3u + nx * 64 + ny);
    std::vector<float> x(f.size());
    ASSERT_TRUE(spectral::AnalyzerSteps::InverseDct(analyzer, f, nx, ny, x).ok());
    EXPECT_LE(RelativeError(x, NaiveInverseDct(ToDouble(f), nx, ny)), 1e-5) << nx << " x " << ny;
  }
  for (int nx = 1; nx <= 512; nx *= 2) {
    for (int ny : {1, 4, 64, 512}) {
      const std::vector<float> x = UniformNoise(nx * ny, 1.0f, 11u + nx + ny);
      std::vector<float> f(x.size()), back(x.size());
      ASSERT_TRUE(spectral::AnalyzerSteps::ForwardDct(analyzer, x, nx, ny, f).ok());
      ASSERT_TRUE(spectral::AnalyzerSteps::InverseDct(analyzer, f, nx, ny, back).ok());
      EXPECT_LE(RelativeError(back, ToDouble(x)), 1e-5) << nx << " x " << ny;
    }
  }
}

TEST(DctTest, OrthonormalPreservesEnergy) {
  SpectralAnalyzer analyzer;
  for (auto [nx, ny] : std::vector<std::pair<int, int>>{{4, 4}, {64, 64}, {512, 8}, {1, 256}}) {
    const std::vector<float> x = UniformNoise(nx * ny, 1.0f, 23u);
    std::vector<float> f(x.size());
    ASSERT_TRUE(spectral::AnalyzerSteps::ForwardDct(analyzer, x, nx, ny, f).ok());
    double ex = 0, ef = 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      ex += double(x[k]) * x[k];
      ef += double(f[k]) * f[k];
    }
    EXPECT_NEAR(ef / ex, 1.0, 1e-5) << nx << " x " << ny;
  }
}

TEST(DctTest, ConstantBlockHasOnlyDcTerm) {
  SpectralAnalyzer analyzer;
  const std::vector<float> x(16 * 8, 0.25f);
  std::vector<float> f(x.size());
  ASSERT_TRUE(spectral::AnalyzerSteps::ForwardDct(analyzer, x, 16, 8, f).ok());
  // F(0,0) = sqrt(1/16) sqrt(1/8) * 128 * 0.25 = 0.25 * sqrt(128)
  EXPECT_NEAR(f[0], 0.25 * std::sqrt(128.0), 1e-6);
  for (std::size_t k = 1; k < f.size(); ++k) EXPECT_NEAR(f[k], 0.0f, 1e-6) << k;
}

TEST(DctTest, RejectsBadSizesAndValues) {
  SpectralAnalyzer analyzer;
  std::vector<float> x(48 * 64), f(48 * 64);
  Status s = spectral::AnalyzerSteps::ForwardDct(analyzer, x, 48, 64, f);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "block size 48 x 64: 48 is not a power of two in 1..512");
  s = spectral::AnalyzerSteps::ForwardDct(analyzer, std::vector<float>(1024 * 1024), 1024, 1024, f);
  EXPECT_EQ(s.message(), "block size 1024 x 1024: 1024 is not a power of two in 1..512");
  s = spectral::AnalyzerSteps::ForwardDct(analyzer, std::vector<float>(0), 0, 4, f);
  EXPECT_EQ(s.message(), "block size 0 x 4: 0 is not a power of two in 1..512");
  std::vector<float> f16(16);
  s = spectral::AnalyzerSteps::ForwardDct(analyzer, std::vector<float>(10), 4, 4, f16);
  EXPECT_EQ(s.message(), "samples holds 10 values, a 4 x 4 block needs 16");
  std::vector<float> out(15);
  s = spectral::AnalyzerSteps::InverseDct(analyzer, std::vector<float>(16), 4, 4, out);
  EXPECT_EQ(s.message(), "samples holds 15 values, a 4 x 4 block needs 16");
  std::vector<float> bad(16, 1.0f);
  bad[2 * 4 + 3] = std::nanf("");
  s = spectral::AnalyzerSteps::ForwardDct(analyzer, bad, 4, 4, f16);
  EXPECT_EQ(s.message(), "sample (3, 2) of the 4 x 4 block is not finite (nan)");
  bad[2 * 4 + 3] = -INFINITY;
  s = spectral::AnalyzerSteps::InverseDct(analyzer, bad, 4, 4, f16);
  EXPECT_EQ(s.message(), "coefficient (3, 2) of the 4 x 4 block is not finite (-inf)");
}

}  // namespace
}  // namespace dispex
