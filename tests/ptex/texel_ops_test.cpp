// Texel operations against the worked values of docs/ptex.md and against naive
// implementations written here from its formulas ("Texel order, channel split and diff
// encoding", "Reductions", "The triangle rule", "Premultiplication for reductions").
#include "ptex/texel_ops.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "dispex/ptex.h"

namespace dispex {
namespace {

using namespace ptex;

TEST(PtexTexelOps, DifferenceEncodingGuideExample) {
  std::vector<std::uint8_t> d = {10, 12, 11, 200};
  EncodeDifference(d.data(), d.size(), PtexDataType::kUint8);
  EXPECT_EQ(d, (std::vector<std::uint8_t>{10, 2, 255, 189}));
  DecodeDifference(d.data(), d.size(), PtexDataType::kUint8);
  EXPECT_EQ(d, (std::vector<std::uint8_t>{10, 12, 11, 200}));
}

TEST(PtexTexelOps, DifferenceEncodingUint16AndOtherTypes) {
  std::vector<std::uint16_t> v = {1000, 999, 65535, 0, 7};
  std::vector<std::uint8_t> bytes(v.size() * 2);
  std::memcpy(bytes.data(), v.data(), bytes.size());
  EncodeDifference(bytes.data(), bytes.size(), PtexDataType::kUint16);
  std::vector<std::uint16_t> enc(v.size());
  std::memcpy(enc.data(), bytes.data(), bytes.size());
  EXPECT_EQ(enc, (std::vector<std::uint16_t>{1000, 65535, 64536, 1, 7}));
  DecodeDifference(bytes.data(), bytes.size(), PtexDataType::kUint16);
  std::memcpy(enc.data(), bytes.data(), bytes.size());
  EXPECT_EQ(enc, v);
  // Half and float data are never differenced.
  std::vector<std::uint8_t> f = {1, 2, 3, 4, 5, 6, 7, 8};
  const auto copy = f;
  EncodeDifference(f.data(), f.size(), PtexDataType::kFloat);
  EncodeDifference(f.data(), f.size(), PtexDataType::kHalf);
  EXPECT_EQ(f, copy);
}

TEST(PtexTexelOps, ChannelSplitAndMerge) {
  // 3x2 texels of 3 uint16 channels: value = 100 * c + texel index.
  const int ures = 3, vres = 2, nch = 3;
  std::vector<std::uint16_t> inter;
  for (int t = 0; t < ures * vres; ++t)
    for (int c = 0; c < nch; ++c) inter.push_back(static_cast<std::uint16_t>(100 * c + t));
  std::vector<std::uint8_t> planes(inter.size() * 2);
  SplitChannels(reinterpret_cast<const std::uint8_t*>(inter.data()), ures * nch * 2, ures, vres,
                nch, 2, planes.data());
  std::vector<std::uint16_t> p(inter.size());
  std::memcpy(p.data(), planes.data(), planes.size());
  for (int c = 0; c < nch; ++c)
    for (int t = 0; t < ures * vres; ++t) EXPECT_EQ(p[std::size_t(c * 6 + t)], 100 * c + t);
  std::vector<std::uint16_t> back(inter.size());
  MergeChannels(planes.data(), ures, vres, nch, 2, reinterpret_cast<std::uint8_t*>(back.data()),
                ures * nch * 2);
  EXPECT_EQ(back, inter);
}

TEST(PtexTexelOps, QuadReductionMatchesTheFormula) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> val(-3, 3);
  const int ulog2 = 3, vlog2 = 2, nch = 2, w = 8, h = 4;
  std::vector<float> src(std::size_t(w * h * nch));
  for (float& x : src) x = val(rng);
  // float: (a + b + c + d) * 0.25f in float, left to right.
  std::vector<float> dst(src.size() / 4);
  ReduceQuad(reinterpret_cast<const std::uint8_t*>(src.data()), ulog2, vlog2, PtexDataType::kFloat,
             nch, reinterpret_cast<std::uint8_t*>(dst.data()));
  for (int j = 0; j < h / 2; ++j)
    for (int i = 0; i < w / 2; ++i)
      for (int c = 0; c < nch; ++c) {
        auto s = [&](int x, int y) { return src[std::size_t((y * w + x) * nch + c)]; };
        const float expect = (s(2 * i, 2 * j) + s(2 * i + 1, 2 * j) + s(2 * i, 2 * j + 1) +
                              s(2 * i + 1, 2 * j + 1)) *
                             0.25f;
        EXPECT_EQ(dst[std::size_t((j * w / 2 + i) * nch + c)], expect);
      }
  // uint8: floor of the mean.
  std::vector<std::uint8_t> u8 = {255, 254, 1, 0, 3, 3, 3, 2};  // 4x2, 1 channel
  std::vector<std::uint8_t> r(2);
  ReduceQuad(u8.data(), 2, 1, PtexDataType::kUint8, 1, r.data());
  EXPECT_EQ(r[0], (255 + 254 + 3 + 3) / 4);
  EXPECT_EQ(r[1], (1 + 0 + 3 + 2) / 4);
  // half: through float, rounded back.
  std::vector<std::uint16_t> hsrc = {FloatToHalf(1.0f), FloatToHalf(2.0f), FloatToHalf(3.0f),
                                     FloatToHalf(4.5f)};
  std::uint16_t hdst = 0;
  ReduceQuad(reinterpret_cast<const std::uint8_t*>(hsrc.data()), 1, 1, PtexDataType::kHalf, 1,
             reinterpret_cast<std::uint8_t*>(&hdst));
  EXPECT_EQ(HalfToFloat(hdst), 2.625f);
}

TEST(PtexTexelOps, TriangleReductionMatchesTheGuide) {
  // N = 4: output (x, y) averages s(2x,2y), s(2x+1,2y), s(2x,2y+1), s(N-1-2y, N-1-2x).
  const int n = 4;
  std::vector<float> s(16);
  for (int i = 0; i < 16; ++i) s[std::size_t(i)] = static_cast<float>(i * i);
  std::vector<float> d(4);
  ReduceTriangle(reinterpret_cast<const std::uint8_t*>(s.data()), 2, PtexDataType::kFloat, 1,
                 reinterpret_cast<std::uint8_t*>(d.data()));
  auto at = [&](int u, int v) { return s[std::size_t(v * n + u)]; };
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x)
      EXPECT_EQ(d[std::size_t(y * 2 + x)],
                (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) +
                 at(n - 1 - 2 * y, n - 1 - 2 * x)) *
                    0.25f);
  // Upright texel (0,0) of the reduction is made of upright (0,0), (1,0), (0,1) and the
  // inverted texel of row 0, column 0 (stored at (N-1, N-1)).
  EXPECT_EQ(d[0], (at(0, 0) + at(1, 0) + at(0, 1) + at(3, 3)) * 0.25f);
}

