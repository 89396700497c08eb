// The files a cache folder keeps between runs (CacheFolder: the sculpt's adjacency, the
// automatic search distance's rays), kept within a size: the least recently used go first.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace dispex {

// Removes the least recently written files of `folder` named `prefix`... beyond `max_bytes` in
// all (never `keep`), and the temporary files (".tmp.") of such a file that a killed run left
// over an hour ago. Errors are ignored: a cache that cannot be trimmed only takes more room.
void EvictCacheFiles(const std::string& folder, std::string_view prefix, std::uint64_t max_bytes,
                     const std::string& keep);

}  // namespace dispex
