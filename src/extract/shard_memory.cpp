// PlanShardMemory: whether a farm shard keeps the whole sculpt or its part, within a node's
// memory.
#include <fmt/format.h>

#include <algorithm>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "extract/memory_check.h"

namespace dispex {

StatusOr<ShardMemoryPlan> PlanShardMemory(const ExtractOptions& options,
                                          std::uint64_t node_memory) {
  DISPEX_ASSIGN_OR_RETURN(const MeshSize sculpt, CountMeshElements(options.sculpt_path));
  const bool matches = extract::MatchesSculpt(options);
  const bool may_trace =
      options.method != ExtractMethod::kMapping && options.method != ExtractMethod::kInterpolate;
  // The output's bound as the run's, less the base's faces it does not know yet.
  const extract::MemoryNeed need = extract::EstimateMemory(
      sculpt.vertices, sculpt.faces, sculpt.corners, extract::kMaxEstimatedTexels, matches);
  ShardMemoryPlan plan;
  plan.floor_bytes =
      std::max(extract::ReadPeakBytes(options), need.arrays + need.match + need.output);
  plan.whole_bytes =
      std::max(plan.floor_bytes, need.arrays + need.output + (may_trace ? need.bvh : need.match));
  if (node_memory == 0 || plan.whole_bytes <= node_memory) return plan;
  // A shard reads its job's memory limit and builds the BVH compact where that fits
  // (SculptPartsWithin), so the whole sculpt may still fit the node.
  if (may_trace) {
    plan.compact_bytes = std::max(plan.floor_bytes, need.arrays + need.output + need.compact_bvh);
    plan.compact_bvh = plan.compact_bytes <= node_memory;
    if (plan.compact_bvh) return plan;
  }
  if (plan.floor_bytes > node_memory) {
    return Status::Error(
        StatusCode::kOverBudget,
        fmt::format("{}: a sculpt of {} faces needs an estimated {} in any shard (reading it, "
                    "its arrays{}, the output) but a node has {}",
                    options.sculpt_path, sculpt.faces, MemorySize(plan.floor_bytes),
                    matches ? ", its correspondence" : "", MemorySize(node_memory)));
  }
  plan.shard_sculpt = ShardSculpt::kPart;
  return plan;
}

}  // namespace dispex
