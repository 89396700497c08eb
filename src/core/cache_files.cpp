#include "core/cache_files.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <vector>

#include "core/byte_record.h"
#include "core/hash128.h"

namespace dispex {

namespace fs = std::filesystem;

void EvictCacheFiles(const std::string& folder, std::string_view prefix, std::uint64_t max_bytes,
                     const std::string& keep) {
  struct Entry {
    fs::file_time_type time;
    std::uintmax_t size;
    fs::path path;
  };
  std::vector<Entry> entries;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    std::error_code stat_error;
    const auto time = entry.last_write_time(stat_error);
    const auto size = entry.file_size(stat_error);
    if (stat_error) continue;
    if (name.find(".tmp.") != std::string::npos) {
      if (fs::file_time_type::clock::now() - time > std::chrono::hours(1)) {
        fs::remove(entry.path(), stat_error);
      }
      continue;
    }
    entries.push_back({time, size, entry.path()});
  }
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.time > b.time; });
  std::uintmax_t total = 0;
  for (const Entry& e : entries) {
    total += e.size;
    if (total > max_bytes && e.path != fs::path(keep)) fs::remove(e.path, ec);
  }
}

std::optional<CacheRecord> ReadCacheRecord(const std::string& path, std::string_view magic) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  StatusOr<MappedFile> file = MappedFile::Open(path);
  if (!file.ok()) return std::nullopt;
  const std::string_view whole = file->view();
  constexpr std::size_t kCheck = sizeof(Hash128);
  if (whole.size() < magic.size() + kCheck || whole.substr(0, magic.size()) != magic) {
    return std::nullopt;
  }
  Hash128 check;
  std::memcpy(&check, whole.data() + whole.size() - kCheck, kCheck);
  const std::string_view bytes = whole.substr(0, whole.size() - kCheck);
  if (!(HashBytes(std::as_bytes(std::span(bytes.data(), bytes.size()))) == check)) {
    return std::nullopt;
  }
  return CacheRecord{std::move(*file), bytes};
}

bool WriteCacheFile(const std::string& path, std::span<const std::span<const std::byte>> parts) {
  static std::atomic<unsigned> written{0};  // two runs of one process at once
  const std::string temp =
      path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(written.fetch_add(1));
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  bool ok = false;
  if (std::FILE* f = std::fopen(temp.c_str(), "wb")) {
    ok = true;
    for (std::span<const std::byte> part : parts) {
      ok = ok && std::fwrite(part.data(), 1, part.size(), f) == part.size();
    }
    ok = std::fclose(f) == 0 && ok;
  }
  if (ok) fs::rename(temp, path, ec);
  if (!ok || ec) fs::remove(temp, ec);
  return ok && !ec;
}

bool WriteCacheRecord(const std::string& path, std::string bytes) {
  const std::span<const std::byte> whole = std::as_bytes(std::span(bytes.data(), bytes.size()));
  return WriteCacheRecord(path, std::span(&whole, 1));
}

bool WriteCacheRecord(const std::string& path, std::span<const std::span<const std::byte>> parts) {
  Hasher h;
  for (std::span<const std::byte> part : parts) h.Add(part);
  const Hash128 check = h.Digest();
  std::vector<std::span<const std::byte>> all(parts.begin(), parts.end());
  all.push_back(std::as_bytes(std::span(&check, 1)));
  return WriteCacheFile(path, all);
}

}  // namespace dispex
