#include "extract/process_faces.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/progress.h"
#include "core/system.h"
#include "extract/parallel_errors.h"

namespace dispex {

namespace {

PtexFaceInfo FaceInfo(const ExtractInputs& inputs, PtexFaceId face, int ulog2, int vlog2) {
  PtexFaceInfo info = inputs.faces[static_cast<std::size_t>(face.value)];
  info.ulog2 = static_cast<std::int8_t>(ulog2);
  info.vlog2 = static_cast<std::int8_t>(vlog2);
  return info;
}

// A face that missed entirely is written later, once its neighbours are known.
Status WriteFace(PtexWriter& writer, const ExtractInputs& inputs, PtexFaceId face,
                 const FaceResult& result) {
  switch (result.kind) {
    case FaceResult::Kind::kHole: return WriteConstantFace(writer, inputs, face, 0.0f);
    case FaceResult::Kind::kAllMissed: return Status::Ok();
    case FaceResult::Kind::kAnalysed: break;
  }
  const SpectralFace& analysed = result.analysed;
  const PtexFaceInfo info = FaceInfo(inputs, face, analysed.ulog2, analysed.vlog2);
  return analysed.constant ? writer.SetConstantFace(face, info, {&analysed.constant_value, 1})
                           : writer.SetFace(face, info, analysed.texels);
}

WorkerTotals SumWorkers(const tbb::enumerable_thread_specific<FaceScratch>& scratches) {
  WorkerTotals totals;
  for (const FaceScratch& w : scratches) {
    totals.rays_cast += w.counters.rays_cast;
    totals.cpu_limit += w.cpu_limit;
    totals.cpu_trace += w.cpu_trace;
    totals.cpu_spectral += w.cpu_spectral;
    totals.cpu_write += w.cpu_write;
    totals.fallback_normals += w.evaluator.stats().fallback_normals;
  }
  return totals;
}

}  // namespace

Status WriteConstantFace(PtexWriter& writer, const ExtractInputs& inputs, PtexFaceId face,
                         float value) {
  return writer.SetConstantFace(face, FaceInfo(inputs, face, 0, 0), {&value, 1});
}

StatusOr<ProcessedFaces> ProcessFaces(const ExtractInputs& inputs, const ExtractSettings& settings,
                                      bool progress, PtexWriter& writer) {
  const int num_faces = inputs.surface.num_ptex_faces();
  ProcessedFaces out;
  out.stats.resize(static_cast<std::size_t>(num_faces));
  out.edge_means.resize(static_cast<std::size_t>(num_faces));
  tbb::enumerable_thread_specific<FaceScratch> scratches(
      [&] { return FaceScratch(inputs.surface); });
  FirstError error;
  Progress bar("extract", static_cast<std::uint64_t>(num_faces), "faces", progress);

  auto process = [&](PtexFaceId face, FaceScratch& w) -> Status {
    DISPEX_ASSIGN_OR_RETURN(FaceResult result, ProcessFace(face, inputs, settings, w));
    ThreadCpuStopwatch step;
    Status written = WriteFace(writer, inputs, face, result);
    if (result.kind == FaceResult::Kind::kAnalysed) w.cpu_write += step.seconds();
    out.stats[static_cast<std::size_t>(face.value)] = result.stats;
    out.edge_means[static_cast<std::size_t>(face.value)] = result.edge_means;
    return written;
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, num_faces, 1), [&](const tbb::blocked_range<int>& range) {
    FaceScratch& w = scratches.local();
    for (int f = range.begin(); f != range.end(); ++f) {
      if (error.failed()) return;
      if (CancelRequested()) return error.Record(-1, Cancelled());
      Status s = process(PtexFaceId(f), w);
      if (!s.ok()) return error.Record(f, s);
      bar.Advance();
    }
  });
  bar.Finish();
  if (error.failed()) return error.status();
  out.workers = SumWorkers(scratches);
  return out;
}

}  // namespace dispex
