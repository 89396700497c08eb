// The second stage of an extraction: the automatic settings resolved from the inputs, and
// what every face is asked for.
#pragma once

#include <optional>

#include "dispex/extract.h"
#include "dispex/ptex.h"
#include "dispex/spectral.h"
#include "dispex/trace.h"
#include "extract/extract_inputs.h"
#include "extract/oversampling.h"

namespace dispex::extract {

struct ExtractSettings {
  OversamplingPlan plan;       // samples per side of each Ptex face
  double search_distance = 0;  // as resolved; `query` holds it as a float
  NormalQuery query;           // the rays along +-n
  // The longer second search for samples that missed; its distance is 0 when there is none
  // (the search distance was given).
  NormalQuery retry_query;
  SpectralOptions spectral;  // resolution rule and the resolved tolerance
  HolePolicy holes = HolePolicy::kFill;
  PtexDataType data_type = PtexDataType::kFloat;  // kept texels are rounded to it
  // Watertight edges (kOff unless the rule is kErrorBound), and the largest step MatchEdges
  // lets a shared edge keep: the tolerance.
  WatertightEdges watertight = WatertightEdges::kOff;
  double edge_step_budget = 0;
  // The most samples per side a face may be re-extracted with when its edges need a finer
  // resolution than its planned samples hold (log2; max_oversample).
  int max_samples_log2 = 0;
  bool mapping = false;  // samples traced through the subdivision correspondence
  // With `mapping`: the sculpt's vertex displacements interpolated instead (ExtractInputs).
  bool interpolate = false;
  // A vector map's space: every face reads the sculpt through the correspondence
  // (ExtractInputs::correspondence), 3 channels; none: a scalar map, 1 channel.
  std::optional<VectorSpace> vector;
  int channels() const { return vector ? 3 : 1; }
};

// Tolerance (from the sculpt's median edge length unless given), search distance (estimated
// from a coarse sampling of the limit surface unless given) and its retry, oversampling per
// face. Records them, and the time taken, in the report.
StatusOr<ExtractSettings> ResolveSettings(const ExtractOptions& options,
                                          const ExtractInputs& inputs, ExtractReport& report);

}  // namespace dispex::extract
