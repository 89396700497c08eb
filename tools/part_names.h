// Where the farm's jobs put an asset's parts: the one name `dispex batch --shard` writes and
// the merge job of `dispex farm slurm` reads.
#pragma once

#include <filesystem>
#include <string>

namespace dispex::cli {

inline std::string PartPath(const std::string& parts_dir, const std::string& asset, int index,
                            int count) {
  return (std::filesystem::path(parts_dir) /
          (asset + ".part-" + std::to_string(index) + "-of-" + std::to_string(count) + ".ptx"))
      .string();
}

}  // namespace dispex::cli
