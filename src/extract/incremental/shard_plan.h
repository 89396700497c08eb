// Which Ptex faces a farm shard extracts (ExtractOptions::shard_index of shard_count): a run of
// the faces in shard order (ShardOrder), the runs of all shards of about equal estimated cost.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "extract/incremental/face_keys.h"
#include "extract/oversampling.h"

namespace dispex::extract {

struct ShardRange {
  std::int64_t begin = 0, end = 0;  // the faces order[begin..end) of ShardOrder
  double cost_fraction = 0;         // of the whole map's estimated cost
};

// The order shards cut their runs from: the Ptex faces along a Z-order (Morton) curve of
// their centres on the base cage, so that a shard's faces lie together and the sculpt within
// their reach is little more than theirs (runs of consecutive Ptex face ids are strips across
// the model, each face's reach adding a margin on both sides). From the base alone, so that
// shards and merge compute the same order.
std::vector<std::int32_t> ShardOrder(const Mesh& base, const LimitSurface& surface);

// A face's cost is its planned samples plus the sculpt faces within its reach
// (FaceKeys::reach_faces: the rays it casts, and the part of the BVH it needs); holes cost
// nothing. Shard i (1..count) ends at the first face in `order` where the running cost reaches
// i/count of the total, so every shard computes the same runs from the same inputs and
// settings, and they cover every face exactly once.
ShardRange PlanShard(const LimitSurface& surface, const OversamplingPlan& plan,
                     const FaceKeys& keys, std::span<const std::int32_t> order, int index,
                     int count);

}  // namespace dispex::extract
