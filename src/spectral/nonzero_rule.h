// The published resolution rule, kept for comparison: "the highest non-zero frequency, times
// two" (see ResolutionRule::kNonzero in dispex/spectral.h for the exact definition).
#pragma once

#include <utility>

#include "spectral/block_shape.h"

namespace dispex::spectral {

// (ulog2, vlog2) from the unnormalised REDFT10 coefficients `raw` of a `shape` block: the
// smallest power of two >= 2 * (highest index with |orthonormal F| > threshold), clamped to
// 1..n, per direction.
std::pair<int, int> NonzeroRuleResolution(const float* raw, const BlockShape& shape,
                                          double threshold);

}  // namespace dispex::spectral