TEST(PtexTexelOps, AlphaPremultiplication) {
  // uint8 RGBA, alpha channel 3: colour channels scaled by a/255 with truncation.
  std::vector<std::uint8_t> t = {200, 100, 51, 128, 255, 255, 255, 0};
  MultiplyAlpha(t.data(), 2, PtexDataType::kUint8, 4, 3);
  EXPECT_EQ(t, (std::vector<std::uint8_t>{200 * 128 / 255, 100 * 128 / 255, 51 * 128 / 255, 128, 0,
                                          0, 0, 0}));
  // Alpha channel 0: every other channel; alpha channel 1 of 3: only channel 0.
  std::vector<float> f = {0.5f, 2.0f, 4.0f};
  MultiplyAlpha(reinterpret_cast<std::uint8_t*>(f.data()), 1, PtexDataType::kFloat, 3, 0);
  EXPECT_EQ(f, (std::vector<float>{0.5f, 1.0f, 2.0f}));
  f = {2.0f, 0.5f, 4.0f};
  MultiplyAlpha(reinterpret_cast<std::uint8_t*>(f.data()), 1, PtexDataType::kFloat, 3, 1);
  EXPECT_EQ(f, (std::vector<float>{1.0f, 0.5f, 4.0f}));
  DivideAlpha(reinterpret_cast<std::uint8_t*>(f.data()), 1, PtexDataType::kFloat, 3, 1);
  EXPECT_EQ(f, (std::vector<float>{2.0f, 0.5f, 4.0f}));
  // Zero alpha is left alone; results above the range clamp.
  std::vector<std::uint8_t> z = {50, 0};
  DivideAlpha(z.data(), 1, PtexDataType::kUint8, 2, 1);
  EXPECT_EQ(z, (std::vector<std::uint8_t>{50, 0}));
  std::vector<std::uint8_t> big = {200, 100};
  DivideAlpha(big.data(), 1, PtexDataType::kUint8, 2, 1);
  EXPECT_EQ(big[0], 255);
}

TEST(PtexTexelOps, AverageIsTheExactMean) {
  std::vector<float> f = {1e8f, 1.0f, -1e8f, 1.0f};  // float32 summation would lose the 1s
  float avg = 0;
  Average(reinterpret_cast<const std::uint8_t*>(f.data()), 4, PtexDataType::kFloat, 1,
          reinterpret_cast<std::uint8_t*>(&avg));
  EXPECT_EQ(avg, 0.5f);
  std::vector<std::uint8_t> u = {1, 2, 2, 2};  // 1.75 truncates to 1, as the reference
  std::uint8_t a = 0;
  Average(u.data(), 4, PtexDataType::kUint8, 1, &a);
  EXPECT_EQ(a, 1);
}

TEST(PtexTexelOps, FloatConversions) {
  const std::vector<float> in = {-0.5f, 0.0f, 0.5f, 1.0f, 2.0f, 0.25f, std::nanf("")};
  std::vector<std::uint8_t> u8(in.size());
  FromFloat(in.data(), in.size(), PtexDataType::kUint8, u8.data());
  EXPECT_EQ(u8, (std::vector<std::uint8_t>{0, 0, 128, 255, 255, 64, 0}));
  std::vector<std::uint16_t> u16(in.size());
  FromFloat(in.data(), in.size(), PtexDataType::kUint16,
            reinterpret_cast<std::uint8_t*>(u16.data()));
  EXPECT_EQ(u16, (std::vector<std::uint16_t>{0, 0, 32768, 65535, 65535, 16384, 0}));
  std::vector<float> back(2);
  const std::uint8_t b[2] = {255, 51};
  ToFloat(b, 2, PtexDataType::kUint8, back.data());
  EXPECT_EQ(back[0], 1.0f);
  EXPECT_EQ(back[1], 0.2f);
}

TEST(PtexTexelOps, ConstantDetectionIsBitwise) {
  std::vector<float> f(12, 1.5f);
  EXPECT_TRUE(IsConstant(reinterpret_cast<const std::uint8_t*>(f.data()), 16, 4, 3, 4));
  f[11] = 1.5000001f;
  EXPECT_FALSE(IsConstant(reinterpret_cast<const std::uint8_t*>(f.data()), 16, 4, 3, 4));
  std::vector<float> z = {0.0f, -0.0f};
  EXPECT_FALSE(IsConstant(reinterpret_cast<const std::uint8_t*>(z.data()), 8, 2, 1, 4));
}

}  // namespace
}  // namespace dispex
