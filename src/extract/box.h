// An axis-aligned box of floats: where a Ptex face's rays can reach (face_keys.h), a block of
// sculpt cells or the ray windows of samples (sculpt_blocks.h, far_sheets.h).
#pragma once

#include <array>
#include <limits>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace dispex::extract {

struct Box {
  std::array<float, 3> lower{}, upper{};
  // The box of no point (lower > upper): it meets nothing, and growing it by a box gives that box.
  static Box Empty() {
    constexpr float kInfinity = std::numeric_limits<float>::infinity();
    return {{kInfinity, kInfinity, kInfinity}, {-kInfinity, -kInfinity, -kInfinity}};
  }
  // Closed: boxes that touch meet; a NaN bound meets nothing.
  bool Meets(const Box& o) const {
#if defined(__SSE2__)
    // Six comparisons in two, with one branch: the far-sheet check makes many per sample.
    // (lower, upper.x) <= (o.upper, +inf) and (-inf, o.lower) <= (lower.z, upper).
    constexpr float kInfinity = __builtin_huge_valf();
    const __m128 head = _mm_loadu_ps(lower.data()), tail = _mm_loadu_ps(lower.data() + 2);
    const __m128 o_upper = _mm_setr_ps(o.upper[0], o.upper[1], o.upper[2], kInfinity);
    const __m128 o_lower = _mm_setr_ps(-kInfinity, o.lower[0], o.lower[1], o.lower[2]);
    return _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(head, o_upper), _mm_cmple_ps(o_lower, tail))) ==
           0xF;
#else
    return lower[0] <= o.upper[0] && o.lower[0] <= upper[0] && lower[1] <= o.upper[1] &&
           o.lower[1] <= upper[1] && lower[2] <= o.upper[2] && o.lower[2] <= upper[2];
#endif
  }
};
// Meets reads the six bounds as two overlapping runs of four floats.
static_assert(sizeof(Box) == 6 * sizeof(float));

}  // namespace dispex::extract
