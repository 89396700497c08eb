// Resolution choice with known answers: blocks whose spectrum is known exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "block_generators.h"
#include "dct_reference.h"
#include "dispex/spectral.h"
#include "spectral/analyzer_steps.h"
#include "spectral/bilinear_readback.h"

namespace dispex {
namespace {

using spectral_test::CosineBlock;
using spectral_test::CosineTerm;
using spectral_test::CosineValue;

SpectralOptions BoundOptions(double tolerance, bool verify = true) {
  SpectralOptions o;
  o.rule = ResolutionRule::kErrorBound;
  o.tolerance = tolerance;
  o.verify = verify;
  return o;
}

int Log2Holding(int highest_index) {
  return std::countr_zero(std::bit_ceil(static_cast<unsigned>(highest_index + 1)));
}

TEST(ResolutionTest, CosinesGetTheResolutionThatHoldsThem) {
  const std::vector<CosineTerm> terms = {{0, 0, 0.3}, {3, 1, 0.2}, {5, 2, -0.1}};
  const std::vector<float> block = CosineBlock(64, 64, terms);
  SpectralAnalyzer analyzer;
  auto face = analyzer.Analyze(block, 64, 64, BoundOptions(1e-4, /*verify=*/false));
  ASSERT_TRUE(face.ok()) << face.status().message();
  EXPECT_EQ(face->ulog2, 3);  // u up to 5 needs 8 texels
  EXPECT_EQ(face->vlog2, 2);  // v up to 2 needs 4
  EXPECT_EQ(face->stats.bound_ulog2, 3);
  EXPECT_EQ(face->stats.bound_vlog2, 2);
  EXPECT_EQ(face->stats.step_ups, 0);
  EXPECT_FALSE(face->constant);
  EXPECT_LE(face->stats.bound, 1e-4);
  ASSERT_EQ(face->texels.size(), 32u);
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 8; ++i) {
      EXPECT_NEAR(face->texels[j * 8 + i], CosineValue(terms, (i + 0.5) / 8, (j + 0.5) / 4), 1e-6)
          << i << ", " << j;
    }
  }
}

TEST(ResolutionTest, RandomCosineSetsGetExactlyTheirBand) {
  std::mt19937 rng(2024);
  SpectralAnalyzer analyzer;
  for (int trial = 0; trial < 200; ++trial) {
    const int nx = 1 << std::uniform_int_distribution<int>(0, 7)(rng);
    const int ny = 1 << std::uniform_int_distribution<int>(0, 7)(rng);
    std::vector<CosineTerm> terms = {{0, 0, std::uniform_real_distribution<double>(-1, 1)(rng)}};
    int u_max = 0, v_max = 0;
    const int count = std::uniform_int_distribution<int>(1, 4)(rng);
    for (int k = 0; k < count; ++k) {
      CosineTerm c;
      c.u = std::uniform_int_distribution<int>(0, nx - 1)(rng);
      c.v = std::uniform_int_distribution<int>(0, ny - 1)(rng);
      c.amplitude = std::uniform_real_distribution<double>(0.05, 0.5)(rng) * (k % 2 ? -1 : 1);
      u_max = std::max(u_max, c.u);
      v_max = std::max(v_max, c.v);
      terms.push_back(c);
    }
    const std::vector<float> block = CosineBlock(nx, ny, terms);
    auto face = analyzer.Analyze(block, nx, ny, BoundOptions(1e-4, /*verify=*/false));
    ASSERT_TRUE(face.ok()) << face.status().message();
    SCOPED_TRACE(testing::Message()
                 << nx << " x " << ny << " u_max " << u_max << " v_max " << v_max);
    if (u_max == 0 && v_max == 0) {
      EXPECT_TRUE(face->constant);
      continue;
    }
    EXPECT_EQ(face->ulog2, Log2Holding(u_max));
    EXPECT_EQ(face->vlog2, Log2Holding(v_max));
    const int rx = 1 << face->ulog2, ry = 1 << face->vlog2;
    for (int j = 0; j < ry; ++j) {
      for (int i = 0; i < rx; ++i) {
        ASSERT_NEAR(face->texels[j * rx + i], CosineValue(terms, (i + 0.5) / rx, (j + 0.5) / ry),
                    1e-6);
      }
    }
  }
}

