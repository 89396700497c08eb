// Options validation, rule names and the internal truncation-bound table.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "dct_reference.h"
#include "dispex/spectral.h"
#include "spectral/truncation_bounds.h"

namespace dispex {
namespace {

TEST(SpectralOptionsTest, DefaultsAreValid) {
  EXPECT_TRUE(ValidateSpectralOptions({}).ok());
}

TEST(SpectralOptionsTest, ErrorsNameTheFieldAndValue) {
  SpectralOptions o;
  o.tolerance = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ValidateSpectralOptions(o).message(),
            "tolerance = nan: must be finite and >= 0 (object units)");
  o = {};
  o.nonzero_threshold = -0.5;
  EXPECT_EQ(ValidateSpectralOptions(o).message(),
            "nonzero_threshold = -0.5: must be finite and >= 0");
  o = {};
  o.fixed_vlog2 = 12;
  EXPECT_EQ(ValidateSpectralOptions(o).message(),
            "fixed_ulog2 x fixed_vlog2 = 6 x 12: 12 is outside 0..9");
  o = {};
  o.rule = static_cast<ResolutionRule>(7);
  EXPECT_EQ(ValidateSpectralOptions(o).message(), "rule = 7: not one of bound, nonzero or fixed");
}

TEST(SpectralOptionsTest, RuleNamesRoundTrip) {
  for (ResolutionRule r :
       {ResolutionRule::kErrorBound, ResolutionRule::kNonzero, ResolutionRule::kFixed}) {
    auto parsed = ParseResolutionRule(ResolutionRuleName(r));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, r);
  }
  EXPECT_EQ(ParseResolutionRule("exact").status().message(),
            "unknown resolution rule 'exact' (expected bound, nonzero or fixed)");
}

TEST(TruncationBoundsTest, EveryCandidateMatchesTheDirectSum) {
  std::mt19937 rng(8);
  for (auto [lx, ly] : {std::pair{0, 0}, std::pair{3, 3}, std::pair{6, 2}, std::pair{0, 5},
                        std::pair{9, 1}, std::pair{5, 6}}) {
    const int nx = 1 << lx, ny = 1 << ly;
    // Arbitrary unnormalised coefficients Y; orthonormal F(u,v) = Y a(u)/2 a(v)/2.
    std::vector<float> raw = spectral_test::UniformNoise(nx * ny, 10.0f, rng());
    std::vector<double> f(raw.size());
    for (int v = 0; v < ny; ++v) {
      for (int u = 0; u < nx; ++u) {
        f[v * nx + u] =
            raw[v * nx + u] * spectral_test::Alpha(u, nx) / 2 * spectral_test::Alpha(v, ny) / 2;
      }
    }
    spectral::TruncationBounds bounds;
    bounds.Build(raw.data(), *spectral::MakeBlockShape(nx, ny));
    for (int kx = 0; kx <= lx + 1; ++kx) {
      for (int ky = 0; ky <= ly + 1; ++ky) {
        const double direct = spectral_test::DirectBound(f, nx, ny, 1 << kx, 1 << ky);
        EXPECT_NEAR(bounds.Bound(kx, ky), direct, 1e-12 * (1 + direct)) << kx << " " << ky;
      }
    }
    // Smallest: fewest texels with bound <= tolerance, then smaller bound, then smaller kx.
    for (double tolerance : {0.0, 0.01, 0.1, 1.0, 5.0, 1e9}) {
      int best_kx = -1, best_ky = -1;
      double best = 0;
      for (int kx = 0; kx <= lx; ++kx) {
        for (int ky = 0; ky <= ly; ++ky) {
          const double b = bounds.Bound(kx, ky);
          if (b > tolerance) continue;
          const bool better = best_kx < 0 || kx + ky < best_kx + best_ky ||
                              (kx + ky == best_kx + best_ky && b < best);
          if (better) {
            best_kx = kx;
            best_ky = ky;
            best = b;
          }
        }
      }
      EXPECT_EQ(bounds.Smallest(tolerance), std::make_pair(best_kx, best_ky)) << tolerance;
    }
  }
}

}  // namespace
}  // namespace dispex
