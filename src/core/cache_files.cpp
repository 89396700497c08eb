#include "core/cache_files.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <vector>

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

}  // namespace dispex
