#include "extract/vector_faces.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>

#include "core/progress.h"
#include "core/vec3.h"
#include "dispex/cancel.h"
#include "dispex/correspondence.h"
#include "dispex/spectral.h"
#include "dispex/vector_space.h"
#include "extract/edge_matching.h"
#include "extract/extract_plan.h"
#include "extract/extract_settings.h"
#include "extract/incremental/face_keys.h"
#include "extract/incremental/face_records.h"
#include "extract/input_checks.h"
#include "extract/io/extract_meta.h"
#include "extract/mapping/extract_mapping.h"
#include "extract/mapping/vertex_displacements.h"
#include "extract/parallel_errors.h"
#include "extract/process_faces.h"
#include "extract/uv_maps.h"

namespace dispex::extract {

namespace {

struct VectorScratch {
  explicit VectorScratch(const LimitSurface& surface) : evaluator(surface) {}
  LimitEvaluator evaluator;
  SpectralVectorAnalyzer analyzer;
  std::vector<float> positions, normals, du, dv, channels;
  GridDisplacements grid;  // ExtractSettings::interpolate: the face's vertex displacements
  KeptFace face;           // the face made, when it is written at once
  double cpu_limit = 0, cpu_spectral = 0, cpu_write = 0;
};

// D at the face's n x n texel centres, in the map's space, into w.channels: the sculpt's vertex
// displacements interpolated (`interpolate`, vertex_displacements.h), or the sculpt's quads
// read bilinearly minus the limit point.
Status SampleFace(PtexFaceId face, int n, VectorSpace space, bool interpolate,
                  const ExtractInputs& inputs, const SculptCorrespondence& correspondence,
                  VectorScratch& w, VectorFaceStats& stats) {
  const std::size_t count = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  for (auto* buffer : {&w.positions, &w.normals, &w.du, &w.dv, &w.channels}) {
    buffer->resize(3 * count);
  }
  DISPEX_RETURN_IF_ERROR(
      w.evaluator.EvaluateGridFrames(face, n, n, {w.positions, w.normals, w.du, w.dv}));
  if (interpolate) {
    DISPEX_RETURN_IF_ERROR(
        w.grid.Evaluate(face, *inputs.grids, inputs.sculpt, w.evaluator, /*normals=*/false));
    w.grid.SetSampling(n);
  }
  stats.samples = static_cast<std::int64_t>(count);
  stats.normal_min = std::numeric_limits<float>::infinity();
  stats.normal_max = -std::numeric_limits<float>::infinity();
  for (int j = 0; j < n; ++j) {
    const float v = (static_cast<float>(j) + 0.5f) / static_cast<float>(n);
    for (int i = 0; i < n; ++i) {
      const float u = (static_cast<float>(i) + 0.5f) / static_cast<float>(n);
      const std::size_t k = 3 * (static_cast<std::size_t>(j) * n + i);
      const SurfaceFrame frame{{w.du[k], w.du[k + 1], w.du[k + 2]},
                               {w.dv[k], w.dv[k + 1], w.dv[k + 2]},
                               {w.normals[k], w.normals[k + 1], w.normals[k + 2]}};
      Vec3d d;
      if (interpolate) {
        double xyz[3];
        w.grid.DisplacementAt((i + 0.5) / n, (j + 0.5) / n, xyz);
        d = {xyz[0], xyz[1], xyz[2]};
      } else {
        const Float3 sculpt = SculptPointAt(correspondence, inputs.sculpt, face, u, v);
        const Float3 limit{w.positions[k], w.positions[k + 1], w.positions[k + 2]};
        d = ToVec3d(sculpt) - ToVec3d(limit);
      }
      VectorToChannels(space, frame, FromVec3d<Float3>(d), &w.channels[k]);
      const double along = Dot(d, ToVec3d(frame.normal));
      const double length2 = Dot(d, d);
      stats.normal_min = std::min(stats.normal_min, static_cast<float>(along));
      stats.normal_max = std::max(stats.normal_max, static_cast<float>(along));
      stats.tangential_max =
          std::max(stats.tangential_max, std::sqrt(std::max(0.0, length2 - along * along)));
      stats.length_max = std::max(stats.length_max, std::sqrt(length2));
      stats.sum_squares += length2;
    }
  }
  return Status::Ok();
}

// Parametric channels (a, b, n) are not lengths: D = a dP/du + b dP/dv + n N. With s the largest
// |dP/du|, |dP/dv| over the face's samples and N orthogonal to both,
// |dD|^2 <= 2 s^2 (da^2 + db^2) + dn^2, so the analyzer's vector norm over (k a, k b, n) with
// k >= sqrt(2) s bounds the object-space error. k is a power of two, so scaling is exact.
float ParametricScale(const VectorScratch& w) {
  double s2 = 0;
  for (std::size_t k = 0; k + 2 < w.du.size(); k += 3) {
    s2 = std::max({s2,
                   static_cast<double>(w.du[k]) * w.du[k] + w.du[k + 1] * w.du[k + 1] +
                       w.du[k + 2] * w.du[k + 2],
                   static_cast<double>(w.dv[k]) * w.dv[k] + w.dv[k + 1] * w.dv[k + 1] +
                       w.dv[k + 2] * w.dv[k + 2]});
  }
  const double k = std::sqrt(2 * s2);
  if (!(k > 0) || !std::isfinite(k)) return 1.0f;
  return std::ldexp(1.0f, std::clamp(static_cast<int>(std::ceil(std::log2(k))), -60, 60));
}

// Multiplies the first two of every three channels by `scale`.
void ScaleTangentChannels(std::span<float> channels, float scale) {
  if (scale == 1.0f) return;
  for (std::size_t k = 0; k + 2 < channels.size(); k += 3) {
    channels[k] *= scale;
    channels[k + 1] *= scale;
  }
}

// Face `face` at no less than `least_log2` (log2 per side; a least resolution beyond the
// planned samples takes as many samples) into `out` as the map stores it: 3 interleaved
// channels, one texel for a constant face.
Status ProcessVectorFace(PtexFaceId face, VectorSpace space, const ExtractInputs& inputs,
                         const ExtractSettings& settings,
                         const SculptCorrespondence& correspondence, std::array<int, 2> least_log2,
                         VectorScratch& w, VectorFaceStats& stats, KeptFace& out) {
  out.kept = true;
  if (inputs.surface.is_hole(face)) {
    out.ulog2 = out.vlog2 = 0;
    out.texels.assign(3, 0.0f);
    return Status::Ok();
  }
  // With pinned edges (WatertightEdges::kAll), a face whose samples are too coarse to hold
  // them (the vector changes too fast across the outermost half texel) is sampled again at
  // twice the rate, up to the finest sampling allowed (ExtractSettings::max_samples_log2), as
  // the scalar edge rounds do.
  const int planned = settings.plan.log2[static_cast<std::size_t>(face.value)];
  const int max_log2 = std::max<int>(planned, settings.max_samples_log2);
  SpectralOptions spectral = settings.spectral;
  spectral.min_ulog2 = least_log2[0];
  spectral.min_vlog2 = least_log2[1];
  std::optional<SpectralVectorFace> analysed;
  float scale = 1.0f;
  for (int log2 = std::max({planned, least_log2[0], least_log2[1]});; ++log2) {
    const int n = 1 << log2;
    ThreadCpuStopwatch limit_clock;
    DISPEX_RETURN_IF_ERROR(
        SampleFace(face, n, space, settings.interpolate, inputs, correspondence, w, stats));
    w.cpu_limit += limit_clock.seconds();
    ThreadCpuStopwatch spectral_clock;
    scale = space == VectorSpace::kParametric ? ParametricScale(w) : 1.0f;
    ScaleTangentChannels(w.channels, scale);
    auto result = w.analyzer.Analyze(w.channels, n, n, spectral);
    if (!result.ok()) {
      return Status::Error(fmt::format("{}: Ptex face {}: {}", inputs.sculpt.source, face.value,
                                       result.status().message()));
    }
    analysed.emplace(std::move(*result));
    w.cpu_spectral += spectral_clock.seconds();
    if (!analysed->stats.edge_limited || log2 >= max_log2) break;
  }
  // The texels as the map stores them, so that a face copied from it later (incremental
  // extraction) is written from the same values.
  out.texels.assign(analysed->texels.begin(), analysed->texels.end());
  ScaleTangentChannels(out.texels, 1.0f / scale);
  RoundToDataType(settings.data_type, out.texels);
  out.ulog2 = static_cast<std::int8_t>(analysed->ulog2);
  out.vlog2 = static_cast<std::int8_t>(analysed->vlog2);
  stats.spectral = analysed->stats;
  stats.ulog2 = out.ulog2;
  stats.vlog2 = out.vlog2;
  return Status::Ok();
}

// A face as ProcessVectorFace or ReadVectorFace left it; one texel is a constant face.
Status WriteVectorFace(PtexFaceId face, const ExtractInputs& inputs, const KeptFace& kept,
                       PtexWriter& writer) {
  const PtexFaceInfo info = FaceInfo(inputs, face, kept.ulog2, kept.vlog2);
  return kept.texels.size() == 3 ? writer.SetConstantFace(face, info, kept.texels)
                                 : writer.SetFace(face, info, kept.texels);
}

// Per Ptex face, what its texels are made from: the settings (SettingsKey) and vector space,
// its limit patch and sub-face, its planned samples, and the positions of its grid of sculpt
// vertices in grid order (a face reads the sculpt only inside its own cells, SculptPointAt).
std::vector<Hash128> VectorFaceKeys(const ExtractInputs& inputs, const ExtractSettings& settings,
                                    const SculptCorrespondence& correspondence, VectorSpace space) {
  const LimitSurface& surface = inputs.surface;
  const std::vector<BaseFacePatch> patches = BaseFacePatches(surface);
  Hasher global;
  global.Add(SettingsKey(settings)).Add(std::string_view("vector")).Add(VectorSpaceName(space));
  const Hash128 settings_key = global.Digest();
  std::vector<Hash128> keys(static_cast<std::size_t>(surface.num_ptex_faces()));
  struct Scratch {
    std::vector<VertexId> ids;
    std::vector<int> faces;
    std::vector<Float3> points;
  };
  tbb::enumerable_thread_specific<Scratch> scratches;
  tbb::parallel_for(std::size_t{0}, keys.size(), [&](std::size_t f) {
    Hasher h;
    h.Add(settings_key);
    AddFacePatchKey(h, surface, patches, settings, f);
    const PtexFaceId face(static_cast<int>(f));
    Scratch& w = scratches.local();
    if (settings.interpolate) {
      AddFieldKey(h, inputs, patches, face.value, w.ids, w.faces, w.points);
    } else {
      AddGridKey(h, inputs.sculpt, correspondence.grid_size(face), correspondence.grid(face),
                 w.points);
    }
    keys[f] = h.Digest();
  });
  return keys;
}

// Face f of `previous`, as it is stored.
Status ReadVectorFace(PtexFaceId face, const PreviousMap& previous, KeptFace& out) {
  DISPEX_RETURN_IF_ERROR(previous.ReadTexels(static_cast<std::size_t>(face.value), out));
  out.kept = true;
  return Status::Ok();
}

// Kept face f's D in object space at its texel centres, one array per component of `map`:
// an object map's channels as they are; a tangent or parametric map's turned by the frame at
// each texel centre (a constant face's too, as D turns over it), as verify measures them.
Status EdgeComponents(PtexFaceId face, VectorSpace space, const ExtractInputs& inputs,
                      const KeptFace& kept, VectorScratch& w, EdgeRoundsMap& map) {
  const auto f = static_cast<std::size_t>(face.value);
  const std::size_t stored = kept.texels.size() / 3;
  if (space == VectorSpace::kObject || inputs.surface.is_hole(face)) {
    for (std::size_t c = 0; c < 3; ++c) {
      std::vector<float>& out = map.components[c][f];
      out.resize(stored);
      for (std::size_t i = 0; i < stored; ++i) out[i] = kept.texels[3 * i + c];
    }
    return Status::Ok();
  }
  const int ures = 1 << kept.ulog2, vres = 1 << kept.vlog2;
  const std::size_t count = static_cast<std::size_t>(ures) * static_cast<std::size_t>(vres);
  for (auto* buffer : {&w.positions, &w.normals, &w.du, &w.dv}) buffer->resize(3 * count);
  DISPEX_RETURN_IF_ERROR(
      w.evaluator.EvaluateGridFrames(face, ures, vres, {w.positions, w.normals, w.du, w.dv}));
  for (std::size_t c = 0; c < 3; ++c) map.components[c][f].resize(count);
  VectorsFromChannels(space, w.du, w.dv, w.normals, kept.texels, map.components[0][f],
                      map.components[1][f], map.components[2][f]);
  return Status::Ok();
}

// The watertight-edges stage for vector maps (RaiseEdgeResolutions): D's steps where faces
// meet, measured in object space; raised faces extracted again into `kept`.
Status HoldVectorEdges(VectorSpace space, const ExtractInputs& inputs,
                       const ExtractSettings& settings, const SculptCorrespondence& correspondence,
                       tbb::enumerable_thread_specific<VectorScratch>& scratches,
                       std::vector<KeptFace>& kept, std::vector<VectorFaceStats>& stats,
                       std::vector<std::uint8_t>& copied, ExtractReport& report) {
  const std::size_t n = kept.size();
  EdgeRoundsMap map;
  map.faces = inputs.faces;
  map.components.assign(3, std::vector<std::vector<float>>(n));
  map.skip_faces.resize(n);
  report.texels_before_edges = 0;
  // An object map's components are its channels: while the rounds run they hold the texels
  // (the kept copy is let go, and interleaved again at the end), so the map is held once.
  const bool held_as_components = space == VectorSpace::kObject;
  auto update = [&](PtexFaceId face, VectorScratch& w) {
    const auto f = static_cast<std::size_t>(face.value);
    map.faces[f].ulog2 = kept[f].ulog2;
    map.faces[f].vlog2 = kept[f].vlog2;
    DISPEX_RETURN_IF_ERROR(EdgeComponents(face, space, inputs, kept[f], w, map));
    if (held_as_components) std::vector<float>().swap(kept[f].texels);
    return Status::Ok();
  };
  for (std::size_t f = 0; f < n; ++f) {
    map.skip_faces[f] = inputs.surface.is_hole(PtexFaceId(static_cast<int>(f)));
    if (!map.skip_faces[f]) report.texels_before_edges += kept[f].texels.size() / 3;
  }
  DISPEX_RETURN_IF_ERROR(ForEachFace(
      static_cast<int>(n), [](int k) { return k; }, scratches, nullptr, update));
  const Status raised = RaiseEdgeResolutions(
      inputs, settings, map,
      [&](std::span<const int> redo, std::span<const std::array<int, 2>> least, EdgeRoundsMap&) {
        auto face_of = [&](int k) { return redo[static_cast<std::size_t>(k)]; };
        return ForEachFace(
            static_cast<int>(redo.size()), face_of, scratches, nullptr,
            [&](PtexFaceId face, VectorScratch& w) {
              const auto f = static_cast<std::size_t>(face.value);
              copied[f] = 0;
              stats[f] = {};
              DISPEX_RETURN_IF_ERROR(ProcessVectorFace(
                  face, space, inputs, settings, correspondence, least[f], w, stats[f], kept[f]));
              return update(face, w);
            });
      },
      report);
  DISPEX_RETURN_IF_ERROR(raised);
  if (!held_as_components) return Status::Ok();
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t f) {
    const std::size_t count = map.components[0][f].size();
    kept[f].texels.resize(3 * count);
    for (std::size_t c = 0; c < 3; ++c) {
      std::vector<float>& component = map.components[c][f];
      for (std::size_t i = 0; i < count; ++i) kept[f].texels[3 * i + c] = component[i];
      std::vector<float>().swap(component);
    }
  });
  return Status::Ok();
}

