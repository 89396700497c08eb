// The two implementations of the unnormalised 2-D DCT (FFTW r2r, and Makhoul's paired complex
// FFT) agree with each other and with the direct sum, for every shape both support.
#include "spectral/dct2d.h"

#include <fftw3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "dct_reference.h"
#include "dispex/spectral.h"
#include "spectral/aligned_buffer.h"
#include "spectral/analyzer_steps.h"

namespace dispex::spectral {
namespace {

double RelativeDifference(const float* a, const float* b, std::size_t n) {
  double diff = 0, scale = 0;
  for (std::size_t k = 0; k < n; ++k) {
    diff = std::max(diff, std::fabs(double(a[k]) - b[k]));
    scale = std::max(scale, std::fabs(double(b[k])));
  }
  return diff / scale;
}

TEST(Dct2dTest, PairedComplexMatchesR2rForEveryShape) {
  Dct2d dct;
  AlignedFloats in, r2r, paired;
  for (int lx = 1; lx <= kMaxSpectralLog2; ++lx) {
    for (int ly = 1; ly <= kMaxSpectralLog2; ++ly) {
      if (lx + ly > 14) continue;  // 512 x 512 is covered by the public DCT test
      const std::size_t n = std::size_t{1} << (lx + ly);
      const std::vector<float> x =
          spectral_test::UniformNoise(static_cast<int>(n), 1.0f, lx * 16 + ly);
      std::copy(x.begin(), x.end(), in.Reserve(n));
      for (int dir = 0; dir < 2; ++dir) {
        float* a = r2r.Reserve(n);
        float* b = paired.Reserve(n);
        if (dir == 0) {
          dct.Forward(lx, ly, in.data(), a, Dct2d::Path::kR2r);
          dct.Forward(lx, ly, in.data(), b, Dct2d::Path::kPairedComplex);
        } else {
          dct.Inverse(lx, ly, in.data(), a, Dct2d::Path::kR2r);
          dct.Inverse(lx, ly, in.data(), b, Dct2d::Path::kPairedComplex);
        }
        EXPECT_LE(RelativeDifference(b, a, n), 2e-6)
            << (dir == 0 ? "forward " : "inverse ") << (1 << lx) << " x " << (1 << ly);
      }
      // The input is preserved.
      EXPECT_TRUE(std::equal(x.begin(), x.end(), in.data()));
    }
  }
}

TEST(Dct2dTest, PairedComplexMatchesDirectSum) {
  // The unnormalised REDFT10 is 4 F / (a(u) a(v)) of the orthonormal F.
  Dct2d dct;
  AlignedFloats in, out;
  for (auto [lx, ly] : {std::pair{1, 1}, std::pair{2, 3}, std::pair{4, 1}, std::pair{5, 5}}) {
    const int nx = 1 << lx, ny = 1 << ly;
    const std::vector<float> x = spectral_test::UniformNoise(nx * ny, 1.0f, 3);
    std::copy(x.begin(), x.end(), in.Reserve(x.size()));
    dct.Forward(lx, ly, in.data(), out.Reserve(x.size()), Dct2d::Path::kPairedComplex);
    const std::vector<double> f = spectral_test::NaiveDct(spectral_test::ToDouble(x), nx, ny);
    for (int v = 0; v < ny; ++v) {
      for (int u = 0; u < nx; ++u) {
        const double want =
            4 * f[v * nx + u] / (spectral_test::Alpha(u, nx) * spectral_test::Alpha(v, ny));
        EXPECT_NEAR(out.data()[v * nx + u], want, 1e-5 * nx * ny) << nx << "x" << ny;
      }
    }
  }
}

TEST(Dct2dTest, AutoPathIsAFixedRuleOfTheSize) {
  EXPECT_EQ(Dct2d::AutoPath(6, 6), Dct2d::Path::kPairedComplex);
  EXPECT_EQ(Dct2d::AutoPath(1, 6), Dct2d::Path::kPairedComplex);
  EXPECT_EQ(Dct2d::AutoPath(0, 9), Dct2d::Path::kR2r);  // a side of 1 cannot be paired
  EXPECT_EQ(Dct2d::AutoPath(3, 3), Dct2d::Path::kR2r);
}

TEST(Dct2dTest, ForeignFftwWisdomDoesNotChangeResults) {
  // Other code in the process planning the same transforms with FFTW_MEASURE or FFTW_PATIENT
  // leaves wisdom that FFTW_ESTIMATE alone would adopt; the analyzer's plans must not. (This
  // test fails when the planner flags are FFTW_ESTIMATE alone.)
  const std::vector<float> x = spectral_test::UniformNoise(64 * 64, 0.01f, 77);
  std::vector<float> before(x.size()), after(x.size());
  {
    SpectralAnalyzer analyzer;
    ASSERT_TRUE(spectral::AnalyzerSteps::ForwardDct(analyzer, x, 64, 64, before).ok());
  }
  {
    AlignedFloats a, b;
    float* in = a.Reserve(64 * 64);
    float* out = b.Reserve(64 * 64);
    auto* za = reinterpret_cast<fftwf_complex*>(in);
    auto* zb = reinterpret_cast<fftwf_complex*>(out);
    int n = 64;
    std::fill(in, in + 64 * 64, 0.0f);
    for (unsigned flags : {FFTW_MEASURE, FFTW_PATIENT}) {
      fftwf_plan rows = fftwf_plan_many_dft(1, &n, 32, za, nullptr, 1, 64, zb, nullptr, 1, 64,
                                            FFTW_FORWARD, flags);
      fftwf_plan columns = fftwf_plan_many_dft(1, &n, 32, za, nullptr, 32, 1, zb, nullptr, 32, 1,
                                               FFTW_FORWARD, flags);
      ASSERT_NE(rows, nullptr);
      ASSERT_NE(columns, nullptr);
      fftwf_destroy_plan(rows);
      fftwf_destroy_plan(columns);
    }
  }
  {
    SpectralAnalyzer analyzer;
    ASSERT_TRUE(spectral::AnalyzerSteps::ForwardDct(analyzer, x, 64, 64, after).ok());
  }
  EXPECT_EQ(std::memcmp(before.data(), after.data(), before.size() * sizeof(float)), 0);
}

}  // namespace
}  // namespace dispex::spectral
