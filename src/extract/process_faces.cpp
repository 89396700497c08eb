#include "extract/process_faces.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "core/progress.h"
#include "core/system.h"
#include "extract/incremental/previous_map.h"
#include "extract/mapping/extract_mapping.h"
#include "extract/parallel_errors.h"

namespace dispex::extract {

namespace {

constexpr std::array<float, 3> kZeros{};

// A face of `texels` (one texel: constant) at 2^ulog2 x 2^vlog2.
Status WriteTexels(PtexWriter& writer, const ExtractInputs& inputs, PtexFaceId face, int ulog2,
                   int vlog2, std::span<const float> texels) {
  const PtexFaceInfo info = FaceInfo(inputs, face, ulog2, vlog2);
  return ulog2 == 0 && vlog2 == 0 ? writer.SetConstantFace(face, info, texels)
                                  : writer.SetFace(face, info, texels);
}

// A face that missed entirely is written later, once its neighbours are known.
Status WriteFace(PtexWriter& writer, const ExtractInputs& inputs, PtexFaceId face,
                 const FaceResult& result, int channels) {
  switch (result.kind) {
    case FaceResult::Kind::kHole:
      return WriteTexels(writer, inputs, face, 0, 0,
                         std::span(kZeros).first(static_cast<std::size_t>(channels)));
    case FaceResult::Kind::kAllMissed:
      return Status::Ok();
    case FaceResult::Kind::kAnalysed:
      break;
  }
  return WriteTexels(writer, inputs, face, result.ulog2, result.vlog2, result.texels);
}

void AddCpuTimes(const tbb::enumerable_thread_specific<FaceScratch>& scratches,
                 WorkerTotals& totals) {
  for (const FaceScratch& w : scratches) {
    totals.cpu_limit += w.cpu_limit;
    totals.cpu_trace += w.cpu_trace;
    totals.cpu_spectral += w.cpu_spectral;
    totals.cpu_write += w.cpu_write;
  }
}

// Kept texels hold what the map will store, so that the edges are measured on it and a face
// read back from the map is kept exactly as it was.
KeptFace Keep(const FaceResult& result, PtexDataType type, int channels) {
  KeptFace kept;
  switch (result.kind) {
    case FaceResult::Kind::kAllMissed:
      return kept;
    case FaceResult::Kind::kHole:
      kept.texels.assign(static_cast<std::size_t>(channels), 0.0f);
      break;
    case FaceResult::Kind::kAnalysed:
      kept.ulog2 = static_cast<std::int8_t>(result.ulog2);
      kept.vlog2 = static_cast<std::int8_t>(result.vlog2);
      kept.texels.assign(result.texels.begin(), result.texels.end());
      RoundToDataType(type, kept.texels);
      break;
  }
  kept.kept = true;
  return kept;
}

// A tracer for the faces that asked for one (FaceResult::needs_tracer): through the mapping, for
// the samples it left undecided; through rays, of the retry search's reach.
Status TraceWaiting(ExtractInputs& inputs, std::span<const int> faces) {
  if (inputs.mapping == nullptr) return WidenToRetryReach(inputs);
  return TraceFallback(inputs, faces);
}

}  // namespace

void RoundToDataType(PtexDataType type, std::span<float> texels) {
  if (type != PtexDataType::kHalf) return;
  for (float& t : texels) t = HalfToFloat(FloatToHalf(t));
}

// Face `face` as the previous map stores it, its bytes as they are (PreviousMap::EncodedAs).
Status WriteEncoded(PtexWriter& writer, const ExtractInputs& inputs, const PreviousMap& previous,
                    PtexFaceId face) {
  thread_local PtexEncodedFace encoded;
  DISPEX_RETURN_IF_ERROR(previous.ReadEncoded(static_cast<std::size_t>(face.value), encoded));
  return writer.SetEncodedFace(face, FaceInfo(inputs, face, encoded.ulog2, encoded.vlog2), encoded);
}

// A face copied from the previous map as that map holds it: still encoded where it is encoded as
// `encoding`, else its texels read and encoded again.
Status WriteCopied(PtexWriter& writer, const ExtractInputs& inputs, const PreviousMap& previous,
                   PtexFaceId face, const std::string& encoding) {
  const auto f = static_cast<std::size_t>(face.value);
  if (previous.EncodedAs(f, encoding)) return WriteEncoded(writer, inputs, previous, face);
  KeptFace kept;
  DISPEX_RETURN_IF_ERROR(previous.ReadTexels(f, kept));
  return WriteTexels(writer, inputs, face, kept.ulog2, kept.vlog2, kept.texels);
}

PtexFaceInfo FaceInfo(const ExtractInputs& inputs, PtexFaceId face, int ulog2, int vlog2) {
  PtexFaceInfo info = inputs.faces[static_cast<std::size_t>(face.value)];
  info.ulog2 = static_cast<std::int8_t>(ulog2);
  info.vlog2 = static_cast<std::int8_t>(vlog2);
  return info;
}

Status WriteConstantFace(PtexWriter& writer, const ExtractInputs& inputs, PtexFaceId face,
                         float value) {
  return writer.SetConstantFace(face, FaceInfo(inputs, face, 0, 0), {&value, 1});
}

StatusOr<ProcessedFaces> ProcessFaces(ExtractInputs& inputs, const ExtractSettings& settings,
                                      const PreviousMap* previous,
                                      std::span<const FaceSource> sources, bool progress,
                                      ProgressCounter* counter, PtexWriter& writer) {
  const int num_faces = inputs.surface.num_ptex_faces();
  const bool keep = settings.watertight != WatertightEdges::kOff;
  const int channels = settings.channels();
  ProcessedFaces out;
  out.channels = channels;
  out.stats.resize(static_cast<std::size_t>(num_faces));
  out.edge_means.resize(static_cast<std::size_t>(num_faces));
  if (keep) out.kept.resize(static_cast<std::size_t>(num_faces));
  std::vector<std::uint8_t>& copied = out.copied;
  copied.assign(static_cast<std::size_t>(num_faces), 0);
  std::vector<std::uint8_t> deferred(static_cast<std::size_t>(num_faces), 0);
  std::vector<std::int32_t> fallback(static_cast<std::size_t>(num_faces), 0);
  tbb::enumerable_thread_specific<FaceScratch> scratches(
      [&] { return FaceScratch(inputs.surface); });
  Progress bar("extract", static_cast<std::uint64_t>(num_faces), "faces", progress, counter);

  // The face's first pass as the previous map holds it: still encoded when the map's faces are
  // encoded as this one's and nothing needs its texels.
  const std::string encoding = PtexEncodingName(writer.options());
  if (previous != nullptr && previous->usable()) out.previous = previous;
  auto copy = [&](PtexFaceId face) -> Status {
    const auto f = static_cast<std::size_t>(face.value);
    const FaceRecord& record = previous->record(f);
    out.stats[f] = record.stats;
    out.edge_means[f] = record.edge_means;
    copied[f] = 1;
    if (record.stats.all_missed) return Status::Ok();
    if (keep) {
      previous->KeepUnread(f, out.kept[f]);
      return Status::Ok();
    }
    return WriteCopied(writer, inputs, *previous, face, encoding);
  };
  auto process = [&](PtexFaceId face, FaceScratch& w) -> Status {
    const auto f = static_cast<std::size_t>(face.value);
    if (sources[f] == FaceSource::kElsewhere) return Status::Ok();
    if (sources[f] == FaceSource::kCopy) return copy(face);
    DISPEX_ASSIGN_OR_RETURN(FaceResult result, ProcessFace(face, inputs, settings, w));
    if (result.needs_tracer) {
      deferred[f] = 1;
      return Status::Ok();
    }
    fallback[f] = result.fallback_samples;
    out.stats[f] = result.stats;
    out.edge_means[f] = result.edge_means;
    if (keep) {
      out.kept[f] = Keep(result, settings.data_type, channels);
      return Status::Ok();
    }
    ThreadCpuStopwatch step;
    Status written = WriteFace(writer, inputs, face, result, channels);
    if (result.kind == FaceResult::Kind::kAnalysed) w.cpu_write += step.seconds();
    return written;
  };
  // The faces that trace, in runs when the sculpt is in parts (ForEachTracedRun), after the rest.
  std::vector<int> traced, untraced;
  for (int f = 0; f < num_faces; ++f) {
    (sources[static_cast<std::size_t>(f)] == FaceSource::kRun ? traced : untraced).push_back(f);
  }
  auto each = [&](std::span<const int> faces) {
    return ForEachFace(
        static_cast<int>(faces.size()), [&](int k) { return faces[static_cast<std::size_t>(k)]; },
        scratches, &bar, process);
  };
  Status status = each(untraced);
  if (status.ok()) status = ForEachTracedRun(inputs, traced, each);
  std::vector<int> waiting;
  for (int f = 0; f < num_faces; ++f) {
    if (deferred[static_cast<std::size_t>(f)]) waiting.push_back(f);
  }
  if (status.ok() && !waiting.empty()) {
    status = TraceWaiting(inputs, waiting);
    std::fill(deferred.begin(), deferred.end(), 0);
    if (status.ok()) {
      status = ForEachFace(
          static_cast<int>(waiting.size()),
          [&](int k) { return waiting[static_cast<std::size_t>(k)]; }, scratches, nullptr, process);
    }
    if (status.ok() && std::count(deferred.begin(), deferred.end(), 1) > 0) {
      status = Status::Error("internal: a face the fallback tracer holds asked for a tracer");
    }
  }
  bar.Finish();
  DISPEX_RETURN_IF_ERROR(status);
  AddCpuTimes(scratches, out.workers);
  for (std::size_t f = 0; f < out.stats.size(); ++f) {
    out.workers.rays_cast += static_cast<std::uint64_t>(out.stats[f].rays);
    out.workers.fallback_normals += out.stats[f].fallback_normals;
    out.faces_copied += copied[f];
    out.fallback_samples += fallback[f];
    out.fallback_faces += fallback[f] > 0;
  }
  out.first_pass = out.stats;
  return out;
}

Status ReprocessFaces(ExtractInputs& inputs, const ExtractSettings& settings,
                      std::span<const int> faces, std::span<const std::array<int, 2>> least_log2,
                      ProcessedFaces& processed) {
  tbb::enumerable_thread_specific<FaceScratch> scratches(
      [&] { return FaceScratch(inputs.surface); });
  const auto num_faces = static_cast<std::size_t>(inputs.surface.num_ptex_faces());
  std::vector<std::uint8_t> deferred(num_faces, 0);
  std::vector<std::int32_t> fallback(num_faces, 0);
  auto process = [&](PtexFaceId face, FaceScratch& w) -> Status {
    const auto f = static_cast<std::size_t>(face.value);
    DISPEX_ASSIGN_OR_RETURN(FaceResult result,
                            ProcessFace(face, inputs, settings, w, least_log2[f]));
    if (result.needs_tracer) {
      deferred[f] = 1;
      return Status::Ok();
    }
    fallback[f] = result.fallback_samples;
    processed.stats[f] = result.stats;
    processed.kept[f] = Keep(result, settings.data_type, processed.channels);
    return Status::Ok();
  };
  auto each = [&](std::span<const int> run) {
    return ForEachFace(
        static_cast<int>(run.size()), [&](int k) { return run[static_cast<std::size_t>(k)]; },
        scratches, nullptr, process);
  };
  DISPEX_RETURN_IF_ERROR(inputs.mapping ? each(faces) : ForEachTracedRun(inputs, faces, each));
  std::vector<int> waiting;
  for (int f : faces) {
    if (deferred[static_cast<std::size_t>(f)]) waiting.push_back(f);
  }
  if (!waiting.empty()) {
    DISPEX_RETURN_IF_ERROR(TraceWaiting(inputs, waiting));
    DISPEX_RETURN_IF_ERROR(ForEachFace(
        static_cast<int>(waiting.size()),
        [&](int k) { return waiting[static_cast<std::size_t>(k)]; }, scratches, nullptr, process));
  }
  WorkerTotals extra;
  AddCpuTimes(scratches, extra);
  processed.redone.resize(num_faces, 0);
  for (int f : faces) {
    const auto i = static_cast<std::size_t>(f);
    processed.redone[i] = 1;
    processed.workers.rays_cast += static_cast<std::uint64_t>(processed.stats[i].rays);
    processed.fallback_samples += fallback[i];
    processed.fallback_faces += fallback[i] > 0;
  }
  processed.workers.cpu_limit += extra.cpu_limit;
  processed.workers.cpu_trace += extra.cpu_trace;
  processed.workers.cpu_spectral += extra.cpu_spectral;
  return Status::Ok();
}

Status WriteKeptFaces(PtexWriter& writer, const ExtractInputs& inputs,
                      const ProcessedFaces& processed) {
  const int num_faces = inputs.surface.num_ptex_faces();
  const PreviousMap* previous = processed.previous;
  const std::string encoding = PtexEncodingName(writer.options());
  FirstError error;
  tbb::parallel_for(0, num_faces, [&](int f) {
    const auto i = static_cast<std::size_t>(f);
    const KeptFace& kept = processed.kept[i];
    if (!kept.kept || error.failed()) return;
    const bool as_copied =
        processed.copied[i] && (processed.redone.empty() || !processed.redone[i]);
    // An unread face is a copied one that the edges did not redo.
    const Status s =
        kept.unread || (as_copied && previous != nullptr && previous->EncodedAs(i, encoding))
            ? WriteCopied(writer, inputs, *previous, PtexFaceId(f), encoding)
            : WriteTexels(writer, inputs, PtexFaceId(f), kept.ulog2, kept.vlog2, kept.texels);
    if (!s.ok()) error.Record(f, s);
  });
  return error.failed() ? error.status() : Status::Ok();
}

}  // namespace dispex::extract