// Every face into `writer`: copied from `previous` where its key is unchanged and its texels
// there are its first pass, else extracted; then the edge rounds. `stats`: each face's as
// written; `first_pass`: before the rounds raised any (the map's records, so that a later
// incremental run copies a face only where a full extraction would start from the same).
Status ProcessVectorFaces(const ExtractOptions& options, const ExtractInputs& inputs,
                          const ExtractSettings& settings,
                          const SculptCorrespondence& correspondence, std::span<const Hash128> keys,
                          const PreviousMap* previous, PtexWriter& writer,
                          std::vector<VectorFaceStats>& stats,
                          std::vector<VectorFaceStats>& first_pass, ExtractReport& report) {
  const VectorSpace space = *options.vector;
  const int num_faces = inputs.surface.num_ptex_faces();
  stats.assign(static_cast<std::size_t>(num_faces), {});
  std::vector<std::uint8_t> copied(static_cast<std::size_t>(num_faces), 0);
  // Faces are written as they are made, or kept for the edge rounds and written after them.
  const bool rounds = settings.watertight != WatertightEdges::kOff;
  std::vector<KeptFace> kept(rounds ? static_cast<std::size_t>(num_faces) : 0);
  tbb::enumerable_thread_specific<VectorScratch> scratches(
      [&] { return VectorScratch(inputs.surface); });
  auto write = [&](PtexFaceId face, const KeptFace& made, VectorScratch& w) {
    ThreadCpuStopwatch write_clock;
    Status written = WriteVectorFace(face, inputs, made, writer);
    w.cpu_write += write_clock.seconds();
    return written;
  };
  Progress bar("extract", static_cast<std::uint64_t>(num_faces), "faces", options.progress,
               options.progress_counter);
  Status status = ForEachFace(
      num_faces, [](int k) { return k; }, scratches, &bar,
      [&](PtexFaceId face, VectorScratch& w) {
        const auto f = static_cast<std::size_t>(face.value);
        KeptFace& made = rounds ? kept[f] : w.face;
        if (previous != nullptr && previous->Reusable(f, keys[f])) {
          stats[f] = previous->vector_record(f);
          copied[f] = 1;
          DISPEX_RETURN_IF_ERROR(ReadVectorFace(face, *previous, made));
        } else {
          DISPEX_RETURN_IF_ERROR(ProcessVectorFace(face, space, inputs, settings, correspondence,
                                                   {0, 0}, w, stats[f], made));
        }
        return rounds ? Status::Ok() : write(face, made, w);
      });
  bar.Finish();
  DISPEX_RETURN_IF_ERROR(status);
  first_pass = stats;
  if (rounds) {
    DISPEX_RETURN_IF_ERROR(HoldVectorEdges(space, inputs, settings, correspondence, scratches, kept,
                                           stats, copied, report));
    DISPEX_RETURN_IF_ERROR(ForEachFace(
        num_faces, [](int k) { return k; }, scratches, nullptr,
        [&](PtexFaceId face, VectorScratch& w) {
          return write(face, kept[static_cast<std::size_t>(face.value)], w);
        }));
  }
  report.faces_copied = std::count(copied.begin(), copied.end(), 1);
  for (const VectorScratch& w : scratches) {
    report.cpu_limit += w.cpu_limit;
    report.cpu_spectral += w.cpu_spectral;
    report.cpu_compress += w.cpu_write;
    report.fallback_normals += w.evaluator.stats().fallback_normals;
  }
  return Status::Ok();
}

