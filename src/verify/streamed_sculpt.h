// A refined sculpt too large to hold in memory (a film-scale benchmark asset), written as it is
// evaluated: the all-quad cage refined `levels` times has n x n quads per base face (n =
// 2^levels), and its vertices are the base's vertices, n - 1 points inside every base edge and
// (n - 1)^2 inside every base face, each on the limit surface at its dyadic (u, v) and moved by
// the pattern's D there. The same surface as MakeSculpt's refined layout, with the vertices in
// another order; memory grows with the cage, not with the sculpt.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <string_view>

#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "verify/pattern_field.h"

namespace dispex::verify {

struct StreamedSculpt {
  std::size_t vertices = 0, faces = 0;
  // Over the vertices: the range of h = D.N, the largest |D| and |D - h N|.
  double h_min = std::numeric_limits<double>::infinity();
  double h_max = -std::numeric_limits<double>::infinity();
  double max_displacement = 0, max_tangential = 0;
};

// Writes the sculpt as binary PLY (atomically) with `comment`. Fails, before writing anything,
// on a cage with a face that is not a quad or is a hole, or with more than 2^31 - 1 vertices.
StatusOr<StreamedSculpt> WriteStreamedRefinement(const Mesh& cage, const LimitSurface& surface,
                                                 int levels, const PatternField& pattern,
                                                 const std::string& path, std::string_view comment);

}  // namespace dispex::verify
