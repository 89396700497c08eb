#include "subdiv/match_cache.h"

#include <algorithm>
#include <filesystem>
#include <string_view>

#include "core/byte_record.h"
#include "core/cache_files.h"

namespace dispex::subdiv::matching {
namespace {

constexpr char kMagic[8] = {'D', 'X', 'M', 'A', 'T', 'C', 'H', '1'};
constexpr const char* kPrefix = "match-";

bool Consistent(const ComponentSeeds& c) {
  if (c.met_end.size() != c.walk_complete.size() || c.met_w.size() != c.met_x.size() ||
      c.chosen < 0 || static_cast<std::size_t>(c.chosen) >= c.walk_complete.size()) {
    return false;
  }
  std::uint32_t previous = 0;
  for (std::uint32_t end : c.met_end) {
    if (end < previous || end > c.met_w.size()) return false;
    previous = end;
  }
  return true;
}

}  // namespace

std::string MatchRecordPath(const std::string& folder, const Hash128& key) {
  return (std::filesystem::path(folder) / (kPrefix + key.Hex() + ".bin")).string();
}

std::optional<MatchRecord> ReadMatchRecord(const std::string& path, const Hash128& key,
                                           std::size_t num_cells) {
  const std::optional<CacheRecord> read =
      ReadCacheRecord(path, std::string_view(kMagic, sizeof(kMagic)));
  if (!read) return std::nullopt;
  const std::string_view body = read->bytes;
  std::size_t at = sizeof(kMagic);
  Hash128 stored;
  MatchRecord record;
  std::uint64_t components = 0;
  if (!Take(body, at, stored) || !(stored == key) || !Take(body, at, record.levels) ||
      !TakeArray(body, at, record.cell_labels) || record.cell_labels.size() != num_cells ||
      std::any_of(record.cell_labels.begin(), record.cell_labels.end(),
                  [&](std::uint32_t label) { return label / 4 >= num_cells; }) ||
      !Take(body, at, components) || components > num_cells) {
    return std::nullopt;
  }
  record.components.resize(components);
  for (ComponentSeeds& c : record.components) {
    if (!Take(body, at, c.seed_vertex) || !TakeArray(body, at, c.class_vertices) ||
        !TakeArray(body, at, c.candidates) || !TakeArray(body, at, c.walk_complete) ||
        !TakeArray(body, at, c.met_end) || !TakeArray(body, at, c.met_w) ||
        !TakeArray(body, at, c.met_x) || !Take(body, at, c.chosen) || !Consistent(c)) {
      return std::nullopt;
    }
  }
  PositionChecks& checks = record.checks;
  if (!TakeArray(body, at, checks.own) || !TakeArray(body, at, checks.lattice_keys) ||
      !TakeArray(body, at, checks.max) || !TakeArray(body, at, checks.sum_squares) ||
      !TakeArray(body, at, checks.worst) || !TakeArray(body, at, checks.count) ||
      checks.max.size() != checks.lattice_keys.size() ||
      checks.sum_squares.size() != checks.lattice_keys.size() ||
      checks.worst.size() != checks.lattice_keys.size() ||
      checks.count.size() != checks.lattice_keys.size()) {
    return std::nullopt;
  }
  if (at != body.size()) return std::nullopt;
  std::error_code ec;
  std::filesystem::last_write_time(path, std::filesystem::file_time_type::clock::now(), ec);
  return record;
}

void WriteMatchRecord(const std::string& path, const Hash128& key, std::int32_t levels,
                      std::span<const std::uint32_t> cell_labels,
                      std::span<const ComponentSeeds> components, const PositionChecks& checks) {
  std::string bytes(kMagic, sizeof(kMagic));
  Append(bytes, key);
  Append(bytes, levels);
  AppendArray(bytes, cell_labels);
  Append(bytes, std::uint64_t{components.size()});
  for (const ComponentSeeds& c : components) {
    Append(bytes, c.seed_vertex);
    AppendArray(bytes, c.class_vertices);
    AppendArray(bytes, c.candidates);
    AppendArray(bytes, c.walk_complete);
    AppendArray(bytes, c.met_end);
    AppendArray(bytes, c.met_w);
    AppendArray(bytes, c.met_x);
    Append(bytes, c.chosen);
  }
  AppendArray(bytes, checks.own);
  AppendArray(bytes, checks.lattice_keys);
  AppendArray(bytes, checks.max);
  AppendArray(bytes, checks.sum_squares);
  AppendArray(bytes, checks.worst);
  AppendArray(bytes, checks.count);
  if (!WriteCacheRecord(path, std::move(bytes))) return;
  EvictCacheFiles(std::filesystem::path(path).parent_path().string(), kPrefix, kMatchCacheBytes,
                  path);
}

}  // namespace dispex::subdiv::matching