TEST(ResolutionTest, VerificationStepsUpUntilTheReadBackIsWithinTolerance) {
  // u = 5 on 8 texels is close to their Nyquist limit: a bilinear read-back of 8 texels is far
  // from the cosine, so the verified resolution must be finer than the bound's.
  const std::vector<CosineTerm> terms = {{0, 0, 0.3}, {5, 2, -0.1}};
  const std::vector<float> block = CosineBlock(64, 64, terms);
  SpectralAnalyzer analyzer;
  const double tolerance = 1e-3;
  auto face = analyzer.Analyze(block, 64, 64, BoundOptions(tolerance));
  ASSERT_TRUE(face.ok());
  EXPECT_EQ(face->stats.bound_ulog2, 3);
  EXPECT_EQ(face->stats.bound_vlog2, 2);
  EXPECT_GT(face->stats.step_ups, 0);
  EXPECT_EQ(face->ulog2 + face->vlog2, 3 + 2 + face->stats.step_ups);
  EXPECT_LE(face->stats.measured_error, tolerance);
  const std::vector<float> texels(face->texels.begin(), face->texels.end());
  EXPECT_LE(spectral_test::ReferenceReadBackError(texels, 1 << face->ulog2, 1 << face->vlog2, block,
                                                  64, 64),
            tolerance);
  // The texels are the DCT-domain resampling at the final resolution, and the bound's own
  // choice did fail the read-back check.
  std::vector<float> again(texels.size());
  ASSERT_TRUE(
      spectral::AnalyzerSteps::Resample(analyzer, block, 64, 64, face->ulog2, face->vlog2, again)
          .ok());
  EXPECT_EQ(again, texels);
  std::vector<float> bound_choice(32);
  ASSERT_TRUE(spectral::AnalyzerSteps::Resample(analyzer, block, 64, 64, 3, 2, bound_choice).ok());
  EXPECT_GT(*spectral::MaxBilinearError(bound_choice, 3, 2, block, 64, 64), tolerance);
}

TEST(ResolutionTest, ConstantBlockBecomesConstantFace) {
  SpectralAnalyzer analyzer;
  const std::vector<float> block(32 * 16, -0.125f);
  auto face = analyzer.Analyze(block, 32, 16, BoundOptions(0.0));
  ASSERT_TRUE(face.ok());
  EXPECT_TRUE(face->constant);
  EXPECT_TRUE(face->stats.constant);
  EXPECT_EQ(face->constant_value, -0.125f);
  EXPECT_EQ(face->ulog2, 0);
  EXPECT_EQ(face->vlog2, 0);
  ASSERT_EQ(face->texels.size(), 1u);
  EXPECT_EQ(face->texels[0], -0.125f);
  EXPECT_EQ(face->stats.texels_before, 512);
  EXPECT_EQ(face->stats.texels_after, 1);
  EXPECT_EQ(face->stats.measured_error, 0.0);
}

TEST(ResolutionTest, NearlyFlatBlockBecomesItsMean) {
  SpectralAnalyzer analyzer;
  std::vector<float> block = spectral_test::UniformNoise(64 * 64, 1e-4f, 7);
  for (float& v : block) v += 2.0f;
  double mean = 0;
  for (float v : block) mean += v;
  mean /= block.size();
  auto face = analyzer.Analyze(block, 64, 64, BoundOptions(2e-4));
  ASSERT_TRUE(face.ok());
  ASSERT_TRUE(face->constant);
  EXPECT_FLOAT_EQ(face->constant_value, static_cast<float>(mean));
  for (float v : block) EXPECT_LE(std::fabs(v - face->constant_value), 2e-4);
  EXPECT_LE(face->stats.measured_error, 2e-4);
  // The same block with a tolerance below its spread is not constant.
  auto strict = analyzer.Analyze(block, 64, 64, BoundOptions(5e-5));
  ASSERT_TRUE(strict.ok());
  EXPECT_FALSE(strict->constant);
  EXPECT_LE(strict->stats.measured_error, 5e-5);
}

