// LimitSurface's private state, shared (read-only) by evaluators and uniform refinement.
#pragma once

#include <opensubdiv/far/topologyRefiner.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dispex/subdiv.h"
#include "subdiv/patch_table_evaluator.h"

namespace dispex {

struct LimitSurface::Impl {
  std::string source;
  SubdivOptions options;  // approximation levels resolved (approx_level_sharp != 0)
  std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> refiner;

  std::vector<double> positions;  // xyz per cage vertex, for Bfr (double inside)

  // Ptex numbering (Far::PtexIndices): first Ptex face per base face, plus the total at end.
  std::vector<std::int32_t> first_ptex;
  std::vector<std::int32_t> ptex_base;   // base face of each Ptex face
  std::vector<std::uint16_t> ptex_sub;   // sub-face index (0 for quads)
  std::vector<std::uint8_t> ptex_hole;   // 1: no limit surface
  std::vector<PtexAdjacency> adjacency;  // per Ptex face
  std::vector<CageEdge> inf_sharp_edges;
  // Base faces that must not reach Bfr (see patch_table_evaluator.h), evaluated through
  // `patch_table` instead (null when there are none).
  std::vector<std::uint8_t> use_patch_table;
  std::unique_ptr<subdiv::PatchTableEvaluator> patch_table;
  LimitSurfaceStats stats;

  int num_base_faces() const { return static_cast<int>(first_ptex.size()) - 1; }
  int num_ptex_faces() const { return first_ptex.back(); }
  int face_size(int base_face) const {
    return refiner->GetLevel(0).GetFaceVertices(base_face).size();
  }
};

// The state of a surface, for the subdiv module's evaluators and uniform refinement.
inline const LimitSurface::Impl& SurfaceImpl(const LimitSurface& surface) {
  return *surface.impl_;
}

}  // namespace dispex
