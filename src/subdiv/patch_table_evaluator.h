// Limit evaluation through Far::PatchTable + Far::PatchMap, for the faces that must not go
// through Bfr. OpenSubdiv 3.5's Bfr::IrregularPatchBuilder mishandles face neighbourhoods
// that fold over an interior valence-2 vertex (fixed upstream after 3.5.0, OpenSubdiv PRs
// #1301 and #1353): on OpenSubdiv's own catmark_val2_interior shape it warns "Edge N
// specified to be sharp does not exist", builds a surface without those creases, and can
// read out of bounds. Far's adaptive refinement handles these faces, so LimitSurface::Build
// routes every face whose neighbourhood holds such a vertex here.
#pragma once

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <memory>
#include <vector>

#include "dispex/status.h"

namespace dispex::subdiv {

class PatchTableEvaluator {
 public:
  // Adaptive refinement of `base_faces` only, to `isolation` (secondary level `smooth`),
  // Gregory-basis end caps, infinitely sharp patches, no legacy sharp corners, double
  // precision. `positions` holds xyz per base vertex.
  static StatusOr<std::unique_ptr<PatchTableEvaluator>> Build(
      const OpenSubdiv::Far::TopologyRefiner& base, const std::vector<double>& positions,
      const std::vector<int>& base_faces, int isolation, int smooth);

  // Position and derivatives (d/du, d/dv of the Ptex face) at Ptex (u,v). False if the Ptex
  // face is not one of the built faces.
  bool Evaluate(int ptex, double u, double v, double p[3], double du[3], double dv[3]) const;

 private:
  PatchTableEvaluator() = default;

  std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> refiner_;
  std::unique_ptr<OpenSubdiv::Far::PatchTable> table_;
  std::unique_ptr<OpenSubdiv::Far::PatchMap> map_;
  // The point type Far's interpolation templates expect.
  struct Point3 {
    double p[3];
    void Clear() { p[0] = p[1] = p[2] = 0; }
    void AddWithWeight(const Point3& src, double w) {
      p[0] += w * src.p[0];
      p[1] += w * src.p[1];
      p[2] += w * src.p[2];
    }
  };
  std::vector<Point3> points_;  // base, refined, then local points
};

}  // namespace dispex::subdiv
