// What the per-face reader shows at a face's border: along each of the four edges, the
// outermost texel row or column interpolated along the edge (the reader clamps there), against
// the displacement on the edge itself, estimated by linear extrapolation from the two
// outermost sample rows (exact for data linear across the edge; its error is second order in
// the sample spacing).
#pragma once

#include "spectral/block_shape.h"

namespace dispex::spectral {

// max over the edges' sample positions and the four corners of |edge read - extrapolated
// edge value|, in double.
double MaxEdgeReadError(const float* texels, const BlockShape& res, const float* samples,
                        const BlockShape& samples_shape);

}  // namespace dispex::spectral
