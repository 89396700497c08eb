// Vector displacement maps (docs/VECTOR.md): for a sculpt that is the base refined, every
// Ptex face's samples read the sculpt exactly where they lie through the correspondence
// (MatchRefinedSculpt) -- D = sculpt(u, v) - limit(u, v), no rays -- expressed in the map's
// vector space, and stored at the fewest texels that keep the vector error within the
// tolerance (SpectralVectorAnalyzer).
#pragma once

#include "core/system.h"
#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/incremental/previous_map.h"

namespace dispex::extract {

// Steps 2-9 of ExtractShape for ExtractOptions::vector: correspondence, settings (no search
// distance), faces, totals, the map with its vector meta data. Faces whose key (VectorFaceKeys)
// is unchanged in `previous` (a vector map, or null) are copied from it.
StatusOr<ExtractReport> ExtractVectorShape(const ExtractOptions& options, ExtractInputs inputs,
                                           ExtractReport report, const Stopwatch& total_clock,
                                           const PreviousMap* previous);

}  // namespace dispex::extract
