// Extract, read top-down: load the inputs -> resolve the automatic settings -> process every
// Ptex face -> fill the faces that missed entirely -> make shared edges meet (watertight) ->
// add up the totals -> write the map. Each stage is in its own file of src/extract.
#include "dispex/extract.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <optional>

#include "core/system.h"
#include "dispex/cancel.h"
#include "dispex/shapes.h"
#include "dispex/version.h"
#include "extract/edge_matching.h"
#include "extract/extract_inputs.h"
#include "extract/extract_meta.h"
#include "extract/extract_settings.h"
#include "extract/extract_shape.h"
#include "extract/face_keys.h"
#include "extract/face_records.h"
#include "extract/face_totals.h"
#include "extract/missed_faces.h"
#include "extract/parallel_errors.h"
#include "extract/previous_map.h"
#include "extract/process_faces.h"

namespace dispex::extract {

namespace {

// A temporary file beside the target until CommitMap.
StatusOr<PtexWriter> CreateMap(const ExtractOptions& options, const ExtractInputs& inputs) {
  PtexWriterOptions writer_options;
  writer_options.data_type = options.data_type;
  writer_options.compression_level = options.compression_level;
  return PtexWriter::Create(options.output_path, writer_options, inputs.surface.num_ptex_faces());
}

// The meta data, then the file laid out and renamed onto the target.
Status CommitMap(PtexWriter& writer, const ExtractInputs& inputs,
                 std::span<const Hash128> face_keys, const ProcessedFaces& faces,
                 ExtractReport& report) {
  Stopwatch clock;
  DISPEX_RETURN_IF_ERROR(AddExtractMetaData(writer, inputs.base, report, face_keys,
                                            faces.first_pass, faces.edge_means));
  if (CancelRequested()) return Cancelled();
  DISPEX_RETURN_IF_ERROR(writer.Finish());
  report.t_write = clock.seconds();
  std::error_code ec;
  report.bytes_written = std::filesystem::file_size(report.output_path, ec);
  return Status::Ok();
}

// What changed since the previous map, in words.
std::string RedoReason(const PreviousMap& previous, const ExtractReport& report) {
  if (!previous.usable()) return previous.notice().empty() ? "no previous map" : previous.notice();
  std::vector<std::string> changed;
  if (previous.MetaString("dispex:base_fingerprint") != report.base_fingerprint) {
    changed.push_back("base");
  }
  if (previous.MetaString("dispex:sculpt_fingerprint") != report.sculpt_fingerprint) {
    changed.push_back("sculpt");
  }
  const nlohmann::json before = nlohmann::json::parse(previous.MetaString("dispex:options"),
                                                      nullptr, /*allow_exceptions=*/false);
  const nlohmann::json now = ExtractOptionsJson(report.options);
  std::string options;
  for (const auto& [key, value] : now.items()) {
    if (!before.is_object() || !before.contains(key) || before[key] != value) {
      options += (options.empty() ? "options: " : ", ") + key;
    }
  }
  if (!options.empty()) changed.push_back(options);
  if (changed.empty()) changed.push_back("input file names");
  std::string out;
  for (const std::string& c : changed) out += (out.empty() ? "" : ", ") + c;
  return out;
}

// Several disjoint shapes are ExtractAsset's: one map per shape.
Status CheckOneShape(const ExtractOptions& options, const Mesh& base) {
  if (base.group_names.size() < 2) return Status::Ok();
  auto shapes = SplitShapes(base, /*require_disjoint=*/true);
  if (!shapes.ok() || shapes->size() < 2) return Status::Ok();  // groups of one surface
  std::string names;
  for (std::size_t i = 0; i < shapes->size() && i < 10; ++i) {
    names += fmt::format("{}'{}'", i ? ", " : "", (*shapes)[i].name);
  }
  if (shapes->size() > 10) names += ", ...";
  return Status::Error(fmt::format("{} has {} shapes ({}): write one map per shape with output_dir",
                                   options.base_path, shapes->size(), names));
}

StatusOr<ExtractReport> ExtractInArena(const ExtractOptions& options, int threads) {
  Stopwatch total_clock;
  ExtractReport report = StartReport(options, threads);
  const std::uint64_t memory_limit = MemoryLimit(options);
  DISPEX_ASSIGN_OR_RETURN(ExtractInputs inputs, ReadInputs(options, memory_limit, report));
  DISPEX_RETURN_IF_ERROR(CheckOneShape(options, inputs.base));
  return ExtractShape(options, std::move(inputs), std::move(report), total_clock);
}

}  // namespace

std::uint64_t MemoryLimit(const ExtractOptions& options) {
  return options.max_memory > 0 ? options.max_memory : AvailableMemoryBytes();
}

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

StatusOr<ExtractReport> ExtractShape(const ExtractOptions& options, ExtractInputs inputs,
                                     ExtractReport report, const Stopwatch& total_clock) {
  report.inputs_key = InputsKey(report).Hex();
  const auto num_faces = static_cast<std::size_t>(inputs.surface.num_ptex_faces());
  PreviousMap previous;
  if (options.incremental) {
    previous = PreviousMap::Open(options.output_path, num_faces);
    if (previous.usable() && previous.MetaString(kInputsKeyMetaKey) == report.inputs_key) {
      report.unchanged = true;
      report.t_total = total_clock.seconds();
      report.peak_rss_bytes = PeakResidentBytes();
      return report;
    }
    if (!previous.notice().empty()) report.warnings.push_back(previous.notice());
    report.redo_reason = RedoReason(previous, report);
  }
  DISPEX_RETURN_IF_ERROR(BuildTracer(options, inputs, report));
  DISPEX_ASSIGN_OR_RETURN(ExtractSettings settings, ResolveSettings(options, inputs, report));
  Stopwatch keys_clock;
  const std::vector<Hash128> keys = ComputeFaceKeys(inputs, settings);
  report.t_keys = keys_clock.seconds();
  DISPEX_ASSIGN_OR_RETURN(PtexWriter writer, CreateMap(options, inputs));

  Stopwatch faces_clock;
  DISPEX_ASSIGN_OR_RETURN(ProcessedFaces faces,
                          ProcessFaces(inputs, settings, previous.usable() ? &previous : nullptr,
                                       keys, options.progress, writer));
  report.faces_copied = faces.faces_copied;
  report.faces_extracted = static_cast<std::int64_t>(num_faces) - faces.faces_copied -
                           inputs.surface.stats().hole_ptex_faces;
  DISPEX_RETURN_IF_ERROR(FillMissedFaces(options, inputs, faces, writer, report));
  if (settings.watertight != WatertightEdges::kOff) {
    DISPEX_RETURN_IF_ERROR(MatchEdges(inputs, settings, faces, report));
    DISPEX_RETURN_IF_ERROR(WriteKeptFaces(writer, inputs, faces));
  }
  ListDiscontinuousFaces(inputs, faces, report);
  report.t_sample_trace = faces_clock.seconds();

  DISPEX_RETURN_IF_ERROR(AddFaceTotals(options, inputs, settings, faces, report));
  DISPEX_RETURN_IF_ERROR(CommitMap(writer, inputs, keys, faces, report));
  report.peak_rss_bytes = PeakResidentBytes();
  report.t_total = total_clock.seconds();
  return report;
}

}  // namespace dispex::extract

namespace dispex {

StatusOr<ExtractReport> Extract(const ExtractOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateExtractOptions(options));
  return extract::RunInArena(
      options.threads, [&](int threads) { return extract::ExtractInArena(options, threads); });
}

}  // namespace dispex
