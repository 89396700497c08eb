// SpectralVectorAnalyzer: one resolution for three channels, every error the vector's norm.
// Known answers: a vector with one live channel is analysed exactly as that channel alone
// (rejects mixing or mis-interleaving channels); channels with detail along different axes get
// a resolution holding both (rejects analysing one channel, or the first); the vector
// read-back, recomputed independently per channel, is within the tolerance (rejects a
// per-channel check that lets the vector error reach sqrt(3) tau).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "block_generators.h"
#include "dispex/spectral.h"
#include "spectral/bilinear_readback.h"

namespace dispex {
namespace {

using spectral_test::BlockKind;
using spectral_test::CosineBlock;
using spectral_test::CosineTerm;
using spectral_test::RandomBlock;

SpectralOptions Bound(double tolerance) {
  SpectralOptions o;
  o.tolerance = tolerance;
  return o;
}

std::vector<float> Interleave(const std::vector<float>& a, const std::vector<float>& b,
                              const std::vector<float>& c) {
  std::vector<float> out(3 * a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    out[3 * k] = a[k];
    out[3 * k + 1] = b[k];
    out[3 * k + 2] = c[k];
  }
  return out;
}

std::vector<float> Channel(std::span<const float> texels, int c) {
  std::vector<float> out(texels.size() / 3);
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = texels[3 * k + static_cast<std::size_t>(c)];
  return out;
}

// max over samples of |vector read-back - vector sample|, one channel read back at a time.
double VectorReadBackError(const SpectralVectorFace& face, const std::vector<float>& samples,
                           int nx, int ny) {
  std::vector<double> d2(static_cast<std::size_t>(nx) * ny, 0.0);
  for (int c = 0; c < 3; ++c) {
    std::vector<float> read(d2.size());
    EXPECT_TRUE(
        spectral::BilinearReadBack(Channel(face.texels, c), face.ulog2, face.vlog2, nx, ny, read)
            .ok());
    for (std::size_t k = 0; k < d2.size(); ++k) {
      const double d = static_cast<double>(read[k]) - samples[3 * k + static_cast<std::size_t>(c)];
      d2[k] += d * d;
    }
  }
  double worst = 0;
  for (double x : d2) worst = std::max(worst, x);
  return std::sqrt(worst);
}

SpectralOptions PinnedEdges(double tolerance) {
  SpectralOptions o = Bound(tolerance);
  o.pin_edges = true;
  o.edge_tolerance = 0.5 * tolerance;
  return o;
}

// Also with pinned edges and an edge tolerance (the watertight options): the same texels,
// pinned ones included, and the same edge error.
TEST(VectorAnalyzerTest, OneLiveChannelIsThatChannelsAnalysis) {
  std::mt19937 rng(7);
  const std::vector<float> live = RandomBlock(BlockKind::kSmooth, 64, 32, 1.0, rng);
  const std::vector<float> zero(live.size(), 0.0f);
  for (const SpectralOptions& options : {Bound(1e-3), PinnedEdges(1e-3)}) {
    SpectralAnalyzer scalar;
    const SpectralFace expected = scalar.Analyze(live, 64, 32, options).value();
    const std::vector<float> want(expected.texels.begin(), expected.texels.end());
    for (int c = 0; c < 3; ++c) {
      const std::vector<float> block =
          Interleave(c == 0 ? live : zero, c == 1 ? live : zero, c == 2 ? live : zero);
      SpectralVectorAnalyzer vector;
      const SpectralVectorFace face = vector.Analyze(block, 64, 32, options).value();
      EXPECT_EQ(face.ulog2, expected.ulog2) << c;
      EXPECT_EQ(face.vlog2, expected.vlog2) << c;
      EXPECT_EQ(Channel(face.texels, c), want) << c;
      EXPECT_EQ(Channel(face.texels, (c + 1) % 3), std::vector<float>(want.size(), 0.0f));
      EXPECT_DOUBLE_EQ(face.stats.edge_error, expected.stats.edge_error) << c;
    }
  }
}

// A displacement that turns sideways fast at the face's u = 0 edge: the per-face reader's
// outermost texel, half a texel inside, misses the edge value unless pinned. With the edge
// options every channel's edge reading is within the edge tolerance of the value extrapolated
// from the samples, measured here independently; without them it is over 1.5 x that (rejects
// options that are accepted and ignored, and an edge error taken on one channel only).
TEST(VectorAnalyzerTest, PinnedEdgesHoldTheVectorOnTheEdge) {
  constexpr int n = 128;
  std::vector<float> a(n * n), b(n * n), c(n * n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double u = (i + 0.5) / n, v = (j + 0.5) / n;
      a[static_cast<std::size_t>(j * n + i)] = static_cast<float>(0.01 * std::exp(-6 * u));
      b[static_cast<std::size_t>(j * n + i)] = static_cast<float>(0.01 * std::exp(-6 * u) * v);
      c[static_cast<std::size_t>(j * n + i)] = static_cast<float>(0.001 * std::sin(3 * v));
    }
  }
  const std::vector<float> block = Interleave(a, b, c);
  const double tau = 1e-3;
  // The largest vector distance, along the u = 0 edge, between the face's own reading (its
  // first texel column interpolated along v) and the samples extrapolated to the edge.
  auto left_edge_error = [&](const SpectralVectorFace& face) {
    const int rx = 1 << face.ulog2, ry = 1 << face.vlog2;
    double worst = 0;
    for (int j = 0; j < n; ++j) {
      const double t = std::clamp((j + 0.5) / n * ry - 0.5, 0.0, ry - 1.0);
      const int k = std::min(static_cast<int>(t), ry - 2 < 0 ? 0 : ry - 2);
      const double w = ry > 1 ? t - k : 0;
      double d2 = 0;
      for (int ch = 0; ch < 3; ++ch) {
        const auto at = [&](int row) {
          return static_cast<double>(face.texels[3 * static_cast<std::size_t>(row * rx) + ch]);
        };
        const double read = ry > 1 ? (1 - w) * at(k) + w * at(k + 1) : at(0);
        const float* s = ch == 0 ? a.data() : ch == 1 ? b.data() : c.data();
        const double edge = 1.5 * s[j * n] - 0.5 * s[j * n + 1];
        d2 += (read - edge) * (read - edge);
      }
      worst = std::max(worst, std::sqrt(d2));
    }
    return worst;
  };
  SpectralVectorAnalyzer analyzer;
  const SpectralVectorFace plain = analyzer.Analyze(block, n, n, Bound(tau)).value();
  const double plain_edge = left_edge_error(plain);
  EXPECT_GT(plain_edge, 1.5 * (0.5 * tau)) << "the case must need pinning";
  const SpectralVectorFace pinned = analyzer.Analyze(block, n, n, PinnedEdges(tau)).value();
  EXPECT_FALSE(pinned.stats.edge_limited);
  EXPECT_LE(pinned.stats.edge_error, 0.5 * tau);
  EXPECT_LE(left_edge_error(pinned), 0.5 * tau * (1 + 1e-6));
  EXPECT_LE(pinned.stats.measured_error, tau);
  EXPECT_LE(VectorReadBackError(pinned, block, n, n), tau * (1 + 1e-6));
}

TEST(VectorAnalyzerTest, ChannelsDetailedAlongDifferentAxesShareAResolutionHoldingBoth) {
  // Channel 0 varies along u only (index 9: needs 16 texels in u), channel 2 along v only.
  const std::vector<float> along_u = CosineBlock(64, 64, {{9, 0, 0.05}});
  const std::vector<float> along_v = CosineBlock(64, 64, {{0, 9, 0.05}});
  const std::vector<float> zero(along_u.size(), 0.0f);
  const std::vector<float> block = Interleave(along_u, zero, along_v);
  SpectralVectorAnalyzer analyzer;
  const SpectralVectorFace face = analyzer.Analyze(block, 64, 64, Bound(1e-4)).value();
  EXPECT_GE(face.ulog2, 4);
  EXPECT_GE(face.vlog2, 4);
  EXPECT_LE(face.stats.measured_error, 1e-4);
  EXPECT_LE(VectorReadBackError(face, block, 64, 64), 1e-4 * (1 + 1e-6));
}

TEST(VectorAnalyzerTest, VectorReadBackIsWithinTheTolerance) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const int nx = 8 << (trial % 4), ny = 8 << ((trial / 4) % 3);
    const std::vector<float> block =
        Interleave(RandomBlock(BlockKind::kSmooth, nx, ny, 1.0, rng),
                   RandomBlock(BlockKind::kSmoothPlusDetail, nx, ny, 0.5, rng),
                   RandomBlock(BlockKind::kSmooth, nx, ny, 0.2, rng));
    SpectralVectorAnalyzer analyzer;
    for (double tolerance : {1e-2, 1e-3}) {
      const SpectralVectorFace face = analyzer.Analyze(block, nx, ny, Bound(tolerance)).value();
      ASSERT_LE(face.stats.measured_error, tolerance) << trial;
      ASSERT_LE(VectorReadBackError(face, block, nx, ny), tolerance * (1 + 1e-6)) << trial;
    }
  }
}

