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
#include "dispex/vector_space.h"
#include "dispex/version.h"
#include "extract/edge_matching.h"
#include "extract/extract_inputs.h"
#include "extract/extract_plan.h"
#include "extract/extract_settings.h"
#include "extract/extract_shape.h"
#include "extract/face_totals.h"
#include "extract/incremental/face_keys.h"
#include "extract/incremental/face_records.h"
#include "extract/incremental/previous_map.h"
#include "extract/incremental/ray_cache.h"
#include "extract/incremental/shard_parts.h"
#include "extract/incremental/shard_plan.h"
#include "extract/input_checks.h"
#include "extract/io/extract_meta.h"
#include "extract/mapping/extract_mapping.h"
#include "extract/missed_faces.h"
#include "extract/parallel_errors.h"
#include "extract/process_faces.h"
#include "extract/uv_maps.h"
#include "extract/vector_faces.h"

namespace dispex::extract {

namespace {

// A temporary file beside the target until CommitMap. A vector map's cross-face filter turns
// a tangent or parametric vector into the neighbour's frame; an object-space one is as is.
StatusOr<PtexWriter> CreateMap(const ExtractOptions& options, const ExtractInputs& inputs) {
  PtexWriterOptions writer_options;
  writer_options.data_type = options.data_type;
  writer_options.compression_level = options.compression_level;
  writer_options.level_data_hash_key = kLevelDataHashMetaKey;
  if (options.vector) {
    writer_options.num_channels = 3;
    writer_options.edge_filter = *options.vector == VectorSpace::kObject
                                     ? PtexEdgeFilterMode::kNone
                                     : PtexEdgeFilterMode::kTangentVector;
  }
  return PtexWriter::Create(options.output_path, writer_options, inputs.surface.num_ptex_faces());
}

// The meta data, then the file laid out and renamed onto the target.
Status CommitMap(PtexWriter& writer, const ExtractInputs& inputs,
                 std::span<const Hash128> face_keys, const ProcessedFaces& faces,
                 ExtractReport& report) {
  Stopwatch clock;
  DISPEX_RETURN_IF_ERROR(AddExtractMetaData(writer, inputs.base, report, face_keys,
                                            faces.first_pass, faces.edge_means,
                                            faces.first_round_edge_steps));
  if (CancelRequested()) return Cancelled();
  DISPEX_RETURN_IF_ERROR(writer.Finish());
  report.times.write = clock.seconds();
  std::error_code ec;
  report.output.bytes = std::filesystem::file_size(report.output.path, ec);
  return Status::Ok();
}

// A shard's part: its faces' first pass (kept faces written now), every other face -- and any
// of its own that missed entirely, which the merge fills from their neighbours -- 0 with a zero
// key, and the shard's record.
Status CommitPart(PtexWriter& writer, const ExtractInputs& inputs,
                  std::span<const std::uint8_t> in_shard, const ShardInfo& info,
                  const ProcessedFaces& faces, ExtractReport& report) {
  if (!faces.kept.empty()) DISPEX_RETURN_IF_ERROR(WriteKeptFaces(writer, inputs, faces));
  std::vector<Hash128> keys(in_shard.size());
  for (std::size_t f = 0; f < in_shard.size(); ++f) {
    const PtexFaceId face(static_cast<int>(f));
    if (in_shard[f]) keys[f] = inputs.face_keys->keys[f];
    if (!in_shard[f] || (faces.stats[f].all_missed && !inputs.surface.is_hole(face))) {
      DISPEX_RETURN_IF_ERROR(WriteConstantFace(writer, inputs, face, 0.0f));
    }
  }
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(kShardMetaKey, ShardInfoJson(info)));
  return CommitMap(writer, inputs, keys, faces, report);
}

// What the previous run's UV-space tiles may give an incremental run: nothing (no same_key)
// unless there is a previous map.
UvPrevious PreviousUvTiles(const ExtractOptions& options, const PreviousMap& previous,
                           const FaceKeys& keys) {
  UvPrevious out;
  if (options.uv_maps_dir.empty() || !options.incremental || !previous.usable()) return out;
  out.inputs_key = previous.MetaString(kInputsKeyMetaKey);
  out.same_key.resize(keys.keys.size());
  for (std::size_t f = 0; f < keys.keys.size(); ++f) {
    out.same_key[f] = previous.SameKey(f, keys.keys[f]);
  }
  return out;
}

// What changed since the previous map, in words.
std::string RedoReason(const PreviousMap& previous, const ExtractReport& report) {
  if (!previous.usable()) return previous.notice().empty() ? "no previous map" : previous.notice();
  // The map is of these inputs (PlanOutput ran on because of its tiles).
  if (previous.MetaString(kInputsKeyMetaKey) == report.incremental.inputs_key) {
    return "the UV-space tiles are missing or not of this map";
  }
  std::vector<std::string> changed;
  if (previous.MetaString("dispex:base_fingerprint") != report.inputs.base_fingerprint) {
    changed.push_back("base");
  }
  if (previous.MetaString("dispex:sculpt_fingerprint") != report.inputs.sculpt_fingerprint) {
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

// The tracer of an incremental run, a merge or a shard of part of the sculpt, with a given
// search distance: the sculpt within reach (`traced`: FacesWithinReach). The tie rule
// (dispex/trace.h) keeps hits at shared edges, vertices and folds those of the whole sculpt's
// BVH.
Status BuildLocalTracer(const ExtractOptions& options, std::vector<std::uint8_t> traced, bool shard,
                        ExtractInputs& inputs, ExtractReport& report) {
  SetTracerOptions(options, inputs);
  Stopwatch clock;
  // Most faces' samples all hit within the search distance: the sculpt within its reach, and
  // the retry's only once a face has a miss (WidenToRetryReach). A shard cannot widen: it
  // releases the rest of the sculpt.
  const bool first_search = !shard && !inputs.face_keys->first_search_boxes.empty();
  Mesh part = SculptWithinReach(inputs, *inputs.face_keys, traced, first_search);
  report.times.bvh = clock.seconds();
  report.incremental.tracer_faces = std::count(traced.begin(), traced.end(), 1);
  // A shard needs no more of the sculpt than its part (no stage crosses faces): released
  // before the BVH is built, its memory falls with the shard count.
  if (shard && part.num_faces() > 0) ReleaseSculpt(inputs);
  DISPEX_RETURN_IF_ERROR(BuildPartTracer(std::move(part), std::move(traced), inputs, report));
  inputs.first_search_only = first_search && inputs.tracer && !inputs.traced.empty();
  if (inputs.first_search_only) report.tracer += " within the search distance's reach";
  return Status::Ok();
}

// Rays over the whole sculpt: one BVH of it when that fits in the memory limit (built compact
// when only that fits), else the faces
// traced in runs, a BVH of the sculpt within reach of one at a time (kInParts: the same map,
// built again for each run); refused before any ray when not even that fits.
Status PlanSculptParts(const ExtractOptions& options, ExtractInputs& inputs,
                       ExtractReport& report) {
  ExtractPlan& plan = report.plan;
  DISPEX_ASSIGN_OR_RETURN(
      const SculptParts parts,
      SculptPartsWithin(inputs.memory, report.inputs.sculpt_faces, inputs.memory_limit,
                        options.max_memory > 0, &plan.memory_estimate));
  if (parts.compact_bvh) {
    inputs.compact_bvh = plan.compact_bvh = true;
    report.warnings.push_back(fmt::format(
        "{}: a BVH of the whole sculpt at {} quality is estimated to need more than the {} memory "
        "limit: built compact at medium quality instead (about half the memory, the same map)",
        options.sculpt_path, BuildQualityName(options.bvh_quality),
        MemorySize(inputs.memory_limit)));
  }
  if (parts.parts == 1) return Status::Ok();
  inputs.sculpt_parts = parts.parts;
  inputs.part_faces = parts.part_faces;
  plan.tracer = ExtractPlan::Tracer::kInParts;
  plan.sculpt_parts = inputs.sculpt_parts;
  report.warnings.push_back(fmt::format(
      "{}: a BVH of the whole sculpt is estimated to need more than the {} memory limit: "
      "traced in {} parts, one at a time (the same map, slower){}",
      options.sculpt_path, MemorySize(inputs.memory_limit), inputs.sculpt_parts,
      options.check_inputs ? "; the sculpt's placement against the base is not checked" : ""));
  return Status::Ok();
}

// The output, the inputs key and, for an incremental run or a merge, the previous map or the
// parts the faces that do not run are copied from.
StatusOr<PreviousMap> PlanOutput(const ExtractOptions& options, const ExtractInputs& inputs,
                                 std::vector<ShardPart>* parts, ExtractReport& report) {
  ExtractPlan& plan = report.plan;
  const bool shard = options.shard_count > 0;
  plan.output = shard ? ExtractPlan::Output::kShardPart : ExtractPlan::Output::kMap;
  plan.channels = options.vector ? 3 : 1;
  plan.faces = inputs.surface.num_ptex_faces();
  plan.uv_maps = !options.uv_maps_dir.empty();
  const std::string map_inputs_key = InputsKey(report).Hex();
  report.incremental.inputs_key =
      shard ? PartInputsKey(map_inputs_key, options.shard_index, options.shard_count)
            : map_inputs_key;
  const auto num_faces = static_cast<std::size_t>(plan.faces);
  PreviousMap previous;
  if (parts != nullptr) {
    DISPEX_RETURN_IF_ERROR(CheckPartsMatchInputs(*parts, report));
    report.shard.parts_merged = static_cast<std::int64_t>(parts->size());
    plan.faces_from = fmt::format("{} shard parts", parts->size());
    previous = PreviousMap::FromParts(std::move(*parts), ShardOrder(inputs.base, inputs.surface));
    return previous;
  }
  if (!options.incremental) return previous;
  previous = PreviousMap::Open(options.output_path, num_faces, options.vector.has_value());
  const std::string stored = previous.usable() ? previous.MetaString(kInputsKeyMetaKey) : "";
  if (stored == report.incremental.inputs_key &&
      (options.uv_maps_dir.empty() || UvTilesCurrent(options, stored))) {
    report.incremental.unchanged = true;
    plan.output = ExtractPlan::Output::kUpToDate;
    return previous;
  }
  previous.CheckFaceData();
  if (!previous.notice().empty()) report.warnings.push_back(previous.notice());
  report.incremental.redo_reason = plan.redo_reason = RedoReason(previous, report);
  if (previous.usable()) plan.faces_from = options.output_path;
  return previous;
}

// A shard's faces: a run of the shard order balanced by cost (PlanShard); empty for a run that
// is not a shard.
std::vector<std::uint8_t> ShardFaces(const ExtractOptions& options, const ExtractInputs& inputs,
                                     const ExtractSettings& settings, const FaceKeys& keys,
                                     ExtractReport& report) {
  if (options.shard_count == 0) return {};
  const std::vector<std::int32_t> order = ShardOrder(inputs.base, inputs.surface);
  const ShardRange range = PlanShard(inputs.surface, settings.plan, keys, order,
                                     options.shard_index, options.shard_count);
  report.shard.begin = range.begin;
  report.shard.end = range.end;
  report.shard.cost_fraction = range.cost_fraction;
  std::vector<std::uint8_t> in_shard(static_cast<std::size_t>(inputs.surface.num_ptex_faces()), 0);
  for (auto i = range.begin; i < range.end; ++i) {
    in_shard[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])] = 1;
  }
  return in_shard;
}

// A sculpt moved, scaled or turned against its base as a whole is refused (input_checks.h):
// measured through the correspondence where the map reads one, else by the whole sculpt's BVH.
Status CheckPlacementIfAsked(const ExtractOptions& options, const ExtractInputs& inputs,
                             const ExtractSettings& settings, const ExtractReport& report) {
  if (!options.check_inputs) return Status::Ok();
  std::unique_ptr<GridSource> grids;
  if (inputs.correspondence) {
    grids = std::make_unique<CorrespondenceGrids>(*inputs.correspondence, inputs.faces);
  } else if (inputs.mapping) {
    grids = std::make_unique<MappingGrids>(*inputs.mapping);
  } else if (inputs.tracer == nullptr) {
    return Status::Ok();
  }
  DISPEX_ASSIGN_OR_RETURN(PlacementFit fit, MeasurePlacement(inputs, grids.get(), &settings));
  return CheckPlacement(fit, report.inputs.base_diagonal, inputs.sculpt.source);
}

// What each face is made from (face_keys.h; a vector map's: VectorFaceKeys).
// An incremental run keeps interpolated faces' field keys in the cache folder (field_keys.h).
FaceKeys KeyFaces(const ExtractOptions& options, const ExtractInputs& inputs,
                  const ExtractSettings& settings, ExtractReport& report) {
  Stopwatch clock;
  const std::string folder = options.incremental ? CacheFolder(options) : std::string();
  FaceKeys keys = settings.vector ? VectorFaceKeys(inputs, settings, folder)
                                  : ComputeFaceKeys(inputs, settings, folder);
  report.incremental.fields_kept = keys.fields_kept;
  report.times.keys = clock.seconds();
  return keys;
}

// A shard's part: its faces' first pass and its record.
Status WritePart(const ExtractOptions& options, const ExtractInputs& inputs,
                 std::span<const std::uint8_t> in_shard, const ProcessedFaces& faces,
                 PtexWriter& writer, ExtractReport& report) {
  report.incremental.faces_extracted = -faces.faces_copied;
  for (std::size_t f = 0; f < in_shard.size(); ++f) {
    report.incremental.faces_extracted +=
        in_shard[f] && !inputs.surface.is_hole(PtexFaceId(static_cast<int>(f)));
  }
  ShardInfo info;
  info.index = options.shard_index;
  info.count = options.shard_count;
  info.begin = report.shard.begin;
  info.end = report.shard.end;
  info.map_inputs_key = InputsKey(report).Hex();
  info.base_path = std::filesystem::absolute(options.base_path).lexically_normal().string();
  info.sculpt_path = std::filesystem::absolute(options.sculpt_path).lexically_normal().string();
  info.options = ExtractOptionsJson(options).dump();
  return CommitPart(writer, inputs, in_shard, info, faces, report);
}

// The stages that cross faces -- faces that missed filled from their neighbours, shared edges
// made to meet, the totals -- then the map and its UV-space tiles.
Status WriteMap(const ExtractOptions& options, ExtractInputs& inputs,
                const ExtractSettings& settings, ProcessedFaces& faces, PtexWriter& writer,
                const Stopwatch& faces_clock, const UvPrevious* uv_previous,
                ExtractReport& report) {
  report.incremental.faces_extracted = static_cast<std::int64_t>(inputs.surface.num_ptex_faces()) -
                                       faces.faces_copied - inputs.surface.stats().hole_ptex_faces;
  DISPEX_RETURN_IF_ERROR(FillMissedFaces(options, inputs, faces, writer, report));
  if (settings.watertight != WatertightEdges::kOff) {
    DISPEX_RETURN_IF_ERROR(MatchEdges(inputs, settings, faces, report));
    for (std::size_t f = 0; f < faces.redone.size(); ++f) {
      report.incremental.faces_copied_redone += faces.copied[f] && faces.redone[f];
    }
    if (inputs.widened) {
      report.tracer +=
          inputs.traced.empty()
              ? std::string("; then the whole sculpt, for faces the edges raised")
              : fmt::format("; then {} of {} sculpt faces, for faces the edges raised",
                            inputs.traced_part.num_faces(), report.inputs.sculpt_faces);
    }
    DISPEX_RETURN_IF_ERROR(WriteKeptFaces(writer, inputs, faces));
  }
  if (inputs.widened_for_retry) {
    report.tracer += "; then the retry distance's reach, for faces with samples that missed";
  }
  ListDiscontinuousFaces(inputs, faces, report);
  // The runs' BVHs (a sculpt in parts) are built among the faces, but counted apart.
  report.times.sample_trace = faces_clock.seconds() - inputs.run_bvh_seconds;
  if (inputs.sculpt_parts > 1) {
    report.times.bvh += inputs.run_bvh_seconds;
    report.tracer = fmt::format("{}; {} BVHs, each of the sculpt within reach of a run of faces",
                                inputs.run_backend, inputs.runs_traced);
  }
  if (inputs.mapping != nullptr) ReportMapping(inputs, faces, report);
  DISPEX_RETURN_IF_ERROR(AddFaceTotals(options, inputs, settings, faces, report));
  DISPEX_RETURN_IF_ERROR(CommitMap(writer, inputs, inputs.face_keys->keys, faces, report));
  if (!options.uv_maps_dir.empty()) {
    DISPEX_RETURN_IF_ERROR(WriteUvMaps(options, inputs, settings, uv_previous, report));
  }
  return Status::Ok();
}

ExtractReport Finished(ExtractReport report, const Stopwatch& total_clock) {
  report.peak_rss_bytes = PeakResidentBytes();
  report.times.total = total_clock.seconds();
  return report;
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

StatusOr<ExtractReport> ExtractInArena(const ExtractOptions& options, int threads,
                                       std::vector<ShardPart>* parts = nullptr) {
  Stopwatch total_clock;
  ExtractReport report = StartReport(options, threads);
  const std::uint64_t memory_limit = MemoryLimit(options);
  DISPEX_ASSIGN_OR_RETURN(ExtractInputs inputs, ReadInputs(options, memory_limit, report));
  DISPEX_RETURN_IF_ERROR(CheckOneShape(options, inputs.base));
  return ExtractShape(options, std::move(inputs), std::move(report), total_clock, parts);
}

}  // namespace

std::uint64_t MemoryLimit(const ExtractOptions& options) {
  return options.max_memory > 0 ? options.max_memory : AvailableMemoryBytes(options.threads);
}

ExtractReport StartReport(const ExtractOptions& options, int threads) {
  ExtractReport report;
  report.version = Version();
  report.options = options;
  report.inputs.base_path = options.base_path;
  report.inputs.sculpt_path = options.sculpt_path;
  report.output.path = options.output_path;
  report.settings.threads = threads;
  return report;
}

StatusOr<ExtractReport> ExtractShape(const ExtractOptions& options, ExtractInputs inputs,
                                     ExtractReport report, const Stopwatch& total_clock,
                                     std::vector<ShardPart>* parts) {
  if (options.check_inputs) {
    DISPEX_RETURN_IF_ERROR(CheckFaceCounts(inputs.base, inputs.sculpt));
  }
  ExtractPlan& plan = report.plan;
  DISPEX_ASSIGN_OR_RETURN(PreviousMap previous, PlanOutput(options, inputs, parts, report));
  if (plan.output == ExtractPlan::Output::kUpToDate)
    return Finished(std::move(report), total_clock);
  // Through the subdivision correspondence no BVH is built (extract_mapping.h; a vector map
  // reads the sculpt through it only, vector_faces.h). Rays estimate the automatic search
  // distance over the whole surface; a given one lets an incremental run or a merge trace only
  // the sculpt within reach of the faces it extracts. A shard of ShardSculpt::kPart traces
  // only within reach of its own faces, and estimates the automatic distance in parts.
  DISPEX_RETURN_IF_ERROR(options.vector ? MatchVectorSculpt(options, inputs, report)
                                        : ChooseMethod(options, inputs, report));
  plan.method = report.method.used;
  const bool shard = options.shard_count > 0;
  const bool part_shard = shard && options.shard_sculpt == ShardSculpt::kPart;
  const bool traced = !options.vector && inputs.mapping == nullptr;
  const bool auto_distance = options.search_distance.kind == SearchDistanceSpec::Kind::kAuto;
  // An incremental run keeps the automatic search distance's rays (ray_cache.h); with those of
  // the run before, it updates the estimate without a BVH of the whole sculpt.
  if (traced && auto_distance && options.incremental && !shard) {
    inputs.ray_cache_path =
        RayCachePath(CacheFolder(options), options.sculpt_path, report.inputs.base_fingerprint);
  }
  std::error_code ec;
  const bool rays_kept =
      !inputs.ray_cache_path.empty() && std::filesystem::exists(inputs.ray_cache_path, ec);
  const bool within_reach =
      traced && ((previous.usable() && options.incremental && (!auto_distance || rays_kept)) ||
                 (!auto_distance && previous.usable() && parts != nullptr) || part_shard);
  plan.tracer = !traced        ? ExtractPlan::Tracer::kNone
                : within_reach ? ExtractPlan::Tracer::kWithinReach
                               : ExtractPlan::Tracer::kWholeSculpt;
  // Over the memory limit, any traced plan becomes kInParts.
  if (traced) DISPEX_RETURN_IF_ERROR(PlanSculptParts(options, inputs, report));
  if (part_shard) {
    inputs.estimate_parts = std::clamp(options.shard_count, 1, kMaxSculptParts);
  }
  if (plan.tracer != ExtractPlan::Tracer::kWholeSculpt) SetTracerOptions(options, inputs);
  if (plan.tracer == ExtractPlan::Tracer::kWholeSculpt) {
    DISPEX_RETURN_IF_ERROR(BuildTracer(options, inputs, report));
  }
  DISPEX_ASSIGN_OR_RETURN(ExtractSettings settings, ResolveSettings(options, inputs, report));
  DISPEX_RETURN_IF_ERROR(CheckPlacementIfAsked(options, inputs, settings, report));
  const FaceKeys face_keys = KeyFaces(options, inputs, settings, report);
  inputs.face_keys = &face_keys;
  // A shard runs its faces' first pass only, no stage that crosses faces (the merge runs them).
  const std::vector<std::uint8_t> in_shard =
      ShardFaces(options, inputs, settings, face_keys, report);
  const std::vector<FaceSource> sources =
      PlanFaces(plan, inputs, face_keys.keys, &previous, in_shard);
  std::vector<std::uint8_t> reach;
  if (within_reach) {
    reach = FacesWithinReach(inputs, sources, shard ? 0 : kLocalRings);
    // For a run that is not a shard, the whole sculpt when that is most of it.
    if (!shard && plan.tracer == ExtractPlan::Tracer::kWithinReach &&
        2 * std::count(reach.begin(), reach.end(), 1) > plan.faces) {
      plan.tracer = ExtractPlan::Tracer::kWholeSculpt;
    }
  }
  if (options.plan_only) return Finished(std::move(report), total_clock);

  if (plan.tracer == ExtractPlan::Tracer::kWithinReach) {
    DISPEX_RETURN_IF_ERROR(BuildLocalTracer(options, std::move(reach), shard, inputs, report));
  } else if (within_reach && plan.tracer == ExtractPlan::Tracer::kWholeSculpt) {
    DISPEX_RETURN_IF_ERROR(BuildTracer(options, inputs, report));
  }
  DISPEX_ASSIGN_OR_RETURN(PtexWriter writer, CreateMap(options, inputs));
  Stopwatch faces_clock;
  DISPEX_ASSIGN_OR_RETURN(ProcessedFaces faces,
                          ProcessFaces(inputs, settings, &previous, sources, options.progress,
                                       options.progress_counter, writer));
  report.incremental.faces_copied = faces.faces_copied;
  if (shard) {
    report.times.sample_trace = faces_clock.seconds();
    DISPEX_RETURN_IF_ERROR(WritePart(options, inputs, in_shard, faces, writer, report));
  } else {
    const UvPrevious uv_previous = PreviousUvTiles(options, previous, face_keys);
    DISPEX_RETURN_IF_ERROR(WriteMap(options, inputs, settings, faces, writer, faces_clock,
                                    uv_previous.same_key.empty() ? nullptr : &uv_previous, report));
  }
  return Finished(std::move(report), total_clock);
}

}  // namespace dispex::extract

