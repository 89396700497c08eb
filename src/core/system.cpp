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

// A limit file's value in bytes; 0 for "max", none or unreadable.
std::uint64_t LimitIn(const std::string& file) {
  std::ifstream in(file);
  std::string value;
  if (!(in >> value) || value == "max") return 0;
  try {
    return std::stoull(value);
  } catch (...) {
    return 0;
  }
}

// The lowest memory limit of this process's cgroup and its ancestors (v2 memory.max, v1
// memory.limit_in_bytes: a Slurm job's limit sits on the job's cgroup, its tasks' below it say
// "max"), found through /proc/self/cgroup; or the mount's root's, where the path is not visible
// (a container that shows its own cgroup at the root); 0 when none is set.
std::uint64_t CgroupLimitBytes() {
  std::string v2_path, v1_path;
  bool v2 = false, v1 = false;
  std::ifstream self("/proc/self/cgroup");
  std::string line;
  while (std::getline(self, line)) {  // "ID:CONTROLLERS:PATH"
    const std::size_t a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
    if (line.compare(0, a, "0") == 0 && controllers.empty()) v2 = true, v2_path = path;
    if ((',' + controllers + ',').find(",memory,") != std::string::npos) v1 = true, v1_path = path;
  }
  std::uint64_t lowest = 0;
  auto take = [&](const std::string& mount, std::string path, const char* file) {
    for (;;) {  // the cgroup, then each ancestor up to the mount's root
      const std::uint64_t limit = LimitIn(mount + path + "/" + file);
      if (limit > 0 && (lowest == 0 || limit < lowest)) lowest = limit;
      if (path.empty() || path == "/") return;
      path.erase(path.find_last_of('/'));
    }
  };
  if (v1) take("/sys/fs/cgroup/memory", v1_path, "memory.limit_in_bytes");
  if (v2) take("/sys/fs/cgroup", v2_path, "memory.max");
  return lowest;
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