TEST(ResolutionTest, NoiseKeepsFullResolution) {
  SpectralAnalyzer analyzer;
  for (auto [nx, ny] : {std::pair{64, 64}, std::pair{16, 128}, std::pair{1, 32}}) {
    const std::vector<float> block = spectral_test::UniformNoise(nx * ny, 1.0f, 31u + nx);
    auto face = analyzer.Analyze(block, nx, ny, BoundOptions(1e-3));
    ASSERT_TRUE(face.ok());
    EXPECT_EQ(1 << face->ulog2, nx);
    EXPECT_EQ(1 << face->vlog2, ny);
    EXPECT_EQ(face->stats.measured_error, 0.0);
    EXPECT_EQ(face->stats.bound, 0.0);
    ASSERT_EQ(face->texels.size(), block.size());
    EXPECT_TRUE(std::equal(block.begin(), block.end(), face->texels.begin()));  // bit for bit
  }
}

TEST(ResolutionTest, UAndVAreChosenIndependently) {
  SpectralAnalyzer analyzer;
  for (int trial = 0; trial < 20; ++trial) {
    // A profile along one direction only: smooth or sharp.
    const int n = 64;
    std::vector<float> profile(n);
    const bool sharp = trial % 2 == 1;
    for (int k = 0; k < n; ++k) {
      const double s = (k + 0.5) / n;
      profile[k] = sharp ? (s > 0.3 + 0.01 * trial ? 0.2f : -0.1f)
                         : static_cast<float>(0.1 * std::sin(3 * s + trial) + 0.05 * s * s);
    }
    std::vector<float> along_u(n * 32), along_v(32 * n);
    for (int j = 0; j < 32; ++j) {
      for (int i = 0; i < n; ++i) along_u[j * n + i] = profile[i];
    }
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < 32; ++i) along_v[j * 32 + i] = profile[j];
    }
    auto fu = analyzer.Analyze(along_u, n, 32, BoundOptions(1e-4));
    ASSERT_TRUE(fu.ok());
    EXPECT_GT(fu->ulog2, 0);
    EXPECT_EQ(fu->vlog2, 0) << "trial " << trial;
    EXPECT_LE(fu->stats.measured_error, 1e-4);
    auto fv = analyzer.Analyze(along_v, 32, n, BoundOptions(1e-4));
    ASSERT_TRUE(fv.ok());
    EXPECT_EQ(fv->ulog2, 0) << "trial " << trial;
    EXPECT_GT(fv->vlog2, 0);
    EXPECT_EQ(fv->vlog2, fu->ulog2);  // the transposed problem has the transposed answer
    EXPECT_LE(fv->stats.measured_error, 1e-4);
  }
}

TEST(ResolutionTest, NonSquareBlocks) {
  SpectralAnalyzer analyzer;
  struct Case {
    int nx, ny;
    std::vector<CosineTerm> terms;
    int ulog2, vlog2;
  };
  const std::vector<Case> cases = {
      {128, 8, {{0, 0, 1.0}, {9, 0, 0.2}, {2, 3, 0.1}}, 4, 2},
      {4, 256, {{1, 100, 0.3}}, 1, 7},
      {1, 64, {{0, 0, -1.0}, {0, 7, 0.25}}, 0, 3},
      {512, 1, {{300, 0, 0.5}}, 9, 0},
      {2, 2, {{1, 1, 0.5}}, 1, 1},
  };
  for (const Case& c : cases) {
    const std::vector<float> block = CosineBlock(c.nx, c.ny, c.terms);
    auto face = analyzer.Analyze(block, c.nx, c.ny, BoundOptions(1e-4, /*verify=*/false));
    ASSERT_TRUE(face.ok());
    EXPECT_EQ(face->ulog2, c.ulog2) << c.nx << " x " << c.ny;
    EXPECT_EQ(face->vlog2, c.vlog2) << c.nx << " x " << c.ny;
    auto verified = analyzer.Analyze(block, c.nx, c.ny, BoundOptions(1e-4));
    ASSERT_TRUE(verified.ok());
    EXPECT_GE(verified->ulog2, c.ulog2);
    EXPECT_GE(verified->vlog2, c.vlog2);
    EXPECT_LE(verified->stats.measured_error, 1e-4);
  }
}

