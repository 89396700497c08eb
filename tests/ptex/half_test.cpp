// Half-float conversions against known bit patterns and against the compiler's own IEEE
// binary16 type (_Float16, converted by libgcc with round-to-nearest-even), which agrees with
// the reference Ptex rule (ties away from zero, -0 -> +0) everywhere but on exact ties and -0.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "dispex/ptex.h"

namespace dispex {
namespace {

float OracleToFloat(std::uint16_t h) {
  return static_cast<float>(std::bit_cast<_Float16>(h));
}

// The reference rule from _Float16: an exact tie between two halves takes the one of larger
// magnitude; zero is +0.
std::uint16_t OracleFromFloat(float f) {
  if (f == 0) return 0;
  const auto even = std::bit_cast<std::uint16_t>(static_cast<_Float16>(f));
  if ((even & 0x7c00) == 0x7c00) return even;  // infinity or NaN
  const auto magnitude = static_cast<std::uint16_t>(even & 0x7fff);
  const double a = std::fabs(static_cast<double>(f));
  const double at = OracleToFloat(magnitude);
  // The other neighbour of |f|, on the far side of the rounded value.
  const double other = a > at ? (magnitude + 1 < 0x7c00 ? OracleToFloat(magnitude + 1) : 65536.0)
                              : (magnitude > 0 ? OracleToFloat(magnitude - 1) : 0.0);
  const bool tie = a != at && std::fabs(a - at) == std::fabs(a - other);
  if (!tie || other < at) return even;
  return static_cast<std::uint16_t>((even & 0x8000) | (magnitude + 1));
}
std::uint16_t OracleFromDouble(double d) {
  return OracleFromFloat(static_cast<float>(d));
}

bool IsNanHalf(std::uint16_t h) {
  return (h & 0x7c00) == 0x7c00 && (h & 0x3ff) != 0;
}

TEST(PtexHalf, KnownValues) {
  EXPECT_EQ(FloatToHalf(0.0f), 0x0000);
  EXPECT_EQ(FloatToHalf(-0.0f), 0x0000);  // the reference writes -0 as +0
  EXPECT_EQ(FloatToHalf(1.0f), 0x3c00);
  EXPECT_EQ(FloatToHalf(-1.0f), 0xbc00);
  EXPECT_EQ(FloatToHalf(0.75f), 0x3a00);
  EXPECT_EQ(FloatToHalf(0.0625f), 0x2c00);
  EXPECT_EQ(FloatToHalf(-0.00390625f), 0x9c00);
  EXPECT_EQ(FloatToHalf(65504.0f), 0x7bff);    // largest finite half
  EXPECT_EQ(FloatToHalf(65519.996f), 0x7bff);  // just below the midpoint
  EXPECT_EQ(FloatToHalf(65520.0f), 0x7c00);    // midpoint: away from zero = overflow
  EXPECT_EQ(FloatToHalf(1e6f), 0x7c00);        // overflow to infinity
  EXPECT_EQ(FloatToHalf(-1e6f), 0xfc00);
  EXPECT_EQ(FloatToHalf(std::numeric_limits<float>::infinity()), 0x7c00);
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -14)), 0x0400);  // smallest normal
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -24)), 0x0001);  // smallest subnormal
  // Ties round away from zero (IEEE's ties-to-even would give the first of each pair).
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -25)), 0x0001);  // tie between 0 and 1
  EXPECT_EQ(FloatToHalf(-std::ldexp(1.0f, -25)), 0x8001);
  EXPECT_EQ(FloatToHalf(std::ldexp(3.0f, -25)), 0x0002);  // tie between 1 and 2
  EXPECT_EQ(FloatToHalf(std::ldexp(5.0f, -25)), 0x0003);  // tie between 2 and 3
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -25) * 0.9999999f), 0x0000);
  EXPECT_EQ(FloatToHalf(1.0f + std::ldexp(1.0f, -11)), 0x3c01);      // tie: up
  EXPECT_EQ(FloatToHalf(-1.0f - std::ldexp(1.0f, -11)), 0xbc01);     // tie: away from zero
  EXPECT_EQ(FloatToHalf(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3c02);  // tie: up
  EXPECT_EQ(FloatToHalf(std::ldexp(2047.0f, -25)), 0x0400);          // tie: up into the normals
  EXPECT_EQ(FloatToHalf(2049.0f), 0x6801);                           // 2048 | 2050: up
  EXPECT_EQ(FloatToHalf(1e-8f), 0x0000);
  EXPECT_TRUE(IsNanHalf(FloatToHalf(std::numeric_limits<float>::quiet_NaN())));
  EXPECT_TRUE(IsNanHalf(FloatToHalf(std::bit_cast<float>(0x7f800001u))));  // signalling NaN
  EXPECT_EQ(HalfToFloat(0x7bff), 65504.0f);
  EXPECT_EQ(HalfToFloat(0x0001), std::ldexp(1.0f, -24));
  EXPECT_EQ(HalfToFloat(0x03ff), std::ldexp(1023.0f, -24));
  EXPECT_EQ(HalfToFloat(0xfc00), -std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(HalfToFloat(0x7e00)));
  EXPECT_EQ(DoubleToHalf(65520.0), 0x7c00);
  // 65519.999999 rounds to the float 65520 first, then (a tie) to infinity, as in the reference.
  EXPECT_EQ(DoubleToHalf(65519.999999), 0x7c00);
  EXPECT_EQ(DoubleToHalf(65519.99), 0x7bff);
  EXPECT_EQ(DoubleToHalf(std::ldexp(1.0, -25)), 0x0001);
  // Rounded to float first: just above a tie in double, exactly the tie in float.
  EXPECT_EQ(DoubleToHalf(1.0 + std::ldexp(1.0, -11) - std::ldexp(1.0, -40)), 0x3c01);
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
    const std::uint16_t back = bits == 0x8000 ? 0 : bits;  // -0 is written as +0
    ASSERT_EQ(FloatToHalf(f), back) << h;
    ASSERT_EQ(DoubleToHalf(static_cast<double>(f)), back) << h;
  }
}

// Midpoints between consecutive halves round away from zero, and one float ulp either side
// to the nearer half.
TEST(PtexHalf, MidpointsRoundAwayFromZero) {
  for (std::uint32_t h = 0; h < 0x7c00; ++h) {
    const double lo = HalfToFloat(static_cast<std::uint16_t>(h));
    const double hi = h + 1 < 0x7c00 ? HalfToFloat(static_cast<std::uint16_t>(h + 1)) : 65536.0;
    const float mid = static_cast<float>((lo + hi) / 2);  // exact in float
    ASSERT_EQ(FloatToHalf(mid), h + 1) << mid;
    ASSERT_EQ(FloatToHalf(-mid), 0x8000 | (h + 1)) << mid;
    ASSERT_EQ(FloatToHalf(std::nextafter(mid, 0.0f)), h) << mid;
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