TEST(VectorAnalyzerTest, ConstantFullAndFixed) {
  std::vector<float> block(3 * 16 * 16);
  for (std::size_t k = 0; k < block.size(); k += 3) {
    block[k] = 0.5f;
    block[k + 1] = -0.25f;
    block[k + 2] = 2.0f + 1e-5f * static_cast<float>(k % 7);
  }
  SpectralVectorAnalyzer analyzer;
  const SpectralVectorFace constant = analyzer.Analyze(block, 16, 16, Bound(1e-3)).value();
  EXPECT_TRUE(constant.constant);
  EXPECT_EQ(constant.constant_value[0], 0.5f);
  EXPECT_EQ(constant.constant_value[1], -0.25f);
  EXPECT_NEAR(constant.constant_value[2], 2.0f, 1e-4);
  // At a tolerance below the variation the full resolution keeps the samples bit for bit.
  const SpectralVectorFace full = analyzer.Analyze(block, 16, 16, Bound(1e-9)).value();
  EXPECT_EQ(full.ulog2, 4);
  EXPECT_EQ(full.vlog2, 4);
  EXPECT_EQ(std::vector<float>(full.texels.begin(), full.texels.end()), block);
  SpectralOptions fixed;
  fixed.rule = ResolutionRule::kFixed;
  fixed.fixed_ulog2 = 2;
  fixed.fixed_vlog2 = 3;
  const SpectralVectorFace f = analyzer.Analyze(block, 16, 16, fixed).value();
  EXPECT_EQ(f.ulog2, 2);
  EXPECT_EQ(f.vlog2, 3);
  EXPECT_EQ(f.texels.size(), 3u * 4 * 8);
}

TEST(VectorAnalyzerTest, Errors) {
  SpectralVectorAnalyzer analyzer;
  std::vector<float> block(3 * 4 * 4, 0.0f);
  EXPECT_EQ(analyzer.Analyze(std::span(block).first(47), 4, 4, Bound(1e-3)).status().message(),
            "samples holds 47 values, a 4 x 4 block of 3 channels needs 48");
  block[3 * 5 + 2] = std::nanf("");
  EXPECT_EQ(analyzer.Analyze(block, 4, 4, Bound(1e-3)).status().message(),
            "sample (1, 1) channel 2 of the 4 x 4 block is not finite (nan)");
}

}  // namespace
}  // namespace dispex
