#include "extract/extract_settings.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>

#include "core/system.h"
#include "extract/coarse_sampling.h"
#include "extract/incremental/ray_cache.h"
#include "extract/mapping/extract_mapping.h"

namespace dispex::extract {

namespace {

// The longer search for samples that missed: this many times the automatic search distance.
constexpr double kRetryFactor = 4.0;
// Through the correspondence, the longest hit kept over the largest vertex offset the match
// measured (ExtractReport::method.sheet_bound).
constexpr double kSheetFactor = 2.0;

// Automatic values measured over the whole sculpt are kept to a few significant bits, so that
// an edit of a small part of the sculpt leaves them, and with them every face it does not
// reach, unchanged (incremental extraction). The median edge moves by tiny steps (to the next
// of millions of lengths): 8 bits, a change of at most 0.2% of the tolerance. A percentile of
// the sparse distances jumps from one sample to the next: 4 bits, rounded up, so the search
// reaches at most 1/8 farther.
constexpr int kToleranceBits = 8;
constexpr int kSearchDistanceBits = 4;

double RoundToBits(double x, int bits, bool up) {
  int exponent = 0;
  const double mantissa = std::frexp(x, &exponent);  // in [0.5, 1)
  const double scaled = std::ldexp(mantissa, bits);
  return std::ldexp(up ? std::ceil(scaled) : std::nearbyint(scaled), exponent - bits);
}

Status ResolveTolerance(const ExtractOptions& options, const Mesh& sculpt, ExtractReport& report) {
  report.inputs.sculpt_median_edge = MedianEdgeLength(sculpt);
  report.settings.tolerance_auto = options.tolerance <= 0;
  report.settings.tolerance =
      report.settings.tolerance_auto
          ? RoundToBits(options.tolerance_fraction * report.inputs.sculpt_median_edge,
                        kToleranceBits,
                        /*up=*/false)
          : options.tolerance;
  if (!(report.settings.tolerance > 0)) {
    return Status::Error(
        fmt::format("{}: cannot derive a tolerance (median edge length {}); "
                    "set tolerance",
                    options.sculpt_path, report.inputs.sculpt_median_edge));
  }
  return Status::Ok();
}

// EstimateSearchDistance's rule over each long ray's nearest |t| (infinity: no hit).
StatusOr<SearchDistanceEstimate> EstimateFromNearest(std::span<const float> nearest,
                                                     double diagonal) {
  std::vector<double> abs_t;
  abs_t.reserve(nearest.size());
  for (float t : nearest) {
    if (std::isfinite(t)) abs_t.push_back(static_cast<double>(t));
  }
  return SearchDistanceFromHits(std::move(abs_t), nearest.size(), diagonal);
}

// The long rays' nearest |t| over the sculpt through rays: by the tracer of the whole sculpt;
// else from the rays of the run before (inputs.ray_cache_path) where that file is for these
// rays; else over the sculpt in parts, one BVH at a time (NearestHitsInParts). An incremental
// run keeps them, with the sculpt's cell keys, for the next (ray_cache.h). Every way gives the
// same |t|, those of a BVH of the whole sculpt.
StatusOr<std::vector<float>> NearestHits(const ExtractInputs& inputs, const LongRays& rays,
                                         ExtractReport& report) {
  const bool cache = !inputs.ray_cache_path.empty();
  std::optional<RayGrid> grid;
  RayCache now;
  if (cache) {
    grid.emplace(rays);
    now.rays_key = RaysKey(rays, *grid);
    KeySculptCells(inputs.sculpt, *grid, now);
  }
  // (In parts, a memory limit holds: the rays near an edit could reach all of the sculpt.)
  std::optional<RayCache> before;
  if (cache && !inputs.tracer && inputs.sculpt_parts <= 1) {
    before = ReadRayCache(inputs.ray_cache_path, now.rays_key);
  }
  if (inputs.tracer) {
    now.nearest.assign(rays.origins.size(), std::numeric_limits<float>::infinity());
    now.side.assign(rays.origins.size(), 0);
    LowerNearestHits(*inputs.tracer, rays.origins, rays.normals, rays.length, now.nearest,
                     now.side);
    DISPEX_RETURN_IF_ERROR(inputs.tracer->status());
  } else if (before) {
    std::int64_t recast = 0;
    DISPEX_RETURN_IF_ERROR(
        UpdateNearestHits(inputs.sculpt, inputs.tracer_options, rays, *grid, *before, now, recast));
    report.incremental.search_rays_recast = recast;
    report.incremental.search_rays = static_cast<std::int64_t>(rays.origins.size());
  } else {
    report.plan.search_estimate_parts = std::max(inputs.sculpt_parts, inputs.estimate_parts);
    now.side.assign(cache ? rays.origins.size() : 0, 0);
    DISPEX_ASSIGN_OR_RETURN(
        now.nearest, NearestHitsInParts(inputs, report.plan.search_estimate_parts, rays.origins,
                                        rays.normals, rays.length, now.side));
  }
  if (cache && !WriteRayCache(inputs.ray_cache_path, now)) {
    report.warnings.push_back(
        fmt::format("{}: cannot keep the search distance's rays there for the next run (cache_dir)",
                    inputs.ray_cache_path));
  }
  return std::move(now.nearest);
}

StatusOr<SearchDistanceEstimate> EstimateByRays(const ExtractInputs& inputs,
                                                const CoarseSampling& coarse, double diagonal,
                                                ExtractReport& report) {
  const SearchDistanceOptions options;
  const LongRays rays{coarse.points, coarse.normals,
                      static_cast<float>(options.ray_fraction * diagonal)};
  DISPEX_ASSIGN_OR_RETURN(const std::vector<float> nearest, NearestHits(inputs, rays, report));
  return EstimateFromNearest(nearest, diagonal);
}

Status ResolveSearchDistances(const ExtractOptions& options, const ExtractInputs& inputs,
                              const CoarseSampling& coarse, ExtractReport& report) {
  report.settings.search_distance_auto =
      options.search_distance.kind == SearchDistanceSpec::Kind::kAuto;
  if (report.settings.search_distance_auto) {
    auto estimate = inputs.mapping
                        ? EstimateSearchDistanceMapped(inputs, coarse, report.inputs.base_diagonal)
                        : EstimateByRays(inputs, coarse, report.inputs.base_diagonal, report);
    if (!estimate.ok()) {
      return Status::Error(StatusCode::kMismatch,
                           fmt::format("{} and {} do not overlap: {}", options.base_path,
                                       options.sculpt_path, estimate.status().message()));
    }
    report.settings.search_estimate = *estimate;
    report.settings.search_distance = std::min(
        RoundToBits(estimate->distance, kSearchDistanceBits, /*up=*/true), estimate->ray_length);
  } else {
    DISPEX_ASSIGN_OR_RETURN(
        report.settings.search_distance,
        ResolveSearchDistance(options.search_distance, report.inputs.base_diagonal));
  }
  // With an automatic search distance, samples that missed get a second, longer search: the
  // sparse estimate can miss thin or strongly curved parts where the sculpt is farther from
  // the limit surface than almost everywhere else.
  report.sampling.retry_search_distance =
      report.settings.search_distance_auto
          ? std::max(report.settings.search_distance,
                     std::min(kRetryFactor * report.settings.search_distance,
                              report.settings.search_estimate.ray_length))
          : 0.0;
  // Through the correspondence, a hit farther than the match's own offsets is another sheet of
  // the sculpt (a crease corner's far side, a fold), not the one over the sample: a miss.
  // (Plus a median sculpt edge: the flat quads sag from their vertices by a fraction of one.)
  if (inputs.mapping != nullptr) {
    report.method.sheet_bound =
        kSheetFactor * report.method.max_offset + report.inputs.sculpt_median_edge;
    report.settings.search_distance =
        std::min(report.settings.search_distance, report.method.sheet_bound);
    report.sampling.retry_search_distance =
        std::min(report.sampling.retry_search_distance, report.method.sheet_bound);
  }
  return Status::Ok();
}

}  // namespace

StatusOr<ExtractSettings> ResolveSettings(const ExtractOptions& options,
                                          const ExtractInputs& inputs, ExtractReport& report) {
  Stopwatch clock;
  DISPEX_RETURN_IF_ERROR(ResolveTolerance(options, inputs.sculpt, report));
  ExtractSettings settings;
  {
    DISPEX_ASSIGN_OR_RETURN(CoarseSampling coarse, SampleCoarsely(inputs.surface));
    // Vector maps and interpolated ones read the sculpt through its correspondence: no rays,
    // no search distance.
    if (!options.vector && !inputs.interpolate) {
      DISPEX_RETURN_IF_ERROR(ResolveSearchDistances(options, inputs, coarse, report));
    }
    settings.plan =
        PlanOversampling(inputs.surface, inputs.sculpt, coarse.face_areas, options.oversample,
                         options.min_oversample, options.max_oversample);
  }
  report.sampling.oversample_subdivision_level = settings.plan.subdivision_level;
  report.times.search = clock.seconds();

  settings.search_distance = report.settings.search_distance;
  settings.query.distance = static_cast<float>(report.settings.search_distance);
  settings.query.policy = options.ray_policy;
  settings.retry_query = settings.query;
  settings.retry_query.distance = static_cast<float>(report.sampling.retry_search_distance);
  settings.mapping = inputs.mapping != nullptr;
  settings.interpolate = inputs.interpolate;
  settings.vector = options.vector;
  settings.spectral.rule = options.resolution_rule;
  settings.spectral.tolerance = report.settings.tolerance;
  settings.spectral.nonzero_threshold = options.nonzero_threshold;
  settings.spectral.fixed_ulog2 = options.fixed_ulog2;
  settings.spectral.fixed_vlog2 = options.fixed_vlog2;
  settings.holes = options.holes;
  settings.data_type = options.data_type;
  settings.watertight = options.resolution_rule == ResolutionRule::kErrorBound
                            ? options.watertight
                            : WatertightEdges::kOff;
  settings.edge_step_budget = report.settings.tolerance;
  settings.max_samples_log2 = std::bit_width(static_cast<unsigned>(options.max_oversample)) - 1;
  // For faces read on their own (kAll): edge texels hold the edge's values, and each side of
  // an edge stays within half the tolerance of them, so two faces meet within the tolerance.
  if (settings.watertight == WatertightEdges::kAll) {
    settings.spectral.pin_edges = true;
    settings.spectral.edge_tolerance = 0.5 * report.settings.tolerance;
  }
  report.edges.rule = settings.watertight;
  return settings;
}

}  // namespace dispex::extract
