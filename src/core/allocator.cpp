#include "dispex/allocator.h"

#include <climits>
#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)  // defined by the C library's headers above
#include <malloc.h>
#endif

namespace dispex {

bool KeepFreedMemory() {
#if defined(__GLIBC__)
  const char* keep = std::getenv("DISPEX_KEEP_FREED_MEMORY");
  if (keep != nullptr && std::strcmp(keep, "0") == 0) return false;
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, "glibc.malloc.") != nullptr) return false;
  // Large blocks from the heap, not from mmap (which free unmaps); the heap's free top kept;
  // one heap for every thread, so that what one thread frees another re-uses.
  return mallopt(M_MMAP_MAX, 0) == 1 && mallopt(M_TRIM_THRESHOLD, INT_MAX) == 1 &&
         mallopt(M_ARENA_MAX, 1) == 1;
#else
  return false;
#endif
}

}  // namespace dispex
