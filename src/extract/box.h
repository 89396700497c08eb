// An axis-aligned box of floats: where a Ptex face's rays can reach (face_keys.h), a block of
// sculpt cells or the ray windows of samples (sculpt_blocks.h, far_sheets.h).
#pragma once

#include <array>

namespace dispex::extract {

struct Box {
  std::array<float, 3> lower{}, upper{};
  // Closed: boxes that touch meet.
  bool Meets(const Box& o) const {
    return lower[0] <= o.upper[0] && o.lower[0] <= upper[0] && lower[1] <= o.upper[1] &&
           o.lower[1] <= upper[1] && lower[2] <= o.upper[2] && o.lower[2] <= upper[2];
  }
};

}  // namespace dispex::extract