// The report's totals: samples, resolutions, and the displacement's statistics (its normal
// component as the scalar map's, and how far it leaves the normal).
void SumVectorFaces(const ExtractInputs& inputs, const ExtractSettings& settings,
                    std::span<const VectorFaceStats> stats, ExtractReport& report) {
  double sum_squares = 0;
  bool first = true;
  for (int f = 0; f < inputs.surface.num_ptex_faces(); ++f) {
    if (inputs.surface.is_hole(PtexFaceId(f))) continue;
    const VectorFaceStats& r = stats[static_cast<std::size_t>(f)];
    report.oversample_faces[settings.plan.log2[static_cast<std::size_t>(f)]]++;
    report.samples += r.samples;
    report.spectral.Add(r.spectral, r.ulog2, r.vlog2);
    sum_squares += r.sum_squares;
    report.displacement_min =
        first ? r.normal_min : std::min<double>(report.displacement_min, r.normal_min);
    report.displacement_max =
        first ? r.normal_max : std::max<double>(report.displacement_max, r.normal_max);
    report.vector_length_max = std::max(report.vector_length_max, r.length_max);
    report.vector_tangential_max = std::max(report.vector_tangential_max, r.tangential_max);
    first = false;
  }
  report.displacement_rms =
      report.samples ? std::sqrt(sum_squares / static_cast<double>(report.samples)) : 0;
}

