// Options of the per-face resolution choice, and the totals over faces.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/enum_names.h"
#include "dispex/spectral.h"

namespace dispex {

namespace {

constexpr auto kResolutionRuleNames = EnumTable<ResolutionRule>({
    {ResolutionRule::kErrorBound, "bound"},
    {ResolutionRule::kNonzero, "nonzero"},
    {ResolutionRule::kFixed, "fixed"},
});

}  // namespace

std::string_view ResolutionRuleName(ResolutionRule rule) {
  return EnumName(kResolutionRuleNames, rule);
}

StatusOr<ResolutionRule> ParseResolutionRule(std::string_view name) {
  return ParseEnum(kResolutionRuleNames, "resolution rule", name);
}

Status ValidateSpectralOptions(const SpectralOptions& options) {
  switch (options.rule) {
    case ResolutionRule::kErrorBound:
    case ResolutionRule::kNonzero:
    case ResolutionRule::kFixed:
      break;
    default:
      return Status::Error(fmt::format("rule = {}: not one of {}", static_cast<int>(options.rule),
                                       EnumNameList(kResolutionRuleNames)));
  }
  if (!std::isfinite(options.tolerance) || options.tolerance < 0) {
    return Status::Error(
        fmt::format("tolerance = {}: must be finite and >= 0 (object units)", options.tolerance));
  }
  if (!std::isfinite(options.edge_tolerance) || options.edge_tolerance < 0) {
    return Status::Error(fmt::format("edge_tolerance = {}: must be finite and >= 0 (object units)",
                                     options.edge_tolerance));
  }
  if (!std::isfinite(options.nonzero_threshold) || options.nonzero_threshold < 0) {
    return Status::Error(
        fmt::format("nonzero_threshold = {}: must be finite and >= 0", options.nonzero_threshold));
  }
  for (int l : {options.min_ulog2, options.min_vlog2}) {
    if (l < 0 || l > kMaxSpectralLog2) {
      return Status::Error(fmt::format("min_ulog2 x min_vlog2 = {} x {}: {} is outside 0..{}",
                                       options.min_ulog2, options.min_vlog2, l, kMaxSpectralLog2));
    }
  }
  for (int l : {options.fixed_ulog2, options.fixed_vlog2}) {
    if (l < 0 || l > kMaxSpectralLog2) {
      return Status::Error(fmt::format("fixed_ulog2 x fixed_vlog2 = {} x {}: {} is outside 0..{}",
                                       options.fixed_ulog2, options.fixed_vlog2, l,
                                       kMaxSpectralLog2));
    }
  }
  return Status::Ok();
}

void SpectralTotals::Add(const SpectralFaceStats& face, int ulog2, int vlog2) {
  ++faces;
  constant_faces += face.constant ? 1 : 0;
  stepped_up_faces += face.step_ups > 0 ? 1 : 0;
  step_ups += face.step_ups;
  texels_before += face.texels_before;
  texels_after += face.texels_after;
  max_bound = std::max(max_bound, face.bound);
  max_measured_error = std::max(max_measured_error, face.measured_error);
  max_edge_error = std::max(max_edge_error, face.edge_error);
  edge_limited_faces += face.edge_limited ? 1 : 0;
  ++ulog2_faces[std::clamp(ulog2, 0, kMaxSpectralLog2)];
  ++vlog2_faces[std::clamp(vlog2, 0, kMaxSpectralLog2)];
}

void SpectralTotals::Merge(const SpectralTotals& other) {
  faces += other.faces;
  constant_faces += other.constant_faces;
  stepped_up_faces += other.stepped_up_faces;
  step_ups += other.step_ups;
  texels_before += other.texels_before;
  texels_after += other.texels_after;
  max_bound = std::max(max_bound, other.max_bound);
  max_measured_error = std::max(max_measured_error, other.max_measured_error);
  max_edge_error = std::max(max_edge_error, other.max_edge_error);
  edge_limited_faces += other.edge_limited_faces;
  for (int l = 0; l <= kMaxSpectralLog2; ++l) {
    ulog2_faces[l] += other.ulog2_faces[l];
    vlog2_faces[l] += other.vlog2_faces[l];
  }
}

}  // namespace dispex
