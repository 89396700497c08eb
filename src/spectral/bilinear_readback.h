// What a renderer reads from a face: its texels bilinearly interpolated at the oversampled
// sample positions, clamped to the edge texels at the face border (unchecked kernels; the
// checked forms, BilinearReadBack and MaxBilinearError, are what the tests and benchmarks call).
#pragma once

#include <span>

#include "dispex/status.h"
#include "spectral/block_shape.h"

namespace dispex::spectral {

// out[j * nx + i] = read-back of `texels` (shape `res`) at ((i+0.5)/nx, (j+0.5)/ny).
void ReadBack(const float* texels, const BlockShape& res, const BlockShape& samples_shape,
              float* out);

// max |read-back - sample| over the block, in double. Stops early, returning a value
// > stop_above, once a row ends with the running maximum above `stop_above`; otherwise exact.
double MaxReadBackError(const float* texels, const BlockShape& res, const float* samples,
                        const BlockShape& samples_shape, double stop_above);

// What a renderer reads from a face of 2^ulog2 x 2^vlog2 texels at the nx x ny sample
// positions ((i+0.5)/nx, (j+0.5)/ny): bilinear interpolation between texel centres
// ((k+0.5)/rx, ...), the value of the edge texel beyond the outermost centres (Ptex's clamp
// at a face border). `out` holds nx * ny values. Errors: sizes as for
// SpectralAnalyzer::Analyze, span sizes.
Status BilinearReadBack(std::span<const float> texels, int ulog2, int vlog2, int nx, int ny,
                        std::span<float> out);

// max over samples of |BilinearReadBack(texels)(i,j) - samples(i,j)|, computed in double
// without rounding the read-back to float. Allocation-free. Errors as BilinearReadBack.
StatusOr<double> MaxBilinearError(std::span<const float> texels, int ulog2, int vlog2,
                                  std::span<const float> samples, int nx, int ny);

}  // namespace dispex::spectral
