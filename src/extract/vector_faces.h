// Vector displacement maps (docs/VECTOR.md): for a sculpt that is the base refined, every
// Ptex face's samples read the sculpt exactly where they lie through the correspondence
// (MatchRefinedSculpt) -- D = sculpt(u, v) - limit(u, v), no rays -- expressed in the map's
// vector space, and stored at the fewest texels that keep the vector error within the
// tolerance (SpectralVectorAnalyzer). What differs from a scalar map is here: the match, what
// a face's samples are and the key they are made from, and D in object space at a face's
// edges; the face loop, the edge rounds, the totals and the write are the scalar map's.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "core/hash128.h"
#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"
#include "extract/face_pipeline.h"
#include "extract/incremental/face_keys.h"

namespace dispex::extract {

// The method of a vector map: the sculpt matched to the base (MatchSculpt, within
// OffsetBound's distance when one is given) into inputs.correspondence, read there directly
// (ExtractMethod::kMapping) or through its vertex displacements (otherwise: inputs.interpolate
// and inputs.grids). Records the match, the method and the search distance (the bound) in the
// report. Fails, saying why, when the sculpt is not the base refined.
Status MatchVectorSculpt(const ExtractOptions& options, ExtractInputs& inputs,
                         ExtractReport& report);

// ProcessFace of a vector map (settings.vector): face `face` at no less than `least_log2`,
// its texels as the map stores them (3 interleaved channels, rounded to the data type).
StatusOr<FaceResult> ProcessVectorFace(PtexFaceId face, const ExtractInputs& inputs,
                                       const ExtractSettings& settings, FaceScratch& w,
                                       std::array<int, 2> least_log2);

// Per Ptex face, what its texels are made from: the settings (SettingsKey) and vector space,
// its limit patch and sub-face, its planned samples, and the positions of its grid of sculpt
// vertices in grid order (a face reads the sculpt only inside its own cells, SculptPointAt);
// interpolated, its field's key instead (ComputeFieldKeys, kept in `cache_folder` when given).
FaceKeys VectorFaceKeys(const ExtractInputs& inputs, const ExtractSettings& settings,
                        const std::string& cache_folder);

// A face of a tangent or parametric map (ulog2 x vlog2 texels, 3 interleaved channels; one
// texel: constant) as D in object space at its texel centres, one array per component: the
// channels turned by the frame at each centre (a constant face's too, as D turns over it), as
// verify measures them.
Status VectorObjectComponents(PtexFaceId face, VectorSpace space, int ulog2, int vlog2,
                              std::span<const float> texels, FaceScratch& w,
                              std::array<std::vector<float>*, 3> out);

}  // namespace dispex::extract
