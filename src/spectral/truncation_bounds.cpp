// Octave-band sums of the DCT coefficients: see truncation_bounds.h.
#include "spectral/truncation_bounds.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace dispex::spectral {
namespace {

// sum |x[k]| for k < n, in double, four independent partial sums (a fixed order, so the
// result is deterministic).
double SumAbs(const float* x, int n) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    s0 += std::fabs(static_cast<double>(x[k]));
    s1 += std::fabs(static_cast<double>(x[k + 1]));
    s2 += std::fabs(static_cast<double>(x[k + 2]));
    s3 += std::fabs(static_cast<double>(x[k + 3]));
  }
  for (; k < n; ++k) s0 += std::fabs(static_cast<double>(x[k]));
  return (s0 + s1) + (s2 + s3);
}

int BandOf(int k) {
  return k == 0 ? 0 : std::bit_width(static_cast<unsigned>(k));
}

double BandWeight(int band, int n) {
  return band == 0 ? 0.5 / n : 1.0 / n;
}

}  // namespace

void TruncationBounds::Build(const float* raw, const BlockShape& shape) {
  lx_ = shape.lx;
  ly_ = shape.ly;
  std::array<std::array<double, kBands>, kBands> cell{};  // [v band][u band]
  for (int v = 0; v < shape.ny; ++v) {
    const float* row = raw + static_cast<std::size_t>(v) * shape.nx;
    std::array<double, kBands>& sums = cell[BandOf(v)];
    sums[0] += std::fabs(static_cast<double>(row[0]));
    for (int b = 1; b <= lx_; ++b) {
      const int begin = 1 << (b - 1);
      sums[b] += SumAbs(row + begin, begin);
    }
  }
  for (int bv = 0; bv <= ly_; ++bv) {
    for (int bu = 0; bu <= lx_; ++bu) {
      cell[bv][bu] *= BandWeight(bu, shape.nx) * BandWeight(bv, shape.ny);
    }
  }
  // Column totals over v bands above ky, prefix over u bands; suffix over u bands for u_dropped.
  for (int kx = lx_; kx >= 0; --kx) {
    double above = 0;
    if (kx < lx_) {
      for (int bv = 0; bv <= ly_; ++bv) above += cell[bv][kx + 1];
      above += u_dropped_[kx + 1];
    }
    u_dropped_[kx] = above;
  }
  for (int kx = 0; kx <= lx_; ++kx) {
    double tail = 0;  // sum over v bands > ky of cell[bv][kx]
    for (int ky = ly_; ky >= 0; --ky) {
      v_dropped_[kx][ky] = tail + (kx > 0 ? v_dropped_[kx - 1][ky] : 0.0);
      tail += cell[ky][kx];
    }
  }
}

double TruncationBounds::Bound(int kx, int ky) const {
  kx = std::min(kx, lx_);
  ky = std::min(ky, ly_);
  return u_dropped_[kx] + v_dropped_[kx][ky];
}

std::pair<int, int> TruncationBounds::Smallest(double tolerance) const {
  return SmallestWithin(lx_, ly_, tolerance, [this](int kx, int ky) { return Bound(kx, ky); });
}

}  // namespace dispex::spectral
