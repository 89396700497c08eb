#include "core/system.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

namespace dispex {

namespace {
// Reads "Key:   1234 kB" from a /proc file; returns bytes or 0.
std::uint64_t ReadProcKb(const char* file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) == 0 && line.size() > key.size() &&
        line[key.size()] == ':') {
      std::istringstream fields(line.substr(key.size() + 1));
      std::uint64_t kb = 0;
      fields >> kb;
      return kb * 1024;
    }
  }
  return 0;
}

std::uint64_t CgroupLimitBytes() {
  for (const char* file :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(file);
    std::string value;
    if (in >> value && value != "max") {
      try {
        return std::stoull(value);
      } catch (...) {
      }
    }
  }
  return 0;
}
}  // namespace

std::uint64_t PeakResidentBytes() {
  return ReadProcKb("/proc/self/status", "VmHWM");
}

std::uint64_t AvailableMemoryBytes() {
  std::uint64_t available = ReadProcKb("/proc/meminfo", "MemAvailable");
  std::uint64_t limit = CgroupLimitBytes();
  if (limit > 0 && limit < (1ull << 60)) available = available ? std::min(available, limit) : limit;
  return available;
}

}  // namespace dispex
