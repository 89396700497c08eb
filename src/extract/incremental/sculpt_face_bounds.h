// A sculpt face's corners and the box around them, as the face keys (face_keys.cpp) and the
// search distance's ray cells (ray_cache.cpp) key and place each sculpt face.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "dispex/mesh.h"

namespace dispex::extract {

struct FaceBounds {
  std::array<float, 3> centre;
  // The larger distance from the centre to the box's sides, not yet rounded up by an ulp for
  // a centre an ulp off the middle (SculptReachKeys rounds the largest of all faces').
  float half_extent = 0;
};

// The corners of sculpt face `s`, xyz after xyz, in storage re-used from face to face: a
// fixed array up to 8 corners, a growing one beyond.
class Corners {
 public:
  std::span<const float> Of(const Mesh& sculpt, std::size_t s) {
    const std::span<const std::int32_t> face = sculpt.face(s);
    float* out = fixed_.data();
    if (3 * face.size() > fixed_.size()) {
      spill_.resize(3 * face.size());
      out = spill_.data();
    }
    for (std::size_t c = 0; c < face.size(); ++c) {
      const Float3& p = sculpt.positions[static_cast<std::size_t>(face[c])];
      out[3 * c] = p.x;
      out[3 * c + 1] = p.y;
      out[3 * c + 2] = p.z;
    }
    return {out, 3 * face.size()};
  }

 private:
  std::array<float, 3 * 8> fixed_;
  std::vector<float> spill_;
};

// The bounding box of corners `xyz` (Corners::Of): its centre and half-size.
inline FaceBounds Bounds(std::span<const float> xyz) {
  std::array<float, 3> lower{INFINITY, INFINITY, INFINITY};
  std::array<float, 3> upper{-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t i = 0; i < xyz.size(); i += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      lower[k] = std::min(lower[k], xyz[i + k]);
      upper[k] = std::max(upper[k], xyz[i + k]);
    }
  }
  FaceBounds b;
  for (int k = 0; k < 3; ++k) {
    b.centre[k] = 0.5f * (lower[k] + upper[k]);
    b.half_extent =
        std::max(b.half_extent, std::max(upper[k] - b.centre[k], b.centre[k] - lower[k]));
  }
  return b;
}

}  // namespace dispex::extract
