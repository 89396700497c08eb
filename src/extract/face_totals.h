// The report's totals over all faces, summed in face order so that they do not depend on
// scheduling, and the check that not too many samples missed.
#pragma once

#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"
#include "extract/process_faces.h"

namespace dispex::extract {

// Fails when more than options.max_miss_fraction of the samples missed, or when the tracer
// reported an error.
Status AddFaceTotals(const ExtractOptions& options, const ExtractInputs& inputs,
                     const ExtractSettings& settings, const ProcessedFaces& faces,
                     ExtractReport& report);

}  // namespace dispex::extract