TEST(ResolutionTest, StatsBoundIsTheDirectSumOverDroppedCoefficients) {
  SpectralAnalyzer analyzer;
  std::mt19937 rng(77);
  for (int trial = 0; trial < 30; ++trial) {
    const int nx = 1 << std::uniform_int_distribution<int>(2, 6)(rng);
    const int ny = 1 << std::uniform_int_distribution<int>(2, 6)(rng);
    const auto kind = static_cast<spectral_test::BlockKind>(trial % spectral_test::kBlockKinds);
    const std::vector<float> block = spectral_test::RandomBlock(kind, nx, ny, 0.01, rng);
    auto face = analyzer.Analyze(block, nx, ny, BoundOptions(1e-4, /*verify=*/false));
    ASSERT_TRUE(face.ok());
    if (face->constant) continue;
    const std::vector<double> f =
        spectral_test::SeparableDct(spectral_test::ToDouble(block), nx, ny);
    const double direct = spectral_test::DirectBound(f, nx, ny, 1 << face->ulog2, 1 << face->vlog2);
    EXPECT_NEAR(face->stats.bound, direct, 1e-4 * direct + 2e-6);
    // Minimality: every power-of-two pair with fewer texels has a bound above the tolerance
    // (up to the float rounding of the coefficients).
    for (int lu = 0; (1 << lu) <= nx; ++lu) {
      for (int lv = 0; (1 << lv) <= ny; ++lv) {
        if (lu + lv >= face->ulog2 + face->vlog2) continue;
        EXPECT_GT(spectral_test::DirectBound(f, nx, ny, 1 << lu, 1 << lv), 1e-4 - 2e-6);
      }
    }
  }
}

TEST(ResolutionTest, NonzeroRuleIsHighestFrequencyTimesTwo) {
  SpectralAnalyzer analyzer;
  SpectralOptions o;
  o.rule = ResolutionRule::kNonzero;
  o.nonzero_threshold = 1e-3;
  const std::vector<CosineTerm> terms = {{0, 0, 0.3}, {3, 1, 0.2}, {5, 2, -0.1}};
  const std::vector<float> block = CosineBlock(64, 64, terms);
  auto face = analyzer.Analyze(block, 64, 64, o);
  ASSERT_TRUE(face.ok());
  EXPECT_EQ(face->ulog2, 4);  // 2 * 5 = 10 -> 16
  EXPECT_EQ(face->vlog2, 2);  // 2 * 2 = 4 -> 4
  EXPECT_EQ(face->stats.step_ups, 0);
  EXPECT_LE(face->stats.bound, 1e-4);
  // Highest index 1 -> 2 texels; 0 -> 1; 40 -> 80 -> 128 clamped to the 64 samples.
  EXPECT_EQ(analyzer.Analyze(CosineBlock(64, 64, {{1, 0, 0.5}}), 64, 64, o)->ulog2, 1);
  EXPECT_EQ(analyzer.Analyze(CosineBlock(64, 64, {{1, 0, 0.5}}), 64, 64, o)->vlog2, 0);
  EXPECT_EQ(analyzer.Analyze(CosineBlock(64, 64, {{0, 40, 0.5}}), 64, 64, o)->vlog2, 6);
  auto flat = analyzer.Analyze(std::vector<float>(64, 3.0f), 8, 8, o);
  ASSERT_TRUE(flat.ok());
  EXPECT_TRUE(flat->constant);
  EXPECT_EQ(flat->constant_value, 3.0f);
  // With a zero threshold, float rounding makes "non-zero" meaningless: the same smooth block
  // that the bound stores in 8 x 4 texels is kept (nearly) at full resolution.
  o.nonzero_threshold = 0.0;
  auto zero = analyzer.Analyze(block, 64, 64, o);
  ASSERT_TRUE(zero.ok());
  EXPECT_GE(zero->ulog2 + zero->vlog2, 10);
}

