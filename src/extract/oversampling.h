// Automatic oversampling: how many samples per side each Ptex face needs to catch every
// feature of the sculpt over it.
//
// A sculpt that is the base subdivided L times (its face count says so exactly: 4^L quads per
// base quad, n 4^(L-1) per n-gon) is sampled at 2^(L+1) per side on quads and 2^L on n-gon
// sub-faces: two samples per sculpt quad. Any other sculpt is measured by density: with k
// sculpt quads (a triangle counts as half a quad) over a face's area, the face gets the power
// of two nearest above 2 sqrt(k) (within a quarter octave), between the minimum and maximum.
#pragma once

#include <cstdint>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"

namespace dispex::extract {

struct OversamplingPlan {
  std::vector<std::uint8_t> log2;  // per Ptex face: samples per side = 1 << log2 (0 for holes)
  int subdivision_level = -1;      // L when the sculpt is the base subdivided L times
  // Measured only when the density decides (no subdivision level, no fixed rate):
  double sculpt_quads = 0;  // sculpt area in quad equivalents
  double sculpt_area = 0;
  double base_area = 0;
};

// `face_areas`: the limit-surface area of each Ptex face (0 for holes).
OversamplingPlan PlanOversampling(const LimitSurface& surface, const Mesh& sculpt,
                                  const std::vector<double>& face_areas, int fixed, int min_samples,
                                  int max_samples);

}  // namespace dispex::extract
