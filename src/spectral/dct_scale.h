// Scale factors between FFTW's unnormalised REDFT10/REDFT01 and the orthonormal DCT-II/III.
//
// REDFT10 gives Y(k) = 2 sum_x f(x) cos(pi(2x+1)k/2N); the orthonormal DCT-II is
// F(k) = a(k) sum_x f(x) cos(...), a(0) = sqrt(1/N), a(k) = sqrt(2/N), so F(k) = Y(k) a(k)/2.
// REDFT01 computes X(x) = Z(0) + 2 sum_{k>0} Z(k) cos(...); feeding Z(0) = a(0) F(0),
// Z(k) = a(k) F(k) / 2 gives the orthonormal inverse f(x) = sum_k a(k) F(k) cos(...).
#pragma once

#include <cmath>

namespace dispex::spectral {

// F(k) = Y(k) * ForwardScale(k, n).
inline double ForwardScale(int k, int n) {
  return 0.5 * std::sqrt((k == 0 ? 1.0 : 2.0) / n);
}

// Z(k) = F(k) * InverseScale(k, n).
inline double InverseScale(int k, int n) {
  return k == 0 ? std::sqrt(1.0 / n) : 0.5 * std::sqrt(2.0 / n);
}

}  // namespace dispex::spectral
