// The DCT truncation bound E(rx, ry) for every power-of-two pair, from one pass over the
// coefficients, so that choosing a resolution costs O(1) per candidate.
//
// E(rx,ry) = sum over u >= rx or v >= ry of a_x(u) a_y(v) |F(u,v)| bounds how far the series
// truncated to u < rx, v < ry moves any sample (each cosine is at most 1 in magnitude). With
// FFTW's unnormalised coefficients Y = 4 F / (a_x(u) a_y(v)) each term is
// w_x(u) w_y(v) |Y(u,v)| with w_N(0) = 1/(2N), w_N(k > 0) = 1/N.
//
// The weights are constant on the octave bands {0}, [1,2), [2,4), ..., [N/2, N), and a
// power-of-two cut rx = 2^kx keeps exactly the bands 0..kx. So one pass sums |Y| per
// (v band, u band) cell -- at most 10 x 10 cells -- and two prefix/suffix passes over that
// table give every E(2^kx, 2^ky) as a sum of non-negative terms (no cancellation).
#pragma once

#include <algorithm>
#include <array>
#include <utility>

#include "dispex/spectral.h"
#include "spectral/block_shape.h"

namespace dispex::spectral {

// The (kx, ky), kx <= lx, ky <= ly, of fewest texels 2^(kx+ky) with bound(kx, ky) <= tolerance;
// among equals the smaller bound, then the smaller kx; (lx, ly) when none is.
template <class Bound>
std::pair<int, int> SmallestWithin(int lx, int ly, double tolerance, Bound bound) {
  for (int texels_log2 = 0; texels_log2 <= lx + ly; ++texels_log2) {
    int best_kx = -1;
    double best_bound = 0;
    for (int kx = std::max(0, texels_log2 - ly); kx <= std::min(lx, texels_log2); ++kx) {
      const double b = bound(kx, texels_log2 - kx);
      if (b <= tolerance && (best_kx < 0 || b < best_bound)) {
        best_kx = kx;
        best_bound = b;
      }
    }
    if (best_kx >= 0) return {best_kx, texels_log2 - best_kx};
  }
  return {lx, ly};
}

class TruncationBounds {
 public:
  // Reads the shape.nx * shape.ny unnormalised REDFT10 coefficients `raw` (u fastest).
  void Build(const float* raw, const BlockShape& shape);

  // E(2^kx, 2^ky); kx may exceed log2(nx) (nothing dropped in u), likewise ky.
  double Bound(int kx, int ky) const;

  // The (kx, ky) of fewest texels 2^(kx+ky) with Bound <= tolerance; among equals the smaller
  // bound, then the smaller kx. Always exists: the full resolution drops nothing.
  std::pair<int, int> Smallest(double tolerance) const;

 private:
  static constexpr int kBands = kMaxSpectralLog2 + 1;
  int lx_ = 0;
  int ly_ = 0;
  // u_dropped_[kx] = sum of the terms with u band > kx (any v).
  std::array<double, kBands> u_dropped_{};
  // v_dropped_[kx][ky] = sum of the terms with u band <= kx and v band > ky.
  std::array<std::array<double, kBands>, kBands> v_dropped_{};
};

}  // namespace dispex::spectral
