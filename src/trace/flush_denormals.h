// Flush-to-zero and denormals-are-zero for the current thread, for the length of a scope.
// Embree asks for both modes on every thread that traces (denormal operands are slow); the
// tracer sets them per batch and restores the caller's mode afterwards, so TBB worker
// threads need no setup and no other code sees a changed floating-point mode.
#pragma once

#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#define DISPEX_HAVE_MXCSR 1
#endif

namespace dispex::trace {

class ScopedFlushDenormals {
 public:
#if defined(DISPEX_HAVE_MXCSR)
  ScopedFlushDenormals() : saved_(_mm_getcsr()) {
    _mm_setcsr(saved_ | kFlushToZero | kDenormalsAreZero);
  }
  ~ScopedFlushDenormals() {
    _mm_setcsr(saved_);
  }
#else
  ScopedFlushDenormals() = default;
#endif
  ScopedFlushDenormals(const ScopedFlushDenormals&) = delete;
  ScopedFlushDenormals& operator=(const ScopedFlushDenormals&) = delete;

 private:
#if defined(DISPEX_HAVE_MXCSR)
  static constexpr unsigned kFlushToZero = 0x8000;
  static constexpr unsigned kDenormalsAreZero = 0x0040;
  unsigned saved_;
#endif
};

}  // namespace dispex::trace
