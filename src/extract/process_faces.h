// The per-face stage of an extraction: ProcessFace for every Ptex face in parallel, each face
// written to the map as soon as it is done, so its buffers live only while it is processed.
#pragma once

#include <cstdint>
#include <vector>

#include "dispex/ptex.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"
#include "extract/face_pipeline.h"

namespace dispex {

// The worker threads' counters, summed.
struct WorkerTotals {
  std::uint64_t rays_cast = 0;
  std::int64_t fallback_normals = 0;
  double cpu_limit = 0, cpu_trace = 0, cpu_spectral = 0, cpu_write = 0;
};

struct ProcessedFaces {
  std::vector<FaceStats> stats;          // per Ptex face
  std::vector<EdgeMeans> edge_means;     // per Ptex face
  WorkerTotals workers;
};

// On an error, the error of the lowest face id (whatever the scheduling), or the cancellation.
StatusOr<ProcessedFaces> ProcessFaces(const ExtractInputs& inputs, const ExtractSettings& settings,
                                      bool progress, PtexWriter& writer);

// Writes a constant face with the face table's adjacency.
Status WriteConstantFace(PtexWriter& writer, const ExtractInputs& inputs, PtexFaceId face,
                         float value);

}  // namespace dispex
