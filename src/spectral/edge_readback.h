// What the per-face reader shows at a face's border: along each of the four edges, the
// outermost texel row or column interpolated along the edge (the reader clamps there), against
// the displacement on the edge itself, estimated by linear extrapolation from the two
// outermost sample rows (exact for data linear across the edge; its error is second order in
// the sample spacing).
#pragma once

#include <cstddef>

#include "spectral/block_shape.h"

namespace dispex::spectral {

// max over the edges' sample positions and the four corners of |edge read - extrapolated
// edge value|, in double.
double MaxEdgeReadError(const float* texels, const BlockShape& res, const float* samples,
                        const BlockShape& samples_shape);

// The same reads for one channel of a vector: adds each position's squared error to
// squares[k], k < EdgeReadCount(samples_shape), so that the channels' sums give the vector
// error at each position.
std::size_t EdgeReadCount(const BlockShape& samples_shape);
void AddSquaredEdgeReadErrors(const float* texels, const BlockShape& res, const float* samples,
                              const BlockShape& samples_shape, double* squares);

// Makes the outermost texels hold the displacement on the face's edges rather than at their
// own centres, half a texel inside: where 2 or more texels but fewer than the samples run
// across an edge, the outermost row (column) gets the extrapolated edge values box-averaged
// over each texel's span of samples, and where both do, the corner texels the values at the
// corners (extrapolated both ways). At the samples' own resolution nothing changes (the
// texels are the samples, which read back exactly). Readers then meet the
// neighbour's values on the edge itself, per face and through the cross-face filter, and
// the read-back check sees what this costs inside the face. Requires res <= samples_shape.
void PinEdgeTexels(float* texels, const BlockShape& res, const float* samples,
                   const BlockShape& samples_shape);

}  // namespace dispex::spectral
