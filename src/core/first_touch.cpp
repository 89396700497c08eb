#include "core/first_touch.h"

#include <atomic>
#include <cerrno>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace dispex {

namespace {

// MADV_POPULATE_READ and MADV_POPULATE_WRITE, in <sys/mman.h> of newer headers only.
constexpr int kPopulateRead = 22, kPopulateWrite = 23;

bool Populate(const void* begin, std::size_t bytes, int advice) {
#if defined(__linux__)
  static std::atomic<bool> unsupported{false};
  if (bytes == 0 || unsupported.load(std::memory_order_relaxed)) return false;
  static const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  // Every page holding a byte of the range lies wholly in the range's mapping.
  const auto lo = reinterpret_cast<std::uintptr_t>(begin) & ~(page - 1);
  const auto hi = (reinterpret_cast<std::uintptr_t>(begin) + bytes + page - 1) & ~(page - 1);
  if (madvise(reinterpret_cast<void*>(lo), hi - lo, advice) == 0) return true;
  if (errno == EINVAL) unsupported.store(true, std::memory_order_relaxed);
  return false;
#else
  (void)begin;
  (void)bytes;
  (void)advice;
  return false;
#endif
}

}  // namespace

bool PopulatePages(void* begin, std::size_t bytes) {
  return Populate(begin, bytes, kPopulateWrite);
}

bool PopulateMappedPages(const void* begin, std::size_t bytes) {
  return Populate(begin, bytes, kPopulateRead);
}

}  // namespace dispex
