// The sculpt on a review page: decimated by vertex clustering to a budget of vertices.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dispex/mesh.h"

namespace dispex::view {

struct DecimatedMesh {
  std::vector<Float3> positions;
  std::vector<Float3> normals;           // unit, per vertex: the mesh's own (below)
  std::vector<std::uint32_t> triangles;  // 3 vertex ids each, the faces' winding kept
  double cell = 0;                       // the clustering's cell size (0: the mesh whole)
};

// A mesh of at most `max_vertices` vertices (>= 1) that looks like `mesh` from a distance: the
// mesh itself, its faces split into triangle fans, when its vertices that faces use fit;
// otherwise every vertex goes to the cube of a grid of cell size h that holds it, a cube's
// vertices become one (their mean), and the triangles whose corners fall in three distinct
// cubes are kept, each once (turned to face along the mesh's normals where the clustering
// turned them over), with h the smallest tried (growing by the square root of the excess)
// that keeps within the budget. A vertex's normal is the mesh's there: the sum of the
// area vectors of the faces at the vertex (at the cube's vertices), normalised, so that the
// shading stays the sculpt's where the clustering folds triangles over. Deterministic;
// parallel over TBB's arena.
DecimatedMesh DecimateByClustering(const Mesh& mesh, std::int64_t max_vertices);

}  // namespace dispex::view
