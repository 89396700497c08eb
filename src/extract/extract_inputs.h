// The first stage of an extraction: everything read or built from the input files before
// any setting is resolved.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"

namespace dispex::extract {

struct ExtractInputs {
  Mesh base;
  Mesh sculpt;
  LimitSurface surface;             // of the base
  std::vector<PtexFaceInfo> faces;  // the map's face table, from `surface`
  std::unique_ptr<Tracer> tracer;   // the sculpt's BVH; reads the sculpt's arrays
};

// Reads the sculpt while the base is read and its limit surface built, fingerprints both
// meshes (MeshContentKey), and checks the estimated memory against `memory_limit` (bytes; 0:
// no check) before reading and again once the sculpt's size is known. Fills the report's
// input counts, fingerprints, timings and warnings. The tracer is left to BuildTracer.
StatusOr<ExtractInputs> ReadInputs(const ExtractOptions& options, std::uint64_t memory_limit,
                                   ExtractReport& report);

// The same from meshes already read (the shapes of an asset): fingerprints, limit surface,
// counts, memory check. Read times stay 0.
StatusOr<ExtractInputs> InputsFromMeshes(const ExtractOptions& options, Mesh base, Mesh sculpt,
                                         std::uint64_t memory_limit, ExtractReport& report);

// The sculpt's BVH.
Status BuildTracer(const ExtractOptions& options, ExtractInputs& inputs, ExtractReport& report);

}  // namespace dispex::extract
