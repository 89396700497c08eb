// The watertight-edges stage of an extraction (docs/ACCURACY.md, "Watertight edges"): once
// every face has its texels, the steps where faces meet are measured under the readers
// renderers use, and faces are re-extracted at a higher resolution until every shared edge
// meets within the tolerance, or raising no longer helps.
#pragma once

#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"
#include "extract/process_faces.h"

namespace dispex::extract {

// In rounds: measure every shared edge (MeasurePtexEdgeSteps); for each edge over
// settings.edge_step_budget, raise the resolution that causes it -- through the cross-face
// filter the coarser side (along the edge first, then across), for per-face reading
// (WatertightEdges::kAll) both sides across the edge -- and run ProcessFace again for the
// raised faces (round by round, measuring again only the edges of the faces raised). An edge
// whose step twice fell by less than a quarter after a raise, or whose faces are at their
// finest sampling (settings.max_samples_log2), is left as it is and counted. Edges on
// infinitely sharp creases and beside faces whose data may jump (ListDiscontinuousFaces) are
// not held. Fills the report's edge fields but the discontinuous ones. Deterministic:
// decisions depend only on the texels.
Status MatchEdges(ExtractInputs& inputs, const ExtractSettings& settings, ProcessedFaces& faces,
                  ExtractReport& report);

// Faces whose displacement may jump (samples filled over holes of the sculpt, other-sheet hits,
// no hit at all) into report.discontinuous_faces, and the edges beside them into
// report.edges_discontinuous, whether or not edges are made watertight.
void ListDiscontinuousFaces(const ExtractInputs& inputs, const ProcessedFaces& faces,
                            ExtractReport& report);

}  // namespace dispex::extract
