// IEEE-754 binary16 conversions, done on the bit patterns so the result does not depend on
// the FPU's rounding mode. Float to half rounds as the reference Ptex library writes halves
// (docs/ptex.md, "Half floats"): to nearest with ties away from zero, for normal and
// subnormal halves alike, and both zeros become +0. Doubles are rounded to float first, as
// the reference library's PtexHalf(double) does.
#include <bit>
#include <cstdint>

#include "dispex/ptex.h"

namespace dispex {

std::uint16_t FloatToHalf(float value) {
  if (value == 0) return 0;
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(value);
  const auto sign = static_cast<std::uint16_t>((bits >> 16) & 0x8000);
  const std::uint32_t abs = bits & 0x7fffffff;
  const std::uint32_t exp = abs >> 23;
  const std::uint32_t mant = abs & 0x7fffff;
  if (exp == 0xff) {  // infinity or NaN
    if (mant == 0) return sign | 0x7c00;
    return static_cast<std::uint16_t>(sign | 0x7e00 | (mant >> 13));
  }
  if (exp > 142) return sign | 0x7c00;  // >= 65536: infinity
  if (exp >= 113) {                     // normal half: exponent -14 .. 15
    // Adding half of the dropped part rounds ties up in magnitude; a carry moves into the
    // exponent, and past 65504 into infinity.
    const std::uint32_t h = ((exp - 112) << 10) + ((mant + 0x1000) >> 13);
    return static_cast<std::uint16_t>(sign | h);
  }
  // Subnormal half (or rounded to zero): |value| / 2^-24, rounded half up. Below exp 102 the
  // quotient is under 0.5.
  if (exp < 102) return sign;
  const std::uint32_t m = mant | 0x800000;
  const int shift = 126 - static_cast<int>(exp);  // 14 .. 24
  return static_cast<std::uint16_t>(sign | ((m + (1u << (shift - 1))) >> shift));
}

std::uint16_t DoubleToHalf(double value) {
  return FloatToHalf(static_cast<float>(value));
}

float HalfToFloat(std::uint16_t h) {
  const std::uint32_t sign = static_cast<std::uint32_t>(h & 0x8000) << 16;
  const std::uint32_t exp = (h >> 10) & 0x1f;
  std::uint32_t mant = h & 0x3ff;
  std::uint32_t bits;
  if (exp == 0x1f) {
    bits = sign | 0x7f800000 | (mant << 13);
  } else if (exp != 0) {
    bits = sign | ((exp + 112) << 23) | (mant << 13);
  } else if (mant == 0) {
    bits = sign;
  } else {  // subnormal: normalise
    int e = 113;
    while ((mant & 0x400) == 0) {
      mant <<= 1;
      --e;
    }
    bits = sign | (static_cast<std::uint32_t>(e) << 23) | ((mant & 0x3ff) << 13);
  }
  return std::bit_cast<float>(bits);
}

}  // namespace dispex
