// The cage refined L times as grids of quads on its Ptex faces (dispex/correspondence.h): the
// counts of the refinement, each Ptex face's grid size, and what lies across each Ptex face
// edge, from the base topology (OpenSubdiv's level 0) and the Ptex layout of n-gons.
//
// Positions along a Ptex face edge run counter-clockwise around the face: edge 0 (v = 0) from
// (0,0) to (1,0), edge 1 (u = 1) from (1,0) to (1,1), edge 2 (v = 1) from (1,1) to (0,1),
// edge 3 (u = 0) from (0,1) to (0,0). On a grid of size n they count cells (0..n-1) or grid
// points (0..n).
#pragma once

#include <opensubdiv/far/topologyLevel.h>

#include <cstdint>
#include <vector>

#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "subdiv/surface_impl.h"

namespace dispex::subdiv {

// A place on a Ptex face's edge; face < 0 for none.
struct PtexEdgePlace {
  int face = -1;
  int edge = 0;
  int position = 0;
};

struct GridPoint {
  int i = 0, j = 0;
};

class RefinedCage {
 public:
  // Fails (one line starting with the cage's source) for cages the grids cannot describe: an
  // edge with more than two faces, an edge a face uses twice, or two faces running an edge the
  // same way.
  static StatusOr<RefinedCage> Build(const LimitSurface::Impl& surface);

  // The refinement's face and vertex counts at `levels`, holes dropped; 0 faces when the
  // level is impossible (levels 0 with a face that has a surface and is not a quad).
  std::uint64_t CountFaces(int levels) const;
  std::uint64_t CountVertices(int levels) const;

  // Sets the level the grids and the crossings below use (counts allow it).
  void SetLevels(int levels);
  int levels() const { return levels_; }

  int num_ptex_faces() const { return static_cast<int>(s_->ptex_base.size()); }
  bool is_hole(int ptex) const { return s_->ptex_hole[ptex] != 0; }
  // n, the grid of Ptex face `ptex` is n x n cells; 0 for holes.
  int grid_size(int ptex) const;

  // What lies across Ptex face `ptex`'s edge `edge` at `position` (cells when `cells`, else
  // grid points): the Ptex face, its edge and the position on it; none on a boundary of the
  // surface (a boundary of the cage or a hole beyond).
  PtexEdgePlace Across(int ptex, int edge, int position, bool cells) const;

  // The cell (cells) or grid point at `position` along `edge` of a grid of size n.
  static GridPoint OnEdge(int n, int edge, int position, bool cells);

  // The base vertex at corner c of a Ptex face (0: (0,0), 1: (1,0), 2: (1,1), 3: (0,1)), or
  // -1 where none is (the corners of an n-gon's sub-face other than 0).
  int CornerVertex(int ptex, int corner) const;

  int num_vertices() const { return static_cast<int>(valence_.size()); }
  // Among the faces with a surface: how many use the vertex, and whether one of its edges
  // has only one such face.
  int valence(int vertex) const { return valence_[vertex]; }
  bool boundary(int vertex) const { return boundary_[vertex] != 0; }
  bool non_manifold(int vertex) const { return base_->IsVertexNonManifold(vertex); }
  // The (Ptex face, corner) places of a vertex on the faces with a surface, lowest face first.
  struct Corner {
    int ptex;
    int corner;
  };
  const Corner* corners_begin(int vertex) const { return &corners_[corner_offsets_[vertex]]; }
  const Corner* corners_end(int vertex) const { return &corners_[corner_offsets_[vertex + 1]]; }

 private:
  int FaceSize(int base_face) const { return base_->GetFaceVertices(base_face).size(); }

  const LimitSurface::Impl* s_ = nullptr;
  const OpenSubdiv::Far::TopologyLevel* base_ = nullptr;
  int levels_ = 0;
  int edge_cells_ = 1;  // cells along a base edge: 2^levels
  int half_cells_ = 0;  // and along its half: the grid size of an n-gon's sub-face
  // Per corner of a base face (CSR over faces): the face across its edge k (v_k -> v_k+1)
  // and that edge's index in it, or -1.
  std::vector<std::int32_t> face_corner_offsets_;
  std::vector<std::int32_t> across_face_;
  std::vector<std::int8_t> across_edge_;
  std::vector<std::uint16_t> valence_;
  std::vector<std::uint8_t> boundary_;
  std::vector<std::int32_t> corner_offsets_;
  std::vector<Corner> corners_;
  // Counts of the faces with a surface: quads, the sizes of the others, and the vertices and
  // edges they use.
  std::uint64_t quads_ = 0, ngons_ = 0, ngon_corners_ = 0, used_vertices_ = 0, used_edges_ = 0;
};

}  // namespace dispex::subdiv
