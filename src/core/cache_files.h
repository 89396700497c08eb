// The files a cache folder keeps between runs (CacheFolder: the sculpt's adjacency, the
// automatic search distance's rays), kept within a size: the least recently used go first.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/mapped_file.h"

namespace dispex {

// Removes the least recently written files of `folder` named `prefix`... beyond `max_bytes` in
// all (never `keep`), and the temporary files (".tmp.") of such a file that a killed run left
// over an hour ago. Errors are ignored: a cache that cannot be trimmed only takes more room.
void EvictCacheFiles(const std::string& folder, std::string_view prefix, std::uint64_t max_bytes,
                     const std::string& keep);

// A cache record file: an 8-byte magic, the record (core/byte_record.h), and the XXH3-128 of
// both. Read: the file mapped (never copied whole), and `bytes` its bytes less the hash (the
// magic first); nullopt when it is missing, starts with another magic, or fails its hash (cut
// short by a crash, or changed). Cache files are replaced by rename, never rewritten in place,
// so the mapped bytes stay as they were read.
struct CacheRecord {
  MappedFile file;
  std::string_view bytes;
};
std::optional<CacheRecord> ReadCacheRecord(const std::string& path, std::string_view magic);
// Writes `parts` in order to a file beside `path` (its folder made when missing) and renames
// that onto it, without syncing: the cache files carry a hash of their content, which a file a
// crash cuts short fails. False when it could not be written (a cache not kept only makes the
// next run slower); no temporary file is left then.
bool WriteCacheFile(const std::string& path, std::span<const std::span<const std::byte>> parts);
// Writes `bytes` (the magic first) and their hash with WriteCacheFile.
bool WriteCacheRecord(const std::string& path, std::string bytes);
// The same of `parts` in order (the magic first), none of them copied.
bool WriteCacheRecord(const std::string& path, std::span<const std::span<const std::byte>> parts);

}  // namespace dispex
