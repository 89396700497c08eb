// Half-float conversions against the compiler's own IEEE binary16 type (_Float16, converted
// by libgcc with round-to-nearest-even) and against known bit patterns.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "dispex/ptex.h"

namespace dispex {
namespace {

std::uint16_t OracleFromFloat(float f) {
  return std::bit_cast<std::uint16_t>(static_cast<_Float16>(f));
}
std::uint16_t OracleFromDouble(double d) {
  return std::bit_cast<std::uint16_t>(static_cast<_Float16>(d));
}
float OracleToFloat(std::uint16_t h) {
  return static_cast<float>(std::bit_cast<_Float16>(h));
}

bool IsNanHalf(std::uint16_t h) {
  return (h & 0x7c00) == 0x7c00 && (h & 0x3ff) != 0;
}

TEST(PtexHalf, KnownValues) {
  EXPECT_EQ(FloatToHalf(0.0f), 0x0000);
  EXPECT_EQ(FloatToHalf(-0.0f), 0x8000);
  EXPECT_EQ(FloatToHalf(1.0f), 0x3c00);
  EXPECT_EQ(FloatToHalf(-1.0f), 0xbc00);
  EXPECT_EQ(FloatToHalf(0.75f), 0x3a00);
  EXPECT_EQ(FloatToHalf(0.0625f), 0x2c00);
  EXPECT_EQ(FloatToHalf(-0.00390625f), 0x9c00);
  EXPECT_EQ(FloatToHalf(65504.0f), 0x7bff);    // largest finite half
  EXPECT_EQ(FloatToHalf(65519.996f), 0x7bff);  // just below the midpoint
  EXPECT_EQ(FloatToHalf(65520.0f), 0x7c00);    // midpoint: ties to even = overflow
  EXPECT_EQ(FloatToHalf(1e6f), 0x7c00);        // overflow to infinity
  EXPECT_EQ(FloatToHalf(-1e6f), 0xfc00);
  EXPECT_EQ(FloatToHalf(std::numeric_limits<float>::infinity()), 0x7c00);
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -14)), 0x0400);  // smallest normal
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -24)), 0x0001);  // smallest subnormal
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -25)), 0x0000);  // tie between 0 and 1: even (0)
  EXPECT_EQ(FloatToHalf(std::ldexp(3.0f, -25)), 0x0002);  // tie between 1 and 2: even (2)
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -25) * 1.0000001f), 0x0001);
  EXPECT_EQ(FloatToHalf(1.0f + std::ldexp(1.0f, -11)), 0x3c00);      // tie: even
  EXPECT_EQ(FloatToHalf(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3c02);  // tie: even (up)
  EXPECT_EQ(FloatToHalf(1e-8f), 0x0000);
  EXPECT_TRUE(IsNanHalf(FloatToHalf(std::numeric_limits<float>::quiet_NaN())));
  EXPECT_TRUE(IsNanHalf(FloatToHalf(std::bit_cast<float>(0x7f800001u))));  // signalling NaN
  EXPECT_EQ(HalfToFloat(0x7bff), 65504.0f);
  EXPECT_EQ(HalfToFloat(0x0001), std::ldexp(1.0f, -24));
  EXPECT_EQ(HalfToFloat(0x03ff), std::ldexp(1023.0f, -24));
  EXPECT_EQ(HalfToFloat(0xfc00), -std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(HalfToFloat(0x7e00)));
  EXPECT_EQ(DoubleToHalf(65520.0), 0x7c00);
  EXPECT_EQ(DoubleToHalf(65519.999999), 0x7bff);
  EXPECT_EQ(DoubleToHalf(std::ldexp(1.0, -25)), 0x0000);
  EXPECT_EQ(DoubleToHalf(-0.439453125), 0xb708);
}

// Every half: decoding matches the oracle, and encoding the decoded value gives it back.
TEST(PtexHalf, AllHalvesRoundTrip) {
  for (std::uint32_t h = 0; h < 65536; ++h) {
    const auto bits = static_cast<std::uint16_t>(h);
    const float f = HalfToFloat(bits);
    if (IsNanHalf(bits)) {
      ASSERT_TRUE(std::isnan(f)) << h;
      ASSERT_TRUE(IsNanHalf(FloatToHalf(f))) << h;
      continue;
    }
    ASSERT_EQ(std::bit_cast<std::uint32_t>(f), std::bit_cast<std::uint32_t>(OracleToFloat(bits)))
        << h;
    ASSERT_EQ(FloatToHalf(f), bits) << h;
    ASSERT_EQ(DoubleToHalf(static_cast<double>(f)), bits) << h;
  }
}

// Midpoints between consecutive halves, and one float ulp either side, round as the oracle
// (ties to even).
TEST(PtexHalf, MidpointsRoundToEven) {
  for (std::uint32_t h = 0; h < 0x7c00; ++h) {
    const double lo = HalfToFloat(static_cast<std::uint16_t>(h));
    const double hi = h + 1 < 0x7c00 ? HalfToFloat(static_cast<std::uint16_t>(h + 1)) : 65536.0;
    const float mid = static_cast<float>((lo + hi) / 2);  // exact in float
    for (float x : {mid, std::nextafter(mid, 0.0f), std::nextafter(mid, 1e9f)}) {
      ASSERT_EQ(FloatToHalf(x), OracleFromFloat(x)) << x;
      ASSERT_EQ(FloatToHalf(-x), OracleFromFloat(-x)) << x;
      ASSERT_EQ(DoubleToHalf(x), OracleFromDouble(x)) << x;
    }
    const double dmid = (lo + hi) / 2;
    for (double x : {dmid, std::nextafter(dmid, 0.0), std::nextafter(dmid, 1e9)}) {
      ASSERT_EQ(DoubleToHalf(x), OracleFromDouble(x)) << x;
    }
  }
}

// Every float whose bits around the rounding position take the interesting values, and
// random floats and doubles over the whole range.
TEST(PtexHalf, FloatsMatchTheOracle) {
  const std::uint32_t low[] = {0, 1, 0x7ff, 0x800, 0x801, 0xfff, 0x1000, 0x1001, 0x1fff};
  for (std::uint32_t high = 0; high < (1u << 19); ++high) {
    for (std::uint32_t l : low) {
      const std::uint32_t bits = (high << 13) | l;
      const float f = std::bit_cast<float>(bits);
      if (std::isnan(f)) continue;
      ASSERT_EQ(FloatToHalf(f), OracleFromFloat(f)) << std::hex << bits;
    }
  }
  std::mt19937_64 rng(12345);
  for (int i = 0; i < (1 << 21); ++i) {
    const float f = std::bit_cast<float>(static_cast<std::uint32_t>(rng()));
    if (!std::isnan(f)) {
      ASSERT_EQ(FloatToHalf(f), OracleFromFloat(f)) << f;
    }
    // Doubles concentrated in the half range.
    const double d = std::ldexp(static_cast<double>(rng() >> 11) / 9007199254740992.0,
                                static_cast<int>(rng() % 48) - 30) *
                     ((rng() & 1) ? -1 : 1);
    ASSERT_EQ(DoubleToHalf(d), OracleFromDouble(d)) << d;
  }
}

}  // namespace
}  // namespace dispex
