// The steps of a Ptex map at shared face edges (edge_steps.cpp), for Verify (verify.cpp).
#pragma once

#include <optional>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"

namespace dispex::verify {

// The map's steps at shared face edges into `r`, with the bounds on them (options.tolerance or
// the map's own); `space` as the map holds (nullopt: scalar). `faces` gets the map's face table
// on the base's limit surface and `fields` its level-0 values per field and face (a scalar
// map's are read across faces from them, MapReader::TruthScalar).
Status MeasureEdgeSteps(const VerifyOptions& options, const Mesh& base, const LimitSurface& surface,
                        const PtexFile& map, std::optional<VectorSpace> space,
                        std::vector<PtexFaceInfo>& faces,
                        std::vector<std::vector<std::vector<float>>>& fields, VerifyReport& r);

// The edge-step bounds (max_edge_step, max_edge_step_p99) on both readers: the first one
// failed, with its worst edge, is the report's failure.
void EdgeThresholds(VerifyReport& r, const VerifyOptions& options);

}  // namespace dispex::verify
