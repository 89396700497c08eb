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

// Counts the faces that run, those copied from `previous` (when usable), another shard's
// (outside `in_shard`, when not empty) and the holes: as ProcessFaces decides them
// from the same keys. Returns which faces run (1), per Ptex face.
std::vector<std::uint8_t> PlanFaces(ExtractPlan& plan, const ExtractInputs& inputs,
                                    std::span<const Hash128> keys, const PreviousMap* previous,
                                    std::span<const std::uint8_t> in_shard);

// The faces whose sculpt a BVH of the sculpt within reach holds: those that run (PlanFaces),
// and `rings` rings of faces around them.
std::vector<std::uint8_t> FacesWithinReach(const ExtractInputs& inputs,
                                           std::vector<std::uint8_t> runs, int rings);

nlohmann::json ExtractPlanJson(const ExtractPlan& plan);

}  // namespace dispex::extract
