// Names of the trace options (for the command line and reports) and the counters' sum.
#include <fmt/format.h>

#include <array>
#include <utility>

#include "dispex/trace.h"

namespace dispex {
namespace {

constexpr std::array<std::pair<HitPolicy, std::string_view>, 3> kPolicies{{
    {HitPolicy::kNearest, "nearest"},
    {HitPolicy::kOutsideFirst, "outside-first"},
    {HitPolicy::kInsideFirst, "inside-first"},
}};
constexpr std::array<std::pair<BuildQuality, std::string_view>, 3> kQualities{{
    {BuildQuality::kLow, "low"},
    {BuildQuality::kMedium, "medium"},
    {BuildQuality::kHigh, "high"},
}};
constexpr std::array<std::pair<RayMode, std::string_view>, 5> kModes{{
    {RayMode::kSingle, "single"},
    {RayMode::kPacket4, "packet4"},
    {RayMode::kPacket8, "packet8"},
    {RayMode::kPacket16, "packet16"},
    {RayMode::kStream, "stream"},
}};

template <class E, std::size_t N>
std::string_view Name(const std::array<std::pair<E, std::string_view>, N>& table, E value) {
  for (const auto& [e, name] : table) {
    if (e == value) return name;
  }
  return "?";
}

template <class E, std::size_t N>
StatusOr<E> Parse(const std::array<std::pair<E, std::string_view>, N>& table, std::string_view what,
                  std::string_view text) {
  std::string valid;
  for (const auto& [e, name] : table) {
    if (name == text) return e;
    valid += valid.empty() ? "" : ", ";
    valid += name;
  }
  return Status::Error(fmt::format("unknown {} '{}' (valid: {})", what, text, valid));
}

}  // namespace

std::string_view HitPolicyName(HitPolicy policy) {
  return Name(kPolicies, policy);
}
std::string_view BuildQualityName(BuildQuality quality) {
  return Name(kQualities, quality);
}
std::string_view RayModeName(RayMode mode) {
  return Name(kModes, mode);
}

StatusOr<HitPolicy> ParseHitPolicy(std::string_view name) {
  return Parse(kPolicies, "hit policy", name);
}
StatusOr<BuildQuality> ParseBuildQuality(std::string_view name) {
  return Parse(kQualities, "build quality", name);
}
StatusOr<RayMode> ParseRayMode(std::string_view name) {
  return Parse(kModes, "ray mode", name);
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
