// The parts farm shards write (ExtractOptions::shard_count) and the checks MergeShards makes of
// them before it merges. A part is a Ptex file of the whole face table: the first pass of its
// shard's faces (texels, keys, records, as an incremental extraction re-uses them), every other
// face 0 with a zero key, and a record of the shard (kShardMetaKey).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "dispex/ptex.h"

namespace dispex::extract {

inline constexpr const char* kShardMetaKey = "dispex:shard";

struct ShardInfo {
  int index = 0, count = 0;
  std::int64_t begin = 0, end = 0;     // Ptex faces [begin, end)
  std::string map_inputs_key;          // the InputsKey of the map the parts merge into
  std::string base_path, sculpt_path;  // absolute: the merge reads them again
  std::string options;                 // ExtractOptionsJson
};

// As stored in a part (JSON).
std::string ShardInfoJson(const ShardInfo& info);

// What a part stores as its dispex:inputs_key: the map's, and which shard it is (an incremental
// re-run of the same shard with the same inputs leaves it as it is).
std::string PartInputsKey(const std::string& map_inputs_key, int index, int count);

struct ShardPart {
  std::string path;
  PtexFile file;
  ShardInfo info;
};

// Opens a part, reads its shard record and checks its face data; errors name the path.
StatusOr<ShardPart> OpenShardPart(const std::string& path);

// The parts of one extraction -- the same version, base, sculpt, options and shard count --
// each shard exactly once, their faces following on from each other over the whole face table;
// returned in the order of their shards. Errors are one line naming the part (or the missing
// shard).
StatusOr<std::vector<ShardPart>> CheckShardParts(std::vector<ShardPart> parts);

// The parts were made from the base and sculpt as `report` (the merge's) read them now.
Status CheckPartsMatchInputs(const std::vector<ShardPart>& parts, const ExtractReport& report);

}  // namespace dispex::extract
