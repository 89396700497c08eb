// The names of the extract options' enums, one table each (core/enum_names.h): their Name and
// Parse functions (extract_options.cpp) and the values the option table lists
// (option_table.cpp) read them.
#pragma once

#include "core/enum_names.h"
#include "dispex/extract.h"

namespace dispex::extract {

inline constexpr auto kHolePolicyNames = EnumTable<HolePolicy>({
    {HolePolicy::kFill, "fill"},
    {HolePolicy::kFail, "fail"},
    {HolePolicy::kZero, "zero"},
});

inline constexpr auto kWatertightEdgesNames = EnumTable<WatertightEdges>({
    {WatertightEdges::kAll, "all"},
    {WatertightEdges::kFilter, "filter"},
    {WatertightEdges::kOff, "off"},
});

inline constexpr auto kExtractMethodNames = EnumTable<ExtractMethod>({
    {ExtractMethod::kAuto, "auto"},
    {ExtractMethod::kRays, "rays"},
    {ExtractMethod::kMapping, "mapping"},
    {ExtractMethod::kInterpolate, "interpolate"},
});

inline constexpr auto kShardSculptNames = EnumTable<ShardSculpt>({
    {ShardSculpt::kWhole, "whole"},
    {ShardSculpt::kPart, "part"},
});

}  // namespace dispex::extract
