// Bilinear read-back of a Ptex face at its oversampled sample positions.
//
// Follows Ptex's bilinear lookup within one face: texel k of r sits at (k+0.5)/r; a position x
// reads texel coordinate t = x r - 0.5, blends texels floor(t) and floor(t)+1 by the fraction,
// and beyond the outermost centres (t < 0 or t > r-1) reads the edge texel (dispex does not
// blend across face borders here). With r and n powers of two, t is exact in double.
#include "spectral/bilinear_readback.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "dispex/spectral.h"

namespace dispex::spectral {
namespace {

// Per output position: the two texels read and the weight of the second.
struct Taps {
  int first[kMaxSpectralSize];
  int second[kMaxSpectralSize];
  double weight[kMaxSpectralSize];

  Taps(int texels, int positions) {
    const double scale = static_cast<double>(texels) / positions;
    for (int i = 0; i < positions; ++i) {
      const double t = (i + 0.5) * scale - 0.5;
      if (t <= 0.0) {
        first[i] = second[i] = 0;
        weight[i] = 0.0;
      } else if (t >= texels - 1) {
        first[i] = second[i] = texels - 1;
        weight[i] = 0.0;
      } else {
        const double base = std::floor(t);
        first[i] = static_cast<int>(base);
        second[i] = first[i] + 1;
        weight[i] = t - base;
      }
    }
  }
};

// Texel rows interpolated along u to the sample positions, two at a time: the read-back of
// sample row j blends expanded texel rows ty.first[j] and ty.second[j], so each texel row is
// expanded once and the inner loops run over contiguous arrays.
class ExpandedRows {
 public:
  ExpandedRows(const float* texels, const BlockShape& res, int positions)
      : texels_(texels), res_(res), positions_(positions), tx_(res.nx, positions) {}

  // Makes rows r0 and r1 available as first() and second().
  void Load(int r0, int r1) {
    if (r0 != tag_a_) {
      if (r0 == tag_b_) {
        std::swap(a_, b_);
        std::swap(tag_a_, tag_b_);
      } else {
        Expand(r0, a_);
        tag_a_ = r0;
      }
    }
    if (r1 != tag_b_) {
      Expand(r1, b_);
      tag_b_ = r1;
    }
  }
  const double* first() const { return a_; }
  const double* second() const { return b_; }

 private:
  void Expand(int r, double* out) const {
    const float* row = texels_ + static_cast<std::size_t>(r) * res_.nx;
    if (res_.nx == positions_) {  // one texel per position: weights are all 0
      for (int i = 0; i < positions_; ++i) out[i] = row[i];
      return;
    }
    for (int i = 0; i < positions_; ++i) {
      const double w = tx_.weight[i];
      out[i] = (1.0 - w) * row[tx_.first[i]] + w * row[tx_.second[i]];
    }
  }

  const float* texels_;
  BlockShape res_;
  int positions_;
  Taps tx_;
  double storage_[2][kMaxSpectralSize];
  double* a_ = storage_[0];
  double* b_ = storage_[1];
  int tag_a_ = -1;
  int tag_b_ = -1;
};

}  // namespace

void ReadBack(const float* texels, const BlockShape& res, const BlockShape& samples_shape,
              float* out) {
  ExpandedRows rows(texels, res, samples_shape.nx);
  const Taps ty(res.ny, samples_shape.ny);
  for (int j = 0; j < samples_shape.ny; ++j) {
    rows.Load(ty.first[j], ty.second[j]);
    const double* a = rows.first();
    const double* b = rows.second();
    const double w = ty.weight[j];
    float* dst = out + static_cast<std::size_t>(j) * samples_shape.nx;
    for (int i = 0; i < samples_shape.nx; ++i) {
      dst[i] = static_cast<float>((1.0 - w) * a[i] + w * b[i]);
    }
  }
}

double MaxReadBackError(const float* texels, const BlockShape& res, const float* samples,
                        const BlockShape& samples_shape, double stop_above) {
  ExpandedRows rows(texels, res, samples_shape.nx);
  const Taps ty(res.ny, samples_shape.ny);
  const int nx = samples_shape.nx;
  double max_error = 0.0;
  for (int j = 0; j < samples_shape.ny; ++j) {
    rows.Load(ty.first[j], ty.second[j]);
    const double* a = rows.first();
    const double* b = rows.second();
    const double w = ty.weight[j];
    const double w1 = 1.0 - w;
    const float* s = samples + static_cast<std::size_t>(j) * nx;
    // Errors first (a loop the compiler vectorises), then their maximum in four independent
    // lanes (not bound by the latency of one max chain).
    double error[kMaxSpectralSize];
    for (int i = 0; i < nx; ++i) error[i] = std::fabs(w1 * a[i] + w * b[i] - s[i]);
    double m[4] = {max_error, 0.0, 0.0, 0.0};
    int i = 0;
    for (; i + 4 <= nx; i += 4) {
      for (int l = 0; l < 4; ++l) m[l] = error[i + l] > m[l] ? error[i + l] : m[l];
    }
    for (; i < nx; ++i) m[0] = error[i] > m[0] ? error[i] : m[0];
    max_error = std::max(std::max(m[0], m[1]), std::max(m[2], m[3]));
    if (max_error > stop_above) break;
  }
  return max_error;
}

Status BilinearReadBack(std::span<const float> texels, int ulog2, int vlog2, int nx, int ny,
                        std::span<float> out) {
  DISPEX_ASSIGN_OR_RETURN(const spectral::BlockShape res, spectral::MakeTexelShape(ulog2, vlog2));
  DISPEX_ASSIGN_OR_RETURN(const spectral::BlockShape shape, spectral::MakeBlockShape(nx, ny));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(texels.size(), res, "texels"));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(out.size(), shape, "read-back output"));
  spectral::ReadBack(texels.data(), res, shape, out.data());
  return Status::Ok();
}

StatusOr<double> MaxBilinearError(std::span<const float> texels, int ulog2, int vlog2,
                                  std::span<const float> samples, int nx, int ny) {
  DISPEX_ASSIGN_OR_RETURN(const spectral::BlockShape res, spectral::MakeTexelShape(ulog2, vlog2));
  DISPEX_ASSIGN_OR_RETURN(const spectral::BlockShape shape, spectral::MakeBlockShape(nx, ny));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(texels.size(), res, "texels"));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(samples.size(), shape, "samples"));
  return spectral::MaxReadBackError(texels.data(), res, samples.data(), shape,
                                    std::numeric_limits<double>::infinity());
}

}  // namespace dispex::spectral
