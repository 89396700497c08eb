// Which Ptex faces a farm shard extracts (ExtractOptions::shard_index of shard_count): a run of
// consecutive faces, the runs of all shards of about equal estimated cost.
#pragma once

#include <cstdint>

#include "dispex/subdiv.h"
#include "extract/face_keys.h"
#include "extract/oversampling.h"

namespace dispex::extract {

struct ShardRange {
  std::int64_t begin = 0, end = 0;  // Ptex faces [begin, end)
  double cost_fraction = 0;         // of the whole map's estimated cost
};

// A face's cost is its planned samples plus the sculpt faces within its reach
// (FaceKeys::reach_faces: the rays it casts, and the part of the BVH it needs); holes cost
// nothing. Shard i (1..count) ends at the first face where the running cost reaches i/count of
// the total, so every shard computes the same runs from the same inputs and settings, and they
// cover every face exactly once.
ShardRange PlanShard(const LimitSurface& surface, const OversamplingPlan& plan,
                     const FaceKeys& keys, int index, int count);

}  // namespace dispex::extract
