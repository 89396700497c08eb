#include "core/system.h"

#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

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

// The memory limit of this process's own cgroup (v2 memory.max, v1 memory.limit_in_bytes),
// found through /proc/self/cgroup, or of the mount's root when that path is not visible (a
// container that shows its own cgroup at the root); 0 when none is set.
std::uint64_t CgroupLimitBytes() {
  std::string v2_path, v1_path;
  std::ifstream self("/proc/self/cgroup");
  std::string line;
  while (std::getline(self, line)) {  // "ID:CONTROLLERS:PATH"
    const std::size_t a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
    if (line.compare(0, a, "0") == 0 && controllers.empty()) v2_path = path;
    if ((',' + controllers + ',').find(",memory,") != std::string::npos) v1_path = path;
  }
  const std::string candidates[] = {"/sys/fs/cgroup" + v2_path + "/memory.max",
                                    "/sys/fs/cgroup/memory" + v1_path + "/memory.limit_in_bytes",
                                    "/sys/fs/cgroup/memory.max",
                                    "/sys/fs/cgroup/memory/memory.limit_in_bytes"};
  for (const std::string& file : candidates) {
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

std::uint64_t AvailableMemoryBytes(int threads) {
  std::uint64_t available = ReadProcKb("/proc/meminfo", "MemAvailable");
  std::uint64_t limit = CgroupLimitBytes();
  if (limit > 0 && limit < (1ull << 60)) available = available ? std::min(available, limit) : limit;
  rlimit address_space{};
  if (getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY) {
    // Address space is also reserved without being used: Embree's device (about 130 MiB),
    // and each worker thread's stack and malloc arena (up to 64 MiB).
    const std::uint64_t workers =
        threads > 0 ? std::uint64_t(threads) : std::max(1u, std::thread::hardware_concurrency());
    const std::uint64_t reserved =
        ReadProcKb("/proc/self/status", "VmSize") + (160ull << 20) + workers * (72ull << 20);
    const std::uint64_t cap = address_space.rlim_cur;
    const std::uint64_t left = cap > reserved ? cap - reserved : 1;
    available = available ? std::min(available, left) : left;
  }
  return available;
}

}  // namespace dispex
