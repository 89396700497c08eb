// A cheap first look at the limit surface, before the faces are sampled in full: each Ptex
// face's area and a sparse set of limit points and normals, from a 4x4 grid per face.
#pragma once

#include <vector>

#include "dispex/status.h"
#include "dispex/subdiv.h"

namespace dispex::extract {

struct CoarseSampling {
  std::vector<double> face_areas;       // per Ptex face (0 for holes)
  std::vector<Float3> points, normals;  // at most ~64K, spread over all faces
};

StatusOr<CoarseSampling> SampleCoarsely(const LimitSurface& surface);

}  // namespace dispex::extract