TEST(ResolutionTest, FixedRuleResamplesToTheGivenResolution) {
  SpectralAnalyzer analyzer;
  const std::vector<CosineTerm> terms = {{0, 0, 0.3}, {3, 1, 0.2}, {5, 2, -0.1}};
  const std::vector<float> block = CosineBlock(64, 64, terms);
  SpectralOptions o;
  o.rule = ResolutionRule::kFixed;
  for (auto [lu, lv] : {std::pair{3, 3}, std::pair{6, 6}, std::pair{7, 5}, std::pair{0, 0}}) {
    o.fixed_ulog2 = lu;
    o.fixed_vlog2 = lv;
    auto face = analyzer.Analyze(block, 64, 64, o);
    ASSERT_TRUE(face.ok());
    EXPECT_EQ(face->ulog2, lu);
    EXPECT_EQ(face->vlog2, lv);
    EXPECT_EQ(face->constant, lu == 0 && lv == 0);
    const std::vector<float> got(face->texels.begin(), face->texels.end());
    std::vector<float> want(std::size_t{1} << (lu + lv));
    ASSERT_TRUE(spectral::AnalyzerSteps::Resample(analyzer, block, 64, 64, lu, lv, want).ok());
    EXPECT_EQ(got, want);
    auto err = spectral::MaxBilinearError(want, lu, lv, block, 64, 64);
    EXPECT_EQ(face->stats.measured_error, *err);
  }
}

TEST(ResolutionTest, TinyBlocksUnderEveryRule) {
  SpectralAnalyzer analyzer;
  const std::vector<float> one = {0.75f};
  const std::vector<float> two = {0.0f, 1.0f};
  for (ResolutionRule rule :
       {ResolutionRule::kErrorBound, ResolutionRule::kNonzero, ResolutionRule::kFixed}) {
    SpectralOptions o;
    o.rule = rule;
    o.tolerance = 1e-3;
    o.fixed_ulog2 = 0;
    o.fixed_vlog2 = 0;
    auto a = analyzer.Analyze(one, 1, 1, o);
    ASSERT_TRUE(a.ok());
    EXPECT_TRUE(a->constant);
    EXPECT_EQ(a->constant_value, 0.75f);
    EXPECT_EQ(a->stats.measured_error, 0.0);
    o.fixed_ulog2 = 1;
    for (auto [nx, ny] : {std::pair{2, 1}, std::pair{1, 2}}) {
      auto b = analyzer.Analyze(two, nx, ny, o);
      ASSERT_TRUE(b.ok());
      EXPECT_EQ(b->texels.size(), 2u);
      if (rule != ResolutionRule::kFixed) {
        EXPECT_EQ(b->stats.measured_error, 0.0);
        EXPECT_EQ(b->texels[0], 0.0f);
        EXPECT_EQ(b->texels[1], 1.0f);
      }
    }
  }
  // Fixed resolutions beyond the samples: band-limited enlargement of a constant stays constant.
  SpectralOptions o;
  o.rule = ResolutionRule::kFixed;
  o.fixed_ulog2 = 6;
  o.fixed_vlog2 = 6;
  auto big = analyzer.Analyze(one, 1, 1, o);
  ASSERT_TRUE(big.ok());
  ASSERT_EQ(big->texels.size(), 4096u);
  for (float t : big->texels) ASSERT_NEAR(t, 0.75f, 1e-6);
}

