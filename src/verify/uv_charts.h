// The cage's face-varying UVs as a function of (Ptex face, u, v), for the image pattern.
//
// Linear face-varying interpolation (OpenSubdiv's Sdc FVAR_LINEAR_ALL) makes the UV of a
// limit point bilinear in its Ptex coordinates: over a quad's four corner UVs, and on
// sub-face k of an n-gon over the corners of the quad that the first Catmull-Clark split cuts
// from it -- the face's corner k, the midpoint of edge k (corner k to k+1), the face's
// centroid and the midpoint of edge k-1 -- at Ptex (0,0), (1,0), (1,1) and (0,1), the sub-face
// parameterisation of Far::PtexIndices (include/dispex/subdiv.h). Every later split of a
// bilinear quad is bilinear again, so this is exact at every level.
#pragma once

#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"

namespace dispex::verify {

class PtexUvCharts {
 public:
  // Fails with "<cage>: ..." when the cage has no UVs (saying why when the reader dropped
  // them) or when `surface` is not the cage's (face counts differ).
  static StatusOr<PtexUvCharts> Build(const Mesh& cage, const LimitSurface& surface);

  // The UV at (u, v) of `face` (in range; u, v in [0, 1]).
  void Evaluate(PtexFaceId face, double u, double v, double uv[2]) const {
    const double* c = &corners_[8 * static_cast<std::size_t>(face.value)];
    const double w0 = (1 - u) * (1 - v), w1 = u * (1 - v), w2 = u * v, w3 = (1 - u) * v;
    uv[0] = w0 * c[0] + w1 * c[2] + w2 * c[4] + w3 * c[6];
    uv[1] = w0 * c[1] + w1 * c[3] + w2 * c[5] + w3 * c[7];
  }

  int num_ptex_faces() const { return static_cast<int>(corners_.size() / 8); }

 private:
  std::vector<double> corners_;  // per Ptex face: UVs at (0,0), (1,0), (1,1), (0,1)
};

}  // namespace dispex::verify
