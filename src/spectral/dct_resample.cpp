// In terms of FFTW's unnormalised transforms the resampling factor is the same for every
// coefficient: Y(u,v) / (4 nx ny) fed to REDFT01 at rx x ry, a power of two, so exact.
#include "spectral/dct_resample.h"

#include <algorithm>
#include <cstring>

namespace dispex::spectral {

void ResampleBlock(Dct2d& dct, const float* samples, const float* coefficients,
                   const BlockShape& shape, const BlockShape& res, float mean,
                   AlignedFloats& padded, float* out) {
  if (res.nx == shape.nx && res.ny == shape.ny) {
    std::memcpy(out, samples, shape.count() * sizeof(float));
    return;
  }
  if (res.count() == 1) {  // the DC term alone: the mean
    out[0] = mean;
    return;
  }
  float* z = padded.Reserve(res.count());
  const float scale = 1.0f / (4.0f * static_cast<float>(shape.count()));  // 2^-k: exact
  const int keep_u = std::min(res.nx, shape.nx);
  const int keep_v = std::min(res.ny, shape.ny);
  for (int v = 0; v < keep_v; ++v) {
    const float* src = coefficients + static_cast<std::size_t>(v) * shape.nx;
    float* row = z + static_cast<std::size_t>(v) * res.nx;
    for (int u = 0; u < keep_u; ++u) row[u] = src[u] * scale;
    std::fill(row + keep_u, row + res.nx, 0.0f);
  }
  std::fill(z + static_cast<std::size_t>(keep_v) * res.nx, z + res.count(), 0.0f);
  dct.Inverse(res.lx, res.ly, z, out);
}

}  // namespace dispex::spectral
