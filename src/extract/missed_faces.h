// Faces whose rays all missed the sculpt, once every other face is done: each takes the mean
// of its neighbours' shared-edge means, breadth-first over the adjacency; faces that no face
// with values can reach are written 0 (with a warning).
#pragma once

#include "dispex/extract.h"
#include "dispex/ptex.h"
#include "extract/extract_inputs.h"
#include "extract/process_faces.h"

namespace dispex::extract {

// Fails when no ray of any face hit the sculpt. Completes the filled faces' statistics.
Status FillMissedFaces(const ExtractOptions& options, const ExtractInputs& inputs,
                       ProcessedFaces& faces, PtexWriter& writer, ExtractReport& report);

}  // namespace dispex::extract
