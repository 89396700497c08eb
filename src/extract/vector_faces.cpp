#include "extract/vector_faces.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "core/system.h"
#include "core/vec3.h"
#include "dispex/correspondence.h"
#include "dispex/spectral.h"
#include "dispex/vector_space.h"
#include "extract/incremental/field_keys.h"
#include "extract/mapping/extract_mapping.h"
#include "extract/mapping/vertex_displacements.h"
#include "extract/process_faces.h"

namespace dispex::extract {

namespace {

// D at the face's n x n texel centres, in the map's space, into w.channels: the sculpt's vertex
// displacements interpolated (`interpolate`, vertex_displacements.h), or the sculpt's quads
// read bilinearly minus the limit point.
Status SampleFace(PtexFaceId face, int n, VectorSpace space, bool interpolate,
                  const ExtractInputs& inputs, const SculptCorrespondence& correspondence,
                  FaceScratch& w, FaceStats& stats) {
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
  stats.min = std::numeric_limits<float>::infinity();
  stats.max = -std::numeric_limits<float>::infinity();
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
      stats.min = std::min(stats.min, static_cast<float>(along));
      stats.max = std::max(stats.max, static_cast<float>(along));
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
float ParametricScale(const FaceScratch& w) {
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

}  // namespace

Status MatchVectorSculpt(const ExtractOptions& options, ExtractInputs& inputs,
                         ExtractReport& report) {
  report.displacement.vector_space = std::string(VectorSpaceName(*options.vector));
  Stopwatch clock;
  MatchOptions match;
  match.threads = report.settings.threads;
  match.vertex_homes = false;
  DISPEX_ASSIGN_OR_RETURN(match.max_offset, OffsetBound(options, report.inputs.base_diagonal));
  auto correspondence = MatchSculpt(options, match, inputs, report);
  if (!correspondence.ok()) {
    return Status::Error(fmt::format(
        "vector displacement reads the sculpt through its correspondence with the base, and "
        "there is none: {}",
        correspondence.status().message()));
  }
  report.times.match = clock.seconds();
  report.method.levels = correspondence->levels;
  report.method.max_offset = correspondence->max_offset;
  report.method.rms_offset = correspondence->rms_offset;
  report.settings.search_distance = match.max_offset;
  inputs.correspondence = std::make_unique<SculptCorrespondence>(std::move(*correspondence));
  inputs.interpolate = options.method != ExtractMethod::kMapping;
  if (inputs.interpolate) {
    inputs.grids = std::make_unique<CorrespondenceGrids>(*inputs.correspondence, inputs.faces);
  }
  report.method.used = inputs.interpolate ? ExtractMethod::kInterpolate : ExtractMethod::kMapping;
  return Status::Ok();
}

StatusOr<FaceResult> ProcessVectorFace(PtexFaceId face, const ExtractInputs& inputs,
                                       const ExtractSettings& settings, FaceScratch& w,
                                       std::array<int, 2> least_log2) {
  FaceResult result;
  if (inputs.surface.is_hole(face)) return result;
  const VectorSpace space = *settings.vector;
  FaceStats& stats = result.stats;
  const std::int64_t fallbacks_before = w.evaluator.stats().fallback_normals;
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
        SampleFace(face, n, space, settings.interpolate, inputs, *inputs.correspondence, w, stats));
    w.cpu_limit += limit_clock.seconds();
    ThreadCpuStopwatch spectral_clock;
    scale = space == VectorSpace::kParametric ? ParametricScale(w) : 1.0f;
    ScaleTangentChannels(w.channels, scale);
    auto analysis = w.vector_analyzer.Analyze(w.channels, n, n, spectral);
    if (!analysis.ok()) {
      return Status::Error(fmt::format("{}: Ptex face {}: {}", inputs.sculpt.source, face.value,
                                       analysis.status().message()));
    }
    analysed.emplace(std::move(*analysis));
    w.cpu_spectral += spectral_clock.seconds();
    if (!analysed->stats.edge_limited || log2 >= max_log2) break;
  }
  stats.fallback_normals =
      static_cast<std::int32_t>(w.evaluator.stats().fallback_normals - fallbacks_before);
  // The texels as the map stores them, so that a face copied from it later (incremental
  // extraction) is written from the same values.
  w.vector_texels.assign(analysed->texels.begin(), analysed->texels.end());
  ScaleTangentChannels(w.vector_texels, 1.0f / scale);
  RoundToDataType(settings.data_type, w.vector_texels);
  result.kind = FaceResult::Kind::kAnalysed;
  result.ulog2 = analysed->ulog2;
  result.vlog2 = analysed->vlog2;
  result.texels = w.vector_texels;
  stats.spectral = analysed->stats;
  stats.ulog2 = static_cast<std::int8_t>(analysed->ulog2);
  stats.vlog2 = static_cast<std::int8_t>(analysed->vlog2);
  return result;
}

FaceKeys VectorFaceKeys(const ExtractInputs& inputs, const ExtractSettings& settings,
                        const std::string& cache_folder) {
  const LimitSurface& surface = inputs.surface;
  const SculptCorrespondence& correspondence = *inputs.correspondence;
  const std::vector<BaseFacePatch> patches = BaseFacePatches(surface);
  Hasher global;
  global.Add(SettingsKey(settings))
      .Add(std::string_view("vector"))
      .Add(VectorSpaceName(*settings.vector));
  const Hash128 settings_key = global.Digest();
  FieldKeys fields;
  if (settings.interpolate) fields = ComputeFieldKeys(inputs, patches, cache_folder);
  FaceKeys out;
  out.keys.resize(static_cast<std::size_t>(surface.num_ptex_faces()));
  out.fields_kept = fields.kept;
  tbb::enumerable_thread_specific<std::vector<Float3>> scratches;
  tbb::parallel_for(std::size_t{0}, out.keys.size(), [&](std::size_t f) {
    Hasher h;
    h.Add(settings_key);
    AddFacePatchKey(h, surface, patches, settings, f);
    const PtexFaceId face(static_cast<int>(f));
    if (settings.interpolate) {
      h.Add(fields.keys[f]);
    } else {
      AddGridKey(h, inputs.sculpt, correspondence.grid_size(face), correspondence.grid(face),
                 scratches.local());
    }
    out.keys[f] = h.Digest();
  });
  return out;
}

Status VectorObjectComponents(PtexFaceId face, VectorSpace space, int ulog2, int vlog2,
                              std::span<const float> texels, FaceScratch& w,
                              std::array<std::vector<float>*, 3> out) {
  const int ures = 1 << ulog2, vres = 1 << vlog2;
  const std::size_t count = static_cast<std::size_t>(ures) * static_cast<std::size_t>(vres);
  for (auto* buffer : {&w.positions, &w.normals, &w.du, &w.dv}) buffer->resize(3 * count);
  DISPEX_RETURN_IF_ERROR(
      w.evaluator.EvaluateGridFrames(face, ures, vres, {w.positions, w.normals, w.du, w.dv}));
  for (std::vector<float>* component : out) component->resize(count);
  VectorsFromChannels(space, w.du, w.dv, w.normals, texels, *out[0], *out[1], *out[2]);
  return Status::Ok();
}

}  // namespace dispex::extract
