// The sculpt's vertex displacements interpolated through the subdivision correspondence
// (ExtractMethod::kInterpolate, docs/ACCURACY.md "Interpolated vertex displacements").
//
// A sculpt that is the base refined L times puts vertex (a, b) of Ptex face f's m x m grid at
// (u, v) = (a / m, b / m); its displacement is D_ab = S_ab - P(a / m, b / m), the sculpt vertex
// minus the limit point it sits over, and h_ab = D_ab . N(a / m, b / m) its part along the
// limit normal. Between the vertices D and h are bilinear over the grid's cell: the field a
// renderer's subdivided base, displaced at its vertices, shows, and exact at the vertices
// whatever the sculpt's facets do between them. A face reads only its own grid's vertices.
#pragma once

#include <span>
#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"

namespace dispex::extract {

// One Ptex face's grid of vertex displacements; per-thread, reused across faces.
class GridDisplacements {
 public:
  // Evaluates face `face`'s grid: `vertices` holds the (m + 1)^2 sculpt vertex ids of its grid
  // row by row (vertex (a, b) at b (m + 1) + a). `normals`: also h (for scalar maps). Kept
  // while the same face is asked for again (the edge rounds sample a face more than once).
  Status Evaluate(PtexFaceId face, int m, std::span<const VertexId> vertices, const Mesh& sculpt,
                  LimitEvaluator& evaluator, bool normals);
  int face() const { return face_; }
  int m() const { return m_; }
  // At Ptex (u, v) in [0, 1] of the face evaluated: the cell i = min(floor(u m), m - 1),
  // s = u m - i (likewise j, t), and D or h bilinear over its corners, in double.
  void DisplacementAt(double u, double v, double out[3]) const;
  double HeightAt(double u, double v) const;

 private:
  struct Cell {
    int i = 0, j = 0;
    double s = 0, t = 0;
  };
  Cell CellAt(double u, double v) const;

  int face_ = -1, m_ = 0;
  bool normals_ = false;
  std::vector<float> uv_, positions_, limit_normals_;
  std::vector<double> d_;  // 3 per vertex
  std::vector<double> h_;  // 1 per vertex, with normals
};

}  // namespace dispex::extract
