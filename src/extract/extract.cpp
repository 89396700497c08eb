// Extract, read top-down: load the inputs -> resolve the automatic settings -> process every
// Ptex face -> fill the faces that missed entirely -> make shared edges meet (watertight) ->
// add up the totals -> write the map. Each stage is in its own file of src/extract.
#include "dispex/extract.h"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <filesystem>
#include <optional>

#include "core/system.h"
#include "dispex/cancel.h"
#include "dispex/version.h"
#include "extract/edge_matching.h"
#include "extract/extract_inputs.h"
#include "extract/extract_meta.h"
#include "extract/extract_settings.h"
#include "extract/face_totals.h"
#include "extract/missed_faces.h"
#include "extract/parallel_errors.h"
#include "extract/process_faces.h"

namespace dispex::extract {

namespace {

ExtractReport StartReport(const ExtractOptions& options, int threads) {
  ExtractReport report;
  report.version = DISPEX_VERSION_STRING;
  report.options = options;
  report.base_path = options.base_path;
  report.sculpt_path = options.sculpt_path;
  report.output_path = options.output_path;
  report.threads = threads;
  return report;
}

// A temporary file beside the target until CommitMap.
StatusOr<PtexWriter> CreateMap(const ExtractOptions& options, const ExtractInputs& inputs) {
  PtexWriterOptions writer_options;
  writer_options.data_type = options.data_type;
  writer_options.compression_level = options.compression_level;
  return PtexWriter::Create(options.output_path, writer_options, inputs.surface.num_ptex_faces());
}

// The meta data, then the file laid out and renamed onto the target.
Status CommitMap(PtexWriter& writer, const ExtractInputs& inputs, ExtractReport& report) {
  Stopwatch clock;
  DISPEX_RETURN_IF_ERROR(AddExtractMetaData(writer, inputs.base, report));
  if (CancelRequested()) return Cancelled();
  DISPEX_RETURN_IF_ERROR(writer.Finish());
  report.t_write = clock.seconds();
  std::error_code ec;
  report.bytes_written = std::filesystem::file_size(report.output_path, ec);
  return Status::Ok();
}

StatusOr<ExtractReport> ExtractInArena(const ExtractOptions& options, int threads) {
  Stopwatch total_clock;
  ExtractReport report = StartReport(options, threads);
  const std::uint64_t memory_limit =
      options.max_memory > 0 ? options.max_memory : AvailableMemoryBytes();

  DISPEX_ASSIGN_OR_RETURN(ExtractInputs inputs, LoadInputs(options, memory_limit, report));
  DISPEX_ASSIGN_OR_RETURN(ExtractSettings settings, ResolveSettings(options, inputs, report));
  DISPEX_ASSIGN_OR_RETURN(PtexWriter writer, CreateMap(options, inputs));

  Stopwatch faces_clock;
  DISPEX_ASSIGN_OR_RETURN(ProcessedFaces faces,
                          ProcessFaces(inputs, settings, options.progress, writer));
  DISPEX_RETURN_IF_ERROR(FillMissedFaces(options, inputs, faces, writer, report));
  if (settings.watertight != WatertightEdges::kOff) {
    DISPEX_RETURN_IF_ERROR(MatchEdges(inputs, settings, faces, report));
    DISPEX_RETURN_IF_ERROR(WriteKeptFaces(writer, inputs, faces));
  }
  ListDiscontinuousFaces(inputs, faces, report);
  report.t_sample_trace = faces_clock.seconds();

  DISPEX_RETURN_IF_ERROR(AddFaceTotals(options, inputs, settings, faces, report));
  DISPEX_RETURN_IF_ERROR(CommitMap(writer, inputs, report));
  report.peak_rss_bytes = PeakResidentBytes();
  report.t_total = total_clock.seconds();
  return report;
}

}  // namespace

}  // namespace dispex::extract

namespace dispex {

StatusOr<ExtractReport> Extract(const ExtractOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateExtractOptions(options));
  // threads = N runs every parallel loop (Embree's BVH build included) in an arena of N
  // threads, more than the machine's cores if asked: the map is the same at any count.
  std::optional<tbb::global_control> thread_limit;
  if (options.threads > 0) {
    thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                         static_cast<std::size_t>(options.threads));
  }
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.initialize();
  const int threads =
      std::min(arena.max_concurrency(), static_cast<int>(tbb::global_control::active_value(
                                            tbb::global_control::max_allowed_parallelism)));
  return arena.execute([&] { return extract::ExtractInArena(options, threads); });
}

}  // namespace dispex
