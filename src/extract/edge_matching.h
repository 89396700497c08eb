// The watertight-edges stage of an extraction (docs/ACCURACY.md, "Watertight edges"): once
// every face has its texels, the steps where faces meet are measured under the readers
// renderers use, and faces are re-extracted at a higher resolution until every shared edge
// meets within the tolerance, or raising no longer helps.
#pragma once

#include <array>
#include <functional>
#include <span>
#include <vector>

#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"
#include "extract/process_faces.h"

namespace dispex::extract {

// The map as the rounds of RaiseEdgeResolutions measure it.
struct EdgeRoundsMap {
  std::vector<PtexFaceInfo> faces;  // with the resolutions as they stand
  // Per component (one for a scalar map; x, y, z of D for a vector map), per face, its level-0
  // texels as PtexMapSampler takes them (one value for a constant face).
  std::vector<std::vector<std::vector<float>>> components;
  std::vector<std::uint8_t> skip_faces;  // holes, and faces whose data may jump
};

// Extracts `faces` again at no less than their least resolutions (log2 per side) and brings
// the map up to date for them.
using RedoFaces =
    std::function<Status(std::span<const int> faces, std::span<const std::array<int, 2>> least_log2,
                         EdgeRoundsMap& map)>;
// Brings into the map the texels of the flagged faces (one flag per face) where it does not
// hold them yet: a map may hold only those a measurement reads.
using LoadFaces = std::function<Status(std::span<const std::uint8_t> faces)>;

// What the first round may take from the run before (PtexEdgeMeasure::known and changed):
// per face its edges' first-round steps then (empty: none), and the faces whose edges may step
// otherwise now.
struct FirstRoundBefore {
  std::span<const double> steps;
  std::vector<std::uint8_t> changed;
};

// In rounds: measure every shared edge (MeasurePtexVectorEdgeSteps: a vector map's step is the
// length of the step of D); for each edge over settings.edge_step_budget, raise the resolution
// that causes it -- through the cross-face filter the coarser side (along the edge first, then
// across), for per-face reading (WatertightEdges::kAll) both sides across the edge -- and
// redo the raised faces (round by round, measuring again only the edges of the faces raised).
// An edge whose step twice fell by less than a quarter after a raise, or whose faces are at
// their finest sampling (settings.max_samples_log2), is left as it is and counted. Edges on
// infinitely sharp creases and faces in map.skip_faces are not held. Fills the report's edge
// fields but texels_before_edges and the discontinuous ones. Deterministic: decisions depend
// only on the texels. The first round takes the steps of the edges `before` holds for it
// instead of measuring them; `first_round` gets that round's steps (PtexEdgeStepsByFace).
// Before each measurement, `load` is given the faces it reads.
Status RaiseEdgeResolutions(const ExtractInputs& inputs, const ExtractSettings& settings,
                            EdgeRoundsMap& map, const FirstRoundBefore& before,
                            const LoadFaces& load, const RedoFaces& redo,
                            std::vector<double>& first_round, ExtractReport& report);

// RaiseEdgeResolutions for the kept faces (ProcessFaces), raised faces run again by
// ReprocessFaces. A vector map's edges are measured on D in object space (its channels, or
// VectorObjectComponents for tangent and parametric maps); faces whose data may jump
// (ListDiscontinuousFaces) are not held. Faces copied from the previous map are read from it
// only where a measurement reads them; the edges among faces whose first pass is the previous
// map's (same key), away from the faces that changed, take the steps that map recorded
// (PreviousMap::FirstRoundEdgeSteps). faces.first_round_edge_steps gets the first round's.
Status MatchEdges(ExtractInputs& inputs, const ExtractSettings& settings, ProcessedFaces& faces,
                  ExtractReport& report);

// Faces whose displacement may jump (samples filled over holes of the sculpt, other-sheet hits,
// no hit at all) into report.discontinuous_faces, and the edges beside them into
// report.edges_discontinuous, whether or not edges are made watertight.
void ListDiscontinuousFaces(const ExtractInputs& inputs, const ProcessedFaces& faces,
                            ExtractReport& report);

}  // namespace dispex::extract
