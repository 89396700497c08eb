// The map's face table, taken from the limit surface: OpenSubdiv's Ptex numbering and
// adjacency are the one source of both, so the file's faces are the faces that were sampled.
#pragma once

#include <vector>

#include "dispex/ptex.h"
#include "dispex/subdiv.h"

namespace dispex::extract {

// One PtexFaceInfo per Ptex face: neighbours and shared edges as Far::PtexIndices gives them
// (-1 / 0 where there is none), `subface` for the quads an n-gon is split into, resolution 1x1
// (each face's own is set when it is written).
std::vector<PtexFaceInfo> PtexFaceTable(const LimitSurface& surface);

}  // namespace dispex::extract
