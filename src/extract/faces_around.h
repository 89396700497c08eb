// Ptex faces near flagged ones: what a change to a face's texels, or to the sculpt it reads,
// can reach beyond it.
#pragma once

#include <cstdint>
#include <vector>

#include "extract/extract_inputs.h"

namespace dispex::extract {

// The flagged faces and every Ptex face whose base face shares a base vertex with theirs: all
// the faces around the ends of their edges (the cross-face reader's reach at a face's corners,
// and every face whose grid or apron holds a sculpt vertex of a flagged face's grid).
std::vector<std::uint8_t> WithFacesAround(const ExtractInputs& inputs,
                                          std::vector<std::uint8_t> flags);

}  // namespace dispex::extract
