// The subdivision correspondence in an extraction (ExtractOptions::method): whether the sculpt
// is the base refined, the automatic search distance without a BVH, and the BVH built
// afterwards for the samples the mapping leaves undecided.
#pragma once

#include <span>

#include "dispex/correspondence.h"
#include "dispex/extract.h"
#include "dispex/status.h"
#include "dispex/trace.h"
#include "extract/coarse_sampling.h"
#include "extract/extract_inputs.h"
#include "extract/process_faces.h"

namespace dispex::extract {

// MatchRefinedSculpt of inputs.sculpt to the base, a sculpt wound the other way accepted: it is
// then reversed in place (ReverseWinding), with a warning in the report, so that everything
// after the match sees it wound as the base is. An incremental run keeps the sculpt's
// adjacency in CacheFolder for the next (MatchOptions::cache_dir).
StatusOr<SculptCorrespondence> MatchSculpt(const ExtractOptions& options, MatchOptions match,
                                           ExtractInputs& inputs, ExtractReport& report);

// ExtractOptions::cache_dir resolved: the folder given, $XDG_CACHE_HOME/dispex, or
// $HOME/.cache/dispex; "" for "off" or when neither variable is set.
std::string CacheFolder(const ExtractOptions& options);

// What a given search distance bounds when the map reads the sculpt through its
// correspondence alone (interpolated or vector maps): how far a sculpt vertex may lie from its
// point on the limit surface (MatchOptions::max_offset); 0, the match's default, when the
// distance is automatic.
StatusOr<double> OffsetBound(const ExtractOptions& options, double base_diagonal);

// Unless the method is kRays, matches the sculpt to the base (MatchSculpt) and on a match sets
// inputs.mapping (no BVH is built up front then) and, under kAuto and kInterpolate,
// inputs.interpolate. Records the method that will run and the match (time, level, offsets,
// or why there is none) in the report. kMapping and kInterpolate fail with the match's
// reason; kAuto then runs rays.
Status ChooseMethod(const ExtractOptions& options, ExtractInputs& inputs, ExtractReport& report);

// The automatic search distance through the mapping: EstimateSearchDistance's rule (1.5 x the
// 99.9th percentile of |t| of rays 0.15 x the base diagonal long, nearest policy) over the
// same coarse samples, each answered through the mapping, and those it cannot decide by a BVH
// of the sculpt their rays can reach (found through the blocks of cells): the ray path's
// estimate. Errors as EstimateSearchDistance's.
StatusOr<SearchDistanceEstimate> EstimateSearchDistanceMapped(const ExtractInputs& inputs,
                                                              const CoarseSampling& coarse,
                                                              double base_diagonal);

// Before Ptex faces `faces` are traced by a BVH (their samples the mapping left undecided): a
// tracer holding the sculpt within reach of them and of the faces the current tracer holds
// (SculptWithinReach with inputs.face_keys), or of the whole sculpt when those are more than
// half the faces or there are no keys. Their hits are those of the whole sculpt's BVH.
Status TraceFallback(ExtractInputs& inputs, std::span<const int> faces);

// The report's tracer, BVH time and fallback counts of an extraction through the mapping.
void ReportMapping(const ExtractInputs& inputs, const ProcessedFaces& faces, ExtractReport& report);

}  // namespace dispex::extract
