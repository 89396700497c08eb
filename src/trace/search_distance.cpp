// The search distance: parsing the user's spec, and the automatic estimate from how far the
// sculpt actually lies from the base limit surface (a high percentile of |t| of long rays
// from a sparse sample, times a safety factor; see EstimateSearchDistance in dispex/trace.h).
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <vector>

#include "dispex/trace.h"

namespace dispex {
namespace {

bool PositiveFinite(double x) {
  return std::isfinite(x) && x > 0;
}

// Nearest-rank percentile of sorted values: the smallest value with at least a fraction p of
// the values at or below it.
double Percentile(const std::vector<double>& sorted, double p) {
  const auto n = static_cast<double>(sorted.size());
  const auto rank = static_cast<std::size_t>(std::max(1.0, std::ceil(p * n)));
  return sorted[std::min(rank, sorted.size()) - 1];
}

}  // namespace

StatusOr<SearchDistanceSpec> ParseSearchDistance(std::string_view text) {
  if (text == "auto") return SearchDistanceSpec{};
  SearchDistanceSpec spec;
  std::string_view number = text;
  spec.kind = SearchDistanceSpec::Kind::kAbsolute;
  if (!number.empty() && number.back() == '%') {
    number.remove_suffix(1);
    spec.kind = SearchDistanceSpec::Kind::kRelative;
  }
  double value = 0;
  const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
  if (number.empty() || error != std::errc() || end != number.data() + number.size()) {
    return Status::Error(fmt::format(
        "search distance '{}' is not 'auto', a length (0.05) or a percentage of the base mesh's "
        "bounding-box diagonal (2%)",
        text));
  }
  if (!PositiveFinite(value)) {
    return Status::Error(fmt::format("search distance '{}' must be greater than 0", text));
  }
  spec.value = spec.kind == SearchDistanceSpec::Kind::kRelative ? value / 100 : value;
  return spec;
}

StatusOr<double> ResolveSearchDistance(const SearchDistanceSpec& spec, double base_diagonal) {
  if (spec.kind == SearchDistanceSpec::Kind::kAuto) {
    return Status::Error("the automatic search distance needs EstimateSearchDistance");
  }
  if (!PositiveFinite(spec.value)) {
    return Status::Error(fmt::format("search distance {} must be greater than 0", spec.value));
  }
  if (spec.kind == SearchDistanceSpec::Kind::kAbsolute) return spec.value;
  if (!PositiveFinite(base_diagonal)) {
    return Status::Error(
        fmt::format("a relative search distance needs a base mesh of non-zero size (diagonal {})",
                    base_diagonal));
  }
  return spec.value * base_diagonal;
}

namespace {

Status CheckEstimateOptions(double base_diagonal, const SearchDistanceOptions& options) {
  if (!PositiveFinite(base_diagonal)) {
    return Status::Error(fmt::format(
        "search distance estimate: the base mesh has no extent (diagonal {})", base_diagonal));
  }
  if (!PositiveFinite(options.ray_fraction) || !(options.percentile > 0) ||
      !(options.percentile <= 1) || !PositiveFinite(options.safety_factor) ||
      !(options.min_fraction >= 0) || !(options.min_fraction <= options.ray_fraction)) {
    return Status::Error(fmt::format(
        "search distance estimate: options out of range (ray fraction {}, percentile {}, safety "
        "factor {}, min fraction {})",
        options.ray_fraction, options.percentile, options.safety_factor, options.min_fraction));
  }
  return Status::Ok();
}

}  // namespace

StatusOr<SearchDistanceEstimate> SearchDistanceFromHits(std::vector<double> abs_t,
                                                        std::size_t samples, double base_diagonal,
                                                        const SearchDistanceOptions& options) {
  DISPEX_RETURN_IF_ERROR(CheckEstimateOptions(base_diagonal, options));
  SearchDistanceEstimate estimate;
  estimate.base_diagonal = base_diagonal;
  estimate.ray_length = options.ray_fraction * base_diagonal;
  estimate.samples = samples;
  estimate.percentile = options.percentile;
  estimate.hits = abs_t.size();
  if (abs_t.empty()) {
    return Status::Error(fmt::format(
        "search distance estimate: none of {} samples of the base surface hit the sculpt within "
        "{:g} ({:g}% of the base diagonal); is the sculpt aligned with the base mesh?",
        estimate.samples, estimate.ray_length, 100 * options.ray_fraction));
  }
  std::sort(abs_t.begin(), abs_t.end());
  estimate.percentile_abs_t = Percentile(abs_t, options.percentile);
  estimate.median_abs_t = Percentile(abs_t, 0.5);
  estimate.max_abs_t = abs_t.back();

  const double floor = options.min_fraction * base_diagonal;
  double distance = estimate.percentile_abs_t * options.safety_factor;
  if (distance < floor) {
    distance = floor;
    estimate.floored = true;
  }
  if (distance > estimate.ray_length) {
    distance = estimate.ray_length;
    estimate.capped = true;
  }
  estimate.distance = distance;
  return estimate;
}

void LowerNearestHits(const Tracer& tracer, std::span<const Float3> origins,
                      std::span<const Float3> normals, float length, std::span<float> nearest_abs_t,
                      std::span<std::int8_t> side) {
  const NormalQuery query{length, HitPolicy::kNearest, /*verify_hits=*/true};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, origins.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      const std::size_t b = r.begin(), n = r.size();
                      std::vector<float> t(n);
                      std::vector<std::uint8_t> flags(n);
                      TraceCounters counters;
                      tracer.TraceNormals(origins.subspan(b, n), normals.subspan(b, n), query,
                                          NormalHits{t, {}, flags}, counters);
                      for (std::size_t i = 0; i < n; ++i) {
                        if (!(flags[i] & HitFlags::kHit)) continue;
                        float& kept = nearest_abs_t[b + i];
                        const float abs_t = std::fabs(t[i]);
                        if (side.empty()) {
                          kept = std::min(kept, abs_t);
                        } else {
                          KeepNearerHit(kept, side[b + i], abs_t, t[i] < 0 ? -1 : 1);
                        }
                      }
                    });
}

StatusOr<SearchDistanceEstimate> EstimateSearchDistance(const Tracer& tracer,
                                                        std::span<const Float3> origins,
                                                        std::span<const Float3> normals,
                                                        double base_diagonal,
                                                        const SearchDistanceOptions& options) {
  if (origins.size() != normals.size()) {
    return Status::Error(fmt::format("search distance estimate: {} sample points but {} normals",
                                     origins.size(), normals.size()));
  }
  if (origins.empty()) return Status::Error("search distance estimate: no sample points");
  DISPEX_RETURN_IF_ERROR(CheckEstimateOptions(base_diagonal, options));

  std::vector<float> nearest(origins.size(), std::numeric_limits<float>::infinity());
  LowerNearestHits(tracer, origins, normals,
                   static_cast<float>(options.ray_fraction * base_diagonal), nearest);
  DISPEX_RETURN_IF_ERROR(tracer.status());

  std::vector<double> abs_t;
  abs_t.reserve(origins.size());
  for (float t : nearest) {
    if (std::isfinite(t)) abs_t.push_back(static_cast<double>(t));
  }
  return SearchDistanceFromHits(std::move(abs_t), origins.size(), base_diagonal, options);
}

}  // namespace dispex
