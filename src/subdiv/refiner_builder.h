// Builds OpenSubdiv's Far::TopologyRefiner from a dispex::Mesh and its subdivision tags,
// after checking everything OpenSubdiv would otherwise assert on, crash on or silently
// accept (indices out of range, repeated vertices, crease tags that are not edges, ...).
#pragma once

#include <opensubdiv/far/topologyRefiner.h>

#include <memory>

#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex::subdiv {

// Sharpness at and above which OpenSubdiv treats a crease or corner as infinitely sharp.
inline constexpr float kInfiniteSharpness = 10.0f;

// Checks the cage's arrays and tags. The message names the file and the 0-based element.
Status ValidateCage(const Mesh& cage);

// The largest finite (semi-sharp) crease or corner sharpness among the tags, 0 if none.
float MaxSemiSharpness(const SubdivTags& tags);

// A Catmull-Clark refiner of the cage's base level with its tags (face-varying settings
// ignored). The one place where tags become Sdc::Options (boundary interpolation, crease
// method, triangle subdivision): every surface, patch table and uniform refinement of dispex
// starts from this refiner. Runs ValidateCage first; OpenSubdiv's own rejections become a
// Status too.
StatusOr<std::unique_ptr<OpenSubdiv::Far::TopologyRefiner>> BuildTopologyRefiner(const Mesh& cage);

}  // namespace dispex::subdiv
