// Resampling a block in the DCT domain to a power-of-two texel grid: the kept coefficients,
// scaled, inverted at the new size (SpectralAnalyzer::Resample describes the rule).
#pragma once

#include "spectral/aligned_buffer.h"
#include "spectral/block_shape.h"
#include "spectral/dct2d.h"

namespace dispex::spectral {

// `samples` (shape) with `coefficients` their unnormalised REDFT10 (not read when `res` equals
// `shape` or is 1 x 1, where the samples themselves or `mean` are the texels) into `out`
// (res.count() floats). `padded` is scratch.
void ResampleBlock(Dct2d& dct, const float* samples, const float* coefficients,
                   const BlockShape& shape, const BlockShape& res, float mean,
                   AlignedFloats& padded, float* out);

}  // namespace dispex::spectral
