// "Highest non-zero frequency, times two": the per-face resolution rule of the published DCT
// approach, read literally on the DCT index with an explicit threshold for "non-zero".
#include "spectral/nonzero_rule.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "dispex/spectral.h"
#include "spectral/dct_scale.h"

namespace dispex::spectral {
namespace {

int Log2ForHighest(int highest, int max_log2) {
  const unsigned texels = std::bit_ceil(static_cast<unsigned>(std::max(1, 2 * highest)));
  return std::min(std::countr_zero(texels), max_log2);
}

}  // namespace

std::pair<int, int> NonzeroRuleResolution(const float* raw, const BlockShape& shape,
                                          double threshold) {
  double sx[kMaxSpectralSize];
  for (int u = 0; u < shape.nx; ++u) sx[u] = ForwardScale(u, shape.nx);
  int u_max = 0;
  int v_max = 0;
  for (int v = 0; v < shape.ny; ++v) {
    const double sy = ForwardScale(v, shape.ny);
    const float* row = raw + static_cast<std::size_t>(v) * shape.nx;
    for (int u = 0; u < shape.nx; ++u) {
      if (std::fabs(static_cast<double>(row[u])) * sx[u] * sy > threshold) {
        u_max = std::max(u_max, u);
        v_max = v;
      }
    }
  }
  return {Log2ForHighest(u_max, shape.lx), Log2ForHighest(v_max, shape.ly)};
}

}  // namespace dispex::spectral