TEST(ResolutionTest, RejectsBadInput) {
  SpectralAnalyzer analyzer;
  std::vector<float> block(64, 0.0f);
  EXPECT_EQ(analyzer.Analyze(block, 8, 6, {}).status().message(),
            "block size 8 x 6: 6 is not a power of two in 1..512");
  EXPECT_EQ(analyzer.Analyze(block, 16, 8, {}).status().message(),
            "samples holds 64 values, a 16 x 8 block needs 128");
  block[9] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(analyzer.Analyze(block, 8, 8, {}).status().message(),
            "sample (1, 1) of the 8 x 8 block is not finite (inf)");
  block[9] = 0.0f;
  SpectralOptions o;
  o.tolerance = -1;
  EXPECT_EQ(analyzer.Analyze(block, 8, 8, o).status().message(),
            "tolerance = -1: must be finite and >= 0 (object units)");
  // The analyzer still works after errors.
  EXPECT_TRUE(analyzer.Analyze(block, 8, 8, {}).ok());
}

}  // namespace
}  // namespace dispex

namespace dispex {
namespace {

// A ramp across u, f = 0.5 u (500 tolerances of 1e-3 over the face). The read-back check
// already covers the clamped strip between the outermost texel centre and the outermost
// sample, half a sample from the edge: 0.5 (1 / (2 rx) - 1 / (2 nx)) <= 1e-3 needs rx = 256.
// On the edge itself the per-face reader misses by 0.5 / (2 rx) = 9.8e-4, twice the edge
// tolerance 5e-4, which takes rx = 512.
TEST(ResolutionTest, EdgeToleranceRaisesTheResolutionAcrossASlope) {
  const int nx = 512, ny = 4;
  std::vector<float> samples(nx * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) samples[j * nx + i] = float(0.5 * (i + 0.5) / nx);
  }
  SpectralAnalyzer analyzer;
  SpectralOptions options;
  options.tolerance = 1e-3;
  auto plain = analyzer.Analyze(samples, nx, ny, options);
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->ulog2, 8);
  EXPECT_EQ(plain->stats.edge_error, 0.0);  // not measured without an edge tolerance

  options.edge_tolerance = 5e-4;
  auto watertight = analyzer.Analyze(samples, nx, ny, options);
  ASSERT_TRUE(watertight.ok());
  EXPECT_EQ(watertight->ulog2, 9);
  EXPECT_EQ(watertight->vlog2, 0);
  EXPECT_LE(watertight->stats.edge_error, 5e-4);
  EXPECT_FALSE(watertight->stats.edge_limited);

  // Coarser samples cannot hold it: the face stays at the sample resolution, flagged.
  std::vector<float> coarse(64 * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < 64; ++i) coarse[j * 64 + i] = float(0.5 * (i + 0.5) / 64);
  }
  auto limited = analyzer.Analyze(coarse, 64, ny, options);
  ASSERT_TRUE(limited.ok());
  EXPECT_EQ(limited->ulog2, 6);
  EXPECT_TRUE(limited->stats.edge_limited);
  EXPECT_GT(limited->stats.edge_error, 5e-4);
}

}  // namespace
}  // namespace dispex

namespace dispex {
namespace {

// A least resolution is honoured (capped at the sample grid) and keeps a flat face from
// becoming constant.
TEST(ResolutionTest, LeastResolutionIsAFloor) {
  const std::vector<float> flat(32 * 16, 0.25f);
  SpectralAnalyzer analyzer;
  SpectralOptions options;
  options.tolerance = 1e-3;
  auto plain = analyzer.Analyze(flat, 32, 16, options);
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->constant);
  options.min_ulog2 = 3;
  options.min_vlog2 = 6;
  auto floored = analyzer.Analyze(flat, 32, 16, options);
  ASSERT_TRUE(floored.ok());
  EXPECT_FALSE(floored->constant);
  EXPECT_EQ(floored->ulog2, 3);
  EXPECT_EQ(floored->vlog2, 4);
  for (float t : floored->texels) EXPECT_FLOAT_EQ(t, 0.25f);
}

}  // namespace
}  // namespace dispex
