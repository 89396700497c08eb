// What a renderer reads from a face: its texels bilinearly interpolated at the oversampled
// sample positions, clamped to the edge texels at the face border (unchecked kernels; the
// checked public API is in dispex/spectral.h).
#pragma once

#include "spectral/block_shape.h"

namespace dispex::spectral {

// out[j * nx + i] = read-back of `texels` (shape `res`) at ((i+0.5)/nx, (j+0.5)/ny).
void ReadBack(const float* texels, const BlockShape& res, const BlockShape& samples_shape,
              float* out);

// max |read-back - sample| over the block, in double. Stops early, returning a value
// > stop_above, once a row ends with the running maximum above `stop_above`; otherwise exact.
double MaxReadBackError(const float* texels, const BlockShape& res, const float* samples,
                        const BlockShape& samples_shape, double stop_above);

}  // namespace dispex::spectral
