// IEEE-754 binary16 conversions with round-to-nearest-even (IEEE 754-2008 §4.3.1), done on
// the bit patterns so the result does not depend on the FPU's rounding mode. The reference
// Ptex library rounds ties away from zero; both are valid files (guide §11.3), they differ
// only on exact ties.
#include <bit>
#include <cstdint>

#include "dispex/ptex.h"

namespace dispex {

namespace {

// Rounds `value >> shift` to nearest, ties to even (shift >= 1).
template <class U>
U ShiftRoundEven(U value, int shift) {
  U q = value >> shift;
  U rem = value & ((U{1} << shift) - 1);
  U half = U{1} << (shift - 1);
  if (rem > half || (rem == half && (q & 1))) ++q;
  return q;
}

}  // namespace

std::uint16_t FloatToHalf(float value) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(value);
  const auto sign = static_cast<std::uint16_t>((bits >> 16) & 0x8000);
  const std::uint32_t abs = bits & 0x7fffffff;
  const std::uint32_t exp = abs >> 23;
  const std::uint32_t mant = abs & 0x7fffff;
  if (exp == 0xff) {  // infinity or NaN
    if (mant == 0) return sign | 0x7c00;
    return static_cast<std::uint16_t>(sign | 0x7e00 | (mant >> 13));
  }
  if (abs >= 0x477ff000) return sign | 0x7c00;  // >= 65520 rounds past 65504: infinity
  if (exp >= 113) {                             // normal half: exponent -14 .. 15
    std::uint32_t h = ((exp - 112) << 10) | (mant >> 13);
    std::uint32_t rem = mant & 0x1fff;
    if (rem > 0x1000 || (rem == 0x1000 && (h & 1))) ++h;  // a carry moves into the exponent
    return static_cast<std::uint16_t>(sign | h);
  }
  // Subnormal half (or zero): value / 2^-24 rounded. Float subnormals are far below.
  if (exp == 0) return sign;
  const int shift = 126 - static_cast<int>(exp);  // >= 14
  if (shift > 24) return sign;
  const std::uint32_t m = mant | 0x800000;
  return static_cast<std::uint16_t>(sign | ShiftRoundEven<std::uint32_t>(m, shift));
}

std::uint16_t DoubleToHalf(double value) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(value);
  const auto sign = static_cast<std::uint16_t>((bits >> 48) & 0x8000);
  const std::uint64_t abs = bits & 0x7fffffffffffffffull;
  const std::uint64_t exp = abs >> 52;
  const std::uint64_t mant = abs & 0xfffffffffffffull;
  if (exp == 0x7ff) {
    if (mant == 0) return sign | 0x7c00;
    return static_cast<std::uint16_t>(sign | 0x7e00 | (mant >> 42));
  }
  if (abs >= 0x40effe0000000000ull) return sign | 0x7c00;  // >= 65520
  if (exp >= 1009) {
    std::uint64_t h = ((exp - 1008) << 10) | (mant >> 42);
    std::uint64_t rem = mant & ((std::uint64_t{1} << 42) - 1);
    std::uint64_t half = std::uint64_t{1} << 41;
    if (rem > half || (rem == half && (h & 1))) ++h;
    return static_cast<std::uint16_t>(sign | h);
  }
  if (exp == 0) return sign;
  const int shift = 1051 - static_cast<int>(exp);  // >= 43
  if (shift > 53) return sign;
  const std::uint64_t m = mant | (std::uint64_t{1} << 52);
  return static_cast<std::uint16_t>(sign | ShiftRoundEven<std::uint64_t>(m, shift));
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
