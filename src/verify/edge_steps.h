// The steps a map shows where Ptex faces meet: on every shared edge, the value read from one
// side minus the value read from the other, under the per-face and the cross-face reader
// (include/dispex/ptex_sampler.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/verify.h"

namespace dispex {

// The map's face table for the sampler: resolutions from the map, adjacency and sub-face
// flags from the base's limit surface (the map's own adjacency is not trusted).
std::vector<PtexFaceInfo> MapFacesOnSurface(const LimitSurface& surface, const PtexFile& map);

// Per Ptex face, bit e set when its edge e lies on an infinitely sharp crease of the base: the
// limit normal, and so the displacement, is discontinuous there.
std::vector<std::uint8_t> SharpCreaseEdges(const Mesh& base, const LimitSurface& surface);

// Steps on every edge between two faces with a surface, at t = j / n (j = 0..n) along it,
// n = max(16, 2 x the finer side's texels along the edge): every texel centre and edge of
// either side, where the piecewise-linear steps have their extremes, so `max` is exact.
// Sharp-crease edges are counted, not measured. Deterministic: per face in face order.
struct EdgeSteps {
  std::size_t edges = 0, crease_edges = 0;
  std::vector<float> per_face, across_faces;  // one |step| per point
  std::vector<VerifyReport::WorstEdge> worst;  // largest first, at most 10, either reader
};
EdgeSteps MeasureEdgeSteps(std::span<const PtexFaceInfo> faces,
                           std::span<const std::vector<float>> texels,
                           std::span<const std::uint8_t> crease_edges,
                           std::span<const std::uint8_t> hole_faces);

}  // namespace dispex
