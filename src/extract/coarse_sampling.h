// A cheap first look at the limit surface, before the faces are sampled in full: each Ptex
// face's area and a sparse set of limit points and normals, from a 4x4 grid per face.
#pragma once

#include <cstdint>
#include <vector>

#include "dispex/status.h"
#include "dispex/subdiv.h"

namespace dispex::extract {

struct CoarseSampling {
  static constexpr int kGrid = 4;       // texel centres per side of each face
  std::vector<double> face_areas;       // per Ptex face (0 for holes)
  std::vector<Float3> points, normals;  // at most ~64K, spread over all faces
  // Per point: its Ptex face * kGrid^2 + its index j * kGrid + i in the face's grid; ascending.
  std::vector<std::int64_t> ids;
};

StatusOr<CoarseSampling> SampleCoarsely(const LimitSurface& surface);

}  // namespace dispex::extract
