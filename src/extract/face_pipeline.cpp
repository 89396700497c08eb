#include "extract/face_pipeline.h"

#include <fmt/format.h>

#include <algorithm>
#include <span>

#include "core/system.h"
#include "extract/vector_faces.h"

namespace dispex::extract {

namespace {

std::span<const Float3> AsFloat3(const std::vector<float>& v, std::size_t n) {
  return {reinterpret_cast<const Float3*>(v.data()), n};
}

const Tracer* TracerFor(const ExtractInputs& inputs, PtexFaceId face) {
  if (!inputs.tracer) return nullptr;
  if (!inputs.traced.empty() && !inputs.traced[static_cast<std::size_t>(face.value)]) {
    return nullptr;
  }
  return inputs.tracer.get();
}

// The same through the mapping; the samples it leaves undecided go to `tracer` as TraceRays
// traces them, or, without one, the face is left for later (result.needs_tracer).
std::int32_t TraceMappedSamples(PtexFaceId face, int n, const ExtractInputs& inputs,
                                const ExtractSettings& settings, std::size_t count, FaceScratch& w,
                                FaceResult& result) {
  const auto origins = AsFloat3(w.positions, count), normals = AsFloat3(w.normals, count);
  w.undecided.resize(count);
  TraceMapped(*inputs.mapping, inputs.sculpt, face, n, {}, origins, normals, settings.query,
              NormalHits{w.t, {}, w.flags}, w.undecided, w.mapping, w.mapping_counters);
  std::int32_t recovered = 0;
  if (settings.retry_query.distance > 0) {
    w.mapped_index.clear();
    for (std::size_t i = 0; i < count; ++i) {
      if (!w.undecided[i] && !(w.flags[i] & HitFlags::kHit)) {
        w.mapped_index.push_back(static_cast<std::int32_t>(i));
      }
    }
    if (!w.mapped_index.empty()) {
      w.mapped_t.resize(count);
      w.mapped_flags.resize(count);
      TraceMapped(*inputs.mapping, inputs.sculpt, face, n, w.mapped_index, origins, normals,
                  settings.retry_query, NormalHits{w.mapped_t, {}, w.mapped_flags}, w.undecided,
                  w.mapping, w.mapping_counters);
      for (const std::int32_t i : w.mapped_index) {
        const auto k = static_cast<std::size_t>(i);
        if (w.undecided[k] || !(w.mapped_flags[k] & HitFlags::kHit)) continue;
        w.t[k] = w.mapped_t[k];
        w.flags[k] = w.mapped_flags[k];
        ++recovered;
      }
    }
  }
  w.mapped_index.clear();
  for (std::size_t i = 0; i < count; ++i) {
    if (w.undecided[i]) w.mapped_index.push_back(static_cast<std::int32_t>(i));
  }
  result.fallback_samples = static_cast<std::int32_t>(w.mapped_index.size());
  if (w.mapped_index.empty()) return recovered;
  const Tracer* tracer = TracerFor(inputs, face);
  if (tracer == nullptr) {
    result.needs_tracer = true;
    return 0;
  }
  w.fallback_origins.clear();
  w.fallback_normals.clear();
  for (const std::int32_t i : w.mapped_index) {
    w.fallback_origins.push_back(origins[static_cast<std::size_t>(i)]);
    w.fallback_normals.push_back(normals[static_cast<std::size_t>(i)]);
  }
  w.fallback_t.resize(w.mapped_index.size());
  w.fallback_flags.resize(w.mapped_index.size());
  recovered += TraceRays(*tracer, settings, w.fallback_origins, w.fallback_normals, w.fallback_t,
                         w.fallback_flags, w);
  for (std::size_t k = 0; k < w.mapped_index.size(); ++k) {
    const auto i = static_cast<std::size_t>(w.mapped_index[k]);
    w.t[i] = w.fallback_t[k];
    w.flags[i] = w.fallback_flags[k];
  }
  return recovered;
}

// The sculpt's vertex heights interpolated at the n x n texel centres, as hits: no misses,
// none opposed.
Status InterpolateHeights(PtexFaceId face, int n, const ExtractInputs& inputs, FaceScratch& w) {
  DISPEX_RETURN_IF_ERROR(
      w.grid.Evaluate(face, *inputs.grids, inputs.sculpt, w.evaluator, /*normals=*/true));
  w.grid.SetSampling(n);
  for (int j = 0; j < n; ++j) {
    const double v = (j + 0.5) / n;
    for (int i = 0; i < n; ++i) {
      const auto k =
          static_cast<std::size_t>(j) * static_cast<std::size_t>(n) + static_cast<std::size_t>(i);
      const float t = static_cast<float>(w.grid.HeightAt((i + 0.5) / n, v));
      w.t[k] = t;
      // As a ray meets a sculpt facing the limit normal's way (TakeDistances).
      w.flags[k] = HitFlags::kHit | (t < 0 ? HitFlags::kNegative : HitFlags::kBackFace);
    }
  }
  return Status::Ok();
}

// Signed distances from the hits (0 where a ray missed), and the hit counts.
void TakeDistances(std::size_t count, FaceScratch& w, FaceStats& stats) {
  stats.samples = static_cast<std::int64_t>(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint8_t fl = w.flags[i];
    const bool hit = fl & HitFlags::kHit;
    w.valid[i] = hit;
    w.values[i] = hit ? w.t[i] : 0.0f;
    stats.misses += !hit;
    stats.hits_negative += hit && (fl & HitFlags::kNegative);
    // The sculpt faces the limit normal's way where it is met from behind along +n or from
    // the front along -n; the other way round it faces against it: a fold or another sheet.
    const bool negative = fl & HitFlags::kNegative, back = fl & HitFlags::kBackFace;
    stats.hits_opposed += hit && (negative == back);
  }
}

}  // namespace

// Rays along +-n from each origin; with a retry distance, the samples that missed are searched
// again that far. Returns how many the second search found.
std::int32_t TraceRays(const Tracer& tracer, const ExtractSettings& settings,
                       std::span<const Float3> origins, std::span<const Float3> normals,
                       std::span<float> t, std::span<std::uint8_t> flags, FaceScratch& w,
                       bool retry) {
  const std::size_t count = origins.size();
  tracer.TraceNormals(origins, normals, settings.query, NormalHits{t, {}, flags}, w.counters);
  if (!retry || !(settings.retry_query.distance > 0)) return 0;
  w.retry_origins.clear();
  w.retry_normals.clear();
  w.retry_index.clear();
  for (std::size_t i = 0; i < count; ++i) {
    if (flags[i] & HitFlags::kHit) continue;
    w.retry_index.push_back(static_cast<std::int32_t>(i));
    w.retry_origins.push_back(origins[i]);
    w.retry_normals.push_back(normals[i]);
  }
  if (w.retry_index.empty()) return 0;
  const std::size_t m = w.retry_index.size();
  w.retry_t.resize(m);
  w.retry_flags.resize(m);
  tracer.TraceNormals(w.retry_origins, w.retry_normals, settings.retry_query,
                      NormalHits{w.retry_t, {}, w.retry_flags}, w.counters);
  std::int32_t recovered = 0;
  for (std::size_t k = 0; k < m; ++k) {
    if (!(w.retry_flags[k] & HitFlags::kHit)) continue;
    const auto i = static_cast<std::size_t>(w.retry_index[k]);
    t[i] = w.retry_t[k];
    flags[i] = w.retry_flags[k];
    ++recovered;
  }
  return recovered;
}

StatusOr<FaceResult> ProcessFace(PtexFaceId face, const ExtractInputs& inputs,
                                 const ExtractSettings& settings, FaceScratch& w,
                                 std::array<int, 2> least_log2) {
  if (settings.vector) return ProcessVectorFace(face, inputs, settings, w, least_log2);
  FaceResult result;
  if (inputs.surface.is_hole(face)) return result;
  FaceStats& r = result.stats;
  const std::uint64_t rays_before = w.counters.rays_cast;
  const std::int64_t fallbacks_before = w.evaluator.stats().fallback_normals;
  // A least resolution beyond the planned samples takes as many samples.
  const int n = 1 << std::max<int>({settings.plan.log2[static_cast<std::size_t>(face.value)],
                                    least_log2[0], least_log2[1]});
  const std::size_t count = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  w.positions.resize(3 * count);
  w.normals.resize(3 * count);
  w.t.resize(count);
  w.flags.resize(count);
  w.values.resize(count);
  w.valid.resize(count);

  ThreadCpuStopwatch step;
  if (settings.interpolate) {
    DISPEX_RETURN_IF_ERROR(InterpolateHeights(face, n, inputs, w));
    w.cpu_limit += step.seconds();
  } else {
    DISPEX_RETURN_IF_ERROR(w.evaluator.EvaluateGrid(face, n, n, w.positions, w.normals));
    w.cpu_limit += step.seconds();
    step.Reset();
    if (inputs.mapping) {
      r.recovered = TraceMappedSamples(face, n, inputs, settings, count, w, result);
    } else {
      // A tracer of the first search's reach only answers the retry for no sample: a face
      // with a miss waits for one of the retry's reach (WidenToRetryReach).
      const bool first_only = inputs.first_search_only && settings.retry_query.distance > 0;
      r.recovered = TraceRays(*inputs.tracer, settings, AsFloat3(w.positions, count),
                              AsFloat3(w.normals, count), w.t, w.flags, w, !first_only);
      result.needs_tracer =
          first_only && std::any_of(w.flags.begin(), w.flags.end(),
                                    [](std::uint8_t f) { return !(f & HitFlags::kHit); });
    }
    w.cpu_trace += step.seconds();
  }
  if (result.needs_tracer) return result;
  r.rays = static_cast<std::int64_t>(w.counters.rays_cast - rays_before);
  r.fallback_normals =
      static_cast<std::int32_t>(w.evaluator.stats().fallback_normals - fallbacks_before);
  TakeDistances(count, w, r);

  if (r.misses > 0) {
    if (settings.holes == HolePolicy::kFail) {
      return Status::Error(StatusCode::kMismatch,
                           fmt::format("Ptex face {}: {} of {} rays missed the sculpt within the "
                                       "search distance {:.6g} (holes = fail)",
                                       face.value, r.misses, count, settings.search_distance))
          .WithFace(face.value);
    }
    if (r.misses == static_cast<std::int32_t>(count) && settings.holes == HolePolicy::kFill) {
      r.all_missed = true;
      result.kind = FaceResult::Kind::kAllMissed;
      return result;
    }
    if (settings.holes == HolePolicy::kFill) {
      r.filled = FillHolesPullPush(w.values.data(), w.valid.data(), n, n, w.pull_push);
    }
  }
  r.min = *std::min_element(w.values.begin(), w.values.end());
  r.max = *std::max_element(w.values.begin(), w.values.end());
  for (float v : w.values) r.sum_squares += double(v) * double(v);
  result.edge_means = ComputeEdgeMeans(w.values.data(), n, n);

  step.Reset();
  SpectralOptions spectral = settings.spectral;
  spectral.min_ulog2 = least_log2[0];
  spectral.min_vlog2 = least_log2[1];
  DISPEX_ASSIGN_OR_RETURN(SpectralFace analysed, w.analyzer.Analyze(w.values, n, n, spectral));
  w.cpu_spectral += step.seconds();
  r.spectral = analysed.stats;
  r.ulog2 = static_cast<std::int8_t>(analysed.ulog2);
  r.vlog2 = static_cast<std::int8_t>(analysed.vlog2);
  result.kind = FaceResult::Kind::kAnalysed;
  result.ulog2 = analysed.ulog2;
  result.vlog2 = analysed.vlog2;
  w.constant[0] = analysed.constant_value;
  result.texels =
      analysed.constant ? std::span<const float>(w.constant.data(), 1) : analysed.texels;
  return result;
}

}  // namespace dispex::extract
