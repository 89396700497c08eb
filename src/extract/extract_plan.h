// The plan of one map's extraction (ExtractPlan, dispex/extract.h): the stages that decide a
// part of it fill it in, and the report carries it.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/hash128.h"
#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/incremental/previous_map.h"

namespace dispex::extract {

// Each face's source, from `previous` (when usable: a face whose key is unchanged and whose
// stored texels are its first pass is copied) and `in_shard` (when not empty: the faces it does
// not flag are another shard's), counted into the plan. ProcessFaces follows it.
std::vector<FaceSource> PlanFaces(ExtractPlan& plan, const ExtractInputs& inputs,
                                  std::span<const Hash128> keys, const PreviousMap* previous,
                                  std::span<const std::uint8_t> in_shard);

// The faces whose sculpt a BVH of the sculpt within reach holds: those that run, and `rings`
// rings of faces around them.
std::vector<std::uint8_t> FacesWithinReach(const ExtractInputs& inputs,
                                           std::span<const FaceSource> sources, int rings);

nlohmann::json ExtractPlanJson(const ExtractPlan& plan);

}  // namespace dispex::extract
