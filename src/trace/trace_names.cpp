// Names of the trace options (for the command line and reports) and the counters' sum.
#include "core/enum_names.h"
#include "dispex/trace.h"

namespace dispex {
namespace {

constexpr auto kPolicies = EnumTable<HitPolicy>({
    {HitPolicy::kNearest, "nearest"},
    {HitPolicy::kOutsideFirst, "outside-first"},
    {HitPolicy::kInsideFirst, "inside-first"},
});
constexpr auto kQualities = EnumTable<BuildQuality>({
    {BuildQuality::kLow, "low"},
    {BuildQuality::kMedium, "medium"},
    {BuildQuality::kHigh, "high"},
});
constexpr auto kModes = EnumTable<RayMode>({
    {RayMode::kSingle, "single"},
    {RayMode::kPacket4, "packet4"},
    {RayMode::kPacket8, "packet8"},
    {RayMode::kPacket16, "packet16"},
    {RayMode::kStream, "stream"},
});

}  // namespace

std::string_view HitPolicyName(HitPolicy policy) {
  return EnumName(kPolicies, policy);
}
std::string_view BuildQualityName(BuildQuality quality) {
  return EnumName(kQualities, quality);
}
std::string_view RayModeName(RayMode mode) {
  return EnumName(kModes, mode);
}

StatusOr<HitPolicy> ParseHitPolicy(std::string_view name) {
  return ParseEnum(kPolicies, "hit policy", name);
}
StatusOr<BuildQuality> ParseBuildQuality(std::string_view name) {
  return ParseEnum(kQualities, "build quality", name);
}
StatusOr<RayMode> ParseRayMode(std::string_view name) {
  return ParseEnum(kModes, "ray mode", name);
}

TraceCounters& TraceCounters::operator+=(const TraceCounters& other) {
  queries += other.queries;
  invalid += other.invalid;
  rays_cast += other.rays_cast;
  repair_rays += other.repair_rays;
  tie_hits += other.tie_hits;
  hits += other.hits;
  return *this;
}

}  // namespace dispex