StatusOr<PtexWriter> CreateVectorMap(const ExtractOptions& options, const ExtractInputs& inputs) {
  PtexWriterOptions writer_options;
  writer_options.data_type = options.data_type;
  writer_options.compression_level = options.compression_level;
  writer_options.num_channels = 3;
  writer_options.edge_filter = *options.vector == VectorSpace::kObject
                                   ? PtexEdgeFilterMode::kNone
                                   : PtexEdgeFilterMode::kTangentVector;
  return PtexWriter::Create(options.output_path, writer_options, inputs.surface.num_ptex_faces());
}

}  // namespace

StatusOr<ExtractReport> ExtractVectorShape(const ExtractOptions& options, ExtractInputs inputs,
                                           ExtractReport report, const Stopwatch& total_clock,
                                           const PreviousMap* previous) {
  report.vector_space = std::string(VectorSpaceName(*options.vector));
  Stopwatch match_clock;
  MatchOptions match;
  match.threads = report.threads;
  DISPEX_ASSIGN_OR_RETURN(match.max_offset, OffsetBound(options, report.base_diagonal));
  auto correspondence = MatchSculpt(match, inputs, report);
  if (!correspondence.ok()) {
    return Status::Error(fmt::format(
        "vector displacement reads the sculpt through its correspondence with the base, and "
        "there is none: {}",
        correspondence.status().message()));
  }
  report.t_match = match_clock.seconds();
  report.mapping_levels = correspondence->levels;
  report.mapping_max_offset = correspondence->max_offset;
  report.mapping_rms_offset = correspondence->rms_offset;
  report.search_distance = match.max_offset;
  inputs.interpolate = options.method != ExtractMethod::kMapping;
  // `correspondence` outlives every use of the grids: the run ends in this function.
  if (inputs.interpolate) {
    inputs.grids = std::make_unique<CorrespondenceGrids>(*correspondence, inputs.faces);
  }
  report.method = inputs.interpolate ? ExtractMethod::kInterpolate : ExtractMethod::kMapping;
  report.plan.method = report.method;
  report.plan.tracer = ExtractPlan::Tracer::kNone;
  DISPEX_ASSIGN_OR_RETURN(ExtractSettings settings, ResolveSettings(options, inputs, report));
  if (options.check_inputs) {
    const CorrespondenceGrids grids(*correspondence, inputs.faces);
    DISPEX_ASSIGN_OR_RETURN(PlacementFit fit, MeasurePlacement(inputs, &grids, &settings));
    DISPEX_RETURN_IF_ERROR(CheckPlacement(fit, report.base_diagonal, inputs.sculpt.source));
  }
  if (CancelRequested()) return Cancelled();

  Stopwatch keys_clock;
  const std::vector<Hash128> keys =
      VectorFaceKeys(inputs, settings, *correspondence, *options.vector);
  report.t_keys = keys_clock.seconds();
  PlanFaces(report.plan, inputs, keys, previous, {});
  if (options.plan_only) {
    report.peak_rss_bytes = PeakResidentBytes();
    report.t_total = total_clock.seconds();
    return report;
  }
  DISPEX_ASSIGN_OR_RETURN(PtexWriter writer, CreateVectorMap(options, inputs));
  Stopwatch faces_clock;
  std::vector<VectorFaceStats> stats, first_pass;
  DISPEX_RETURN_IF_ERROR(ProcessVectorFaces(options, inputs, settings, *correspondence, keys,
                                            previous, writer, stats, first_pass, report));
  report.faces_extracted = inputs.surface.num_ptex_faces() -
                           inputs.surface.stats().hole_ptex_faces - report.faces_copied;
  report.t_sample_trace = faces_clock.seconds();
  SumVectorFaces(inputs, settings, stats, report);

  Stopwatch write_clock;
  DISPEX_RETURN_IF_ERROR(AddExtractMetaData(writer, inputs.base, report, {}, {}, {}));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData(kFaceKeysMetaKey, std::span<const std::int8_t>(EncodeFaceKeys(keys))));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData(kVectorFaceRecordsMetaKey,
                         std::span<const std::int8_t>(EncodeVectorFaceRecords(first_pass))));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(std::string(kVectorSpaceMetaKey), report.vector_space));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(std::string(kVectorChannelsMetaKey),
                                            std::string(VectorSpaceChannels(*options.vector))));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("dispex:frame", std::string(VectorSpaceFrame(*options.vector))));
  if (CancelRequested()) return Cancelled();
  DISPEX_RETURN_IF_ERROR(writer.Finish());
  report.t_write = write_clock.seconds();
  std::error_code ec;
  report.bytes_written = std::filesystem::file_size(report.output_path, ec);
  if (!options.uv_maps_dir.empty()) {
    DISPEX_RETURN_IF_ERROR(WriteUvMaps(options, inputs, settings, report, &*correspondence));
  }
  report.peak_rss_bytes = PeakResidentBytes();
  report.t_total = total_clock.seconds();
  return report;
}

}  // namespace dispex::extract
