// The sculpt's vertex displacements interpolated through the subdivision correspondence
// (ExtractMethod::kInterpolate, docs/ACCURACY.md "Interpolated vertex displacements").
//
// A sculpt that is the base refined L times puts vertex (a, b) of Ptex face f's m x m grid at
// (u, v) = (a / m, b / m); its displacement is D_ab = S_ab - P(a / m, b / m), the sculpt vertex
// minus the limit point it sits over, and h_ab = D_ab . N(a / m, b / m) its part along the
// limit normal. Between the vertices D and h are bilinear over the grid's cell.
//
// Read back at a vertex, a map blends the texels around it, and samples a quarter of a cell
// from the vertex blend a bilinear field to D + (1/8) L D, L D = the sum of the vertex's four
// neighbours - 4 D: the sculpt's bend there, the sculpt's own linear error, which on fine
// detail is many tolerances. So the field sampled on n x n texel centres is that of the
// vertex values D - (m / 4n) L D (for n >= m: samples at m / 2n of a cell from a vertex blend
// to D + (m / 4n) L D), whose blend gives D back up to the fourth differences. L needs the
// neighbour across a face edge: the first row of vertices of the neighbour's grid
// (SculptMapping::Crossing), with its own limit point. A vertex at a corner of any grid (a
// base vertex, often extraordinary; the middle of an n-gon's edge) or on an open border keeps D,
// so every face that holds a vertex gives it the same value.
#pragma once

#include <span>
#include <vector>

#include "dispex/correspondence.h"
#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "extract/mapping/mapping_trace.h"

namespace dispex::extract {

// Where Ptex faces' grids of sculpt vertices, and their neighbours across face edges, come
// from: the mapping (scalar maps) or the correspondence (vector maps). Kept for the run
// (ExtractInputs::grids).
class GridSource {
 public:
  virtual ~GridSource() = default;
  virtual int grid_size(int face) const = 0;
  virtual VertexId vertex(int face, int a, int b, const Mesh& sculpt) const = 0;
  // The (m + 1)^2 vertices of `face`'s grid row by row, vertex (a, b) at b (m + 1) + a.
  virtual void grid(int face, const Mesh& sculpt, std::vector<VertexId>& out) const = 0;
  virtual const SculptMapping::Crossing& crossing(int face, int edge) const = 0;
};

class MappingGrids final : public GridSource {
 public:
  explicit MappingGrids(const SculptMapping& mapping) : mapping_(mapping) {}
  int grid_size(int face) const override { return mapping_.grid_size(face); }
  VertexId vertex(int face, int a, int b, const Mesh& sculpt) const override {
    return mapping_.GridVertex(face, a, b, sculpt);
  }
  void grid(int face, const Mesh& sculpt, std::vector<VertexId>& out) const override {
    mapping_.GridVertices(face, sculpt, out);
  }
  const SculptMapping::Crossing& crossing(int face, int edge) const override {
    return mapping_.crossing(face, edge);
  }

 private:
  const SculptMapping& mapping_;
};

class CorrespondenceGrids final : public GridSource {
 public:
  CorrespondenceGrids(const SculptCorrespondence& correspondence,
                      std::span<const PtexFaceInfo> faces)
      : correspondence_(correspondence),
        crossings_(SculptMapping::Crossings(faces, correspondence.grid_sizes)) {}
  int grid_size(int face) const override { return correspondence_.grid_size(PtexFaceId(face)); }
  VertexId vertex(int face, int a, int b, const Mesh&) const override {
    return correspondence_.vertex(PtexFaceId(face), a, b);
  }
  void grid(int face, const Mesh&, std::vector<VertexId>& out) const override {
    const std::span<const VertexId> g = correspondence_.grid(PtexFaceId(face));
    out.assign(g.begin(), g.end());
  }
  const SculptMapping::Crossing& crossing(int face, int edge) const override {
    return crossings_[4 * static_cast<std::size_t>(face) + static_cast<std::size_t>(edge)];
  }

 private:
  const SculptCorrespondence& correspondence_;
  std::vector<SculptMapping::Crossing> crossings_;
};

// A vertex just outside a face's grid: one cell outward from `inner` (an edge vertex of the
// face's grid, not a corner), vertex (a, b) of face `face`'s grid.
struct ApronVertex {
  int inner = 0;  // b (m + 1) + a of the edge vertex
  int face = 0, a = 0, b = 0;
  VertexId id;
};

// Those of every edge of `face` with a neighbour laid out on the other side, edge by edge.
void ApronVertices(const GridSource& source, int face, const Mesh& sculpt,
                   std::vector<ApronVertex>& out);
// What a face's interpolated texels read (the face keys of incremental runs hold it): its
// grid's vertices, then its apron's, and the faces its apron lies on (their limit points), in
// increasing order.
void FaceFieldVertices(const GridSource& source, int face, const Mesh& sculpt,
                       std::vector<VertexId>& vertices, std::vector<int>& apron_faces);

// One Ptex face's grid of vertex displacements; per-thread, reused across faces.
class GridDisplacements {
 public:
  // Evaluates face `face`'s grid and its apron. `normals`: also h (for scalar maps). Kept
  // while the same face is asked for again (the edge rounds sample a face more than once).
  Status Evaluate(PtexFaceId face, const GridSource& source, const Mesh& sculpt,
                  LimitEvaluator& evaluator, bool normals);
  int face() const { return face_; }
  int m() const { return m_; }
  // The field read by DisplacementAt and HeightAt: sampled on `n` x `n` texel centres (the
  // vertex values corrected for the blend), or 0: the plain bilinear field, for samples at
  // no fixed place against the vertices (UV-space texels). Needed after each Evaluate.
  void SetSampling(int n);
  // At Ptex (u, v) in [0, 1] of the face evaluated: the cell i = min(floor(u m), m - 1),
  // s = u m - i (likewise j, t), and D or h bilinear over its corners, in double.
  void DisplacementAt(double u, double v, double out[3]) const;
  double HeightAt(double u, double v) const;

 private:
  // The four vertices of the cell holding (u, v) and their bilinear weights.
  struct Cell {
    std::size_t k[4];
    double w[4];
  };
  Cell CellAt(double u, double v) const;
  Status EvaluateApron(const GridSource& source, const Mesh& sculpt, LimitEvaluator& evaluator);
  void Bend();

  int face_ = -1, m_ = 0;
  bool normals_ = false;
  std::vector<VertexId> vertices_;
  std::vector<ApronVertex> apron_;
  std::vector<float> uv_, positions_, limit_normals_;
  std::vector<double> d_, h_;              // 3 and (with normals) 1 per vertex
  std::vector<double> bend_d_, bend_h_;    // L D and L h per vertex (0 where not defined)
  std::vector<double> read_d_, read_h_;    // D - (m / 4n) L D, and h likewise: what is read
  std::vector<double> outer_d_, outer_h_;  // D and h of the apron vertex, by apron entry
  std::vector<int> outer_of_;              // per grid vertex: its apron entry, or -1
};

}  // namespace dispex::extract
