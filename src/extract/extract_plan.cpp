#include "extract/extract_plan.h"

#include <fmt/format.h>

#include "core/enum_names.h"
#include "extract/memory_check.h"

namespace dispex {

namespace {

constexpr auto kOutputNames = EnumTable<ExtractPlan::Output>({
    {ExtractPlan::Output::kMap, "map"},
    {ExtractPlan::Output::kShardPart, "shard part"},
    {ExtractPlan::Output::kUpToDate, "up to date"},
});
constexpr auto kTracerNames = EnumTable<ExtractPlan::Tracer>({
    {ExtractPlan::Tracer::kNone, "none"},
    {ExtractPlan::Tracer::kWholeSculpt, "whole sculpt"},
    {ExtractPlan::Tracer::kWithinReach, "within reach"},
    {ExtractPlan::Tracer::kInParts, "in parts"},
});

}  // namespace

std::string_view ExtractPlanOutputName(ExtractPlan::Output output) {
  return EnumName(kOutputNames, output);
}

std::string_view ExtractPlanTracerName(ExtractPlan::Tracer tracer) {
  return EnumName(kTracerNames, tracer);
}

std::string ExtractPlanSummary(const ExtractPlan& plan) {
  if (plan.output == ExtractPlan::Output::kUpToDate) {
    return "plan: nothing to do, the map is up to date\n";
  }
  std::string out =
      fmt::format("plan: a {} ({}), method {}, BVH: {}{}\n", ExtractPlanOutputName(plan.output),
                  plan.channels == 3 ? "vector" : "scalar", ExtractMethodName(plan.method),
                  ExtractPlanTracerName(plan.tracer), plan.compact_bvh ? ", compact" : "");
  if (plan.faces_run >= 0) {
    out += fmt::format("  Ptex faces: {} of {} extracted", plan.faces_run, plan.faces);
    if (plan.faces_copied > 0) {
      out += fmt::format(", {} copied from {}", plan.faces_copied, plan.faces_from);
    }
    if (plan.faces_elsewhere > 0) out += fmt::format(", {} another shard's", plan.faces_elsewhere);
    if (plan.hole_faces > 0) out += fmt::format(", {} holes", plan.hole_faces);
    out += "\n";
  }
  if (plan.tracer == ExtractPlan::Tracer::kInParts) {
    out += fmt::format(
        "  the sculpt's BVH in {} parts, one at a time: the whole is estimated at "
        "more than the {} memory limit\n",
        plan.sculpt_parts, MemorySize(plan.memory_limit));
  }
  if (plan.compact_bvh) {
    out += fmt::format(
        "  the sculpt's BVH built compact at medium quality: at the asked quality it is "
        "estimated at more than the {} memory limit\n",
        MemorySize(plan.memory_limit));
  }
  if (plan.search_estimate_parts > 0) {
    out += fmt::format("  the automatic search distance estimated over the sculpt in {} parts\n",
                       plan.search_estimate_parts);
  }
  if (!plan.redo_reason.empty()) out += fmt::format("  why: {}\n", plan.redo_reason);
  if (plan.uv_maps) out += "  then the UV-space tiles\n";
  return out;
}

namespace extract {

std::vector<FaceSource> PlanFaces(ExtractPlan& plan, const ExtractInputs& inputs,
                                  std::span<const Hash128> keys, const PreviousMap* previous,
                                  std::span<const std::uint8_t> in_shard) {
  plan.faces_run = plan.faces_copied = plan.faces_elsewhere = plan.hole_faces = 0;
  std::vector<FaceSource> sources(keys.size(), FaceSource::kRun);
  for (std::size_t f = 0; f < keys.size(); ++f) {
    if (inputs.surface.is_hole(PtexFaceId(static_cast<int>(f)))) {
      sources[f] = FaceSource::kHole;
      ++plan.hole_faces;
    } else if (!in_shard.empty() && !in_shard[f]) {
      sources[f] = FaceSource::kElsewhere;
      ++plan.faces_elsewhere;
    } else if (previous != nullptr && previous->usable() && previous->Reusable(f, keys[f])) {
      sources[f] = FaceSource::kCopy;
      ++plan.faces_copied;
    } else {
      ++plan.faces_run;
    }
  }
  return sources;
}

std::vector<std::uint8_t> FacesWithinReach(const ExtractInputs& inputs,
                                           std::span<const FaceSource> sources, int rings) {
  std::vector<std::uint8_t> traced(sources.size(), 0);
  std::vector<int> ring;
  for (std::size_t f = 0; f < sources.size(); ++f) {
    if (sources[f] != FaceSource::kRun) continue;
    traced[f] = 1;
    ring.push_back(static_cast<int>(f));
  }
  AddRings(inputs.faces, rings, std::move(ring), traced);
  return traced;
}

nlohmann::json ExtractPlanJson(const ExtractPlan& plan) {
  nlohmann::json j;
  j["output"] = std::string(ExtractPlanOutputName(plan.output));
  j["channels"] = plan.channels;
  j["method"] = std::string(ExtractMethodName(plan.method));
  j["tracer"] = std::string(ExtractPlanTracerName(plan.tracer));
  j["faces_from"] = plan.faces_from;
  j["redo_reason"] = plan.redo_reason;
  j["faces"] = {{"all", plan.faces},
                {"extracted", plan.faces_run},
                {"copied", plan.faces_copied},
                {"another_shards", plan.faces_elsewhere},
                {"holes", plan.hole_faces}};
  j["uv_maps"] = plan.uv_maps;
  j["memory"] = {{"limit_bytes", plan.memory_limit},
                 {"estimate_bytes", plan.memory_estimate},
                 {"sculpt_parts", plan.sculpt_parts},
                 {"compact_bvh", plan.compact_bvh},
                 {"search_estimate_parts", plan.search_estimate_parts}};
  return j;
}

}  // namespace extract

}  // namespace dispex
