// Hole filling for a face's grid of signed distances.
//
// Pull-push (Gortler et al., "The Lumigraph", 1996, §3.3; the push-pull scheme of
// Grossman & Dally 1998): valid samples carry weight 1, misses weight 0; "pull" builds a
// pyramid of weighted 2x2 averages with weights clamped to 1, "push" fills each cell from the
// bilinear interpolation of the coarser level in proportion to its missing weight. Every
// miss gets a value that is a smooth blend of the nearest valid samples, and valid samples are
// never changed.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dispex/ptex.h"

namespace dispex::extract {

// Reusable buffers, so filling allocates nothing once warmed up.
struct PullPushScratch {
  std::vector<float> values;
  std::vector<float> weights;
};

// Fills values[i] where valid[i] == 0 (nx*ny grid, x fastest). Returns the number of samples
// filled, or -1 if the grid has no valid sample (nothing is changed then).
int FillHolesPullPush(float* values, const std::uint8_t* valid, int nx, int ny,
                      PullPushScratch& scratch);

// Mean value along each edge of a Ptex face's grid (edge 0: v = 0, 1: u = 1, 2: v = 1,
// 3: u = 0), the summary a neighbouring face that missed entirely is filled from.
struct EdgeMeans {
  float mean[4] = {0, 0, 0, 0};
};
EdgeMeans ComputeEdgeMeans(const float* values, int nx, int ny);

// Faces whose rays all missed, filled from their neighbours. `filled[f]` is true for faces with
// values; `edges[f]` their edge means; `faces` the Ptex face table (its adjacency: -1 = none). For
// each empty face the value across each edge is the neighbour's mean along the shared edge; the
// face becomes the constant mean of those. Faces reached only through other empty faces are filled
// in later rounds (breadth-first, deterministic). Returns, per face, the constant value, and marks
// it filled; faces no filled face can reach stay unfilled.
struct CrossFaceFill {
  std::vector<std::int32_t> faces;  // faces filled this way, in order
  std::vector<float> values;        // their constant values
  std::size_t unreachable = 0;      // empty faces with no filled face in their component
};
CrossFaceFill FillEmptyFaces(std::vector<std::uint8_t>& filled, std::vector<EdgeMeans>& edges,
                             std::span<const PtexFaceInfo> faces);

}  // namespace dispex::extract