namespace dispex {

StatusOr<ExtractReport> Extract(const ExtractOptions& given) {
  DISPEX_RETURN_IF_ERROR(ValidateExtractOptions(given));
  ExtractOptions options = given;
  if (options.base_mesh && options.base_path.empty()) options.base_path = "base";
  if (options.sculpt_mesh && options.sculpt_path.empty()) options.sculpt_path = "sculpt";
  return extract::RunInArena(
      options.threads, [&](int threads) { return extract::ExtractInArena(options, threads); });
}

StatusOr<ExtractReport> MergeShards(const MergeOptions& merge) {
  if (merge.parts.empty()) return Status::Error("no parts given");
  if (merge.output_path.empty()) return Status::Error("no output file given (output_path)");
  std::vector<extract::ShardPart> parts;
  for (const std::string& path : merge.parts) {
    if (path == merge.output_path) {
      return Status::Error(fmt::format("output {} is also a part; refusing to overwrite it", path));
    }
    DISPEX_ASSIGN_OR_RETURN(extract::ShardPart part, extract::OpenShardPart(path));
    parts.push_back(std::move(part));
  }
  DISPEX_ASSIGN_OR_RETURN(parts, extract::CheckShardParts(std::move(parts)));
  const extract::ShardInfo& info = parts.front().info;
  const nlohmann::json stored = nlohmann::json::parse(info.options, nullptr, false);
  StatusOr<ExtractOptions> read = extract::ExtractOptionsFromJson(stored);
  if (!read.ok()) return read.status().WithPrefix(parts.front().path);
  ExtractOptions options = std::move(*read);
  options.base_path = info.base_path;
  options.sculpt_path = info.sculpt_path;
  options.output_path = merge.output_path;
  options.threads = merge.threads;
  options.progress = merge.progress;
  options.progress_counter = merge.progress_counter;
  options.max_memory = merge.max_memory;
  Status valid = ValidateExtractOptions(options);
  if (!valid.ok()) return valid.WithPrefix(parts.front().path);
  return extract::RunInArena(options.threads, [&](int threads) {
    return extract::ExtractInArena(options, threads, &parts);
  });
}

}  // namespace dispex
