// Validation of a sculpt before it becomes a ray-tracing scene: every check that keeps Embree
// (and the closest-point code, which reads the same arrays) from reading out of bounds or
// building a BVH over NaN bounds.
#pragma once

#include <cstddef>

#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex::trace {

struct SculptCounts {
  std::size_t quads = 0;           // faces of 4 vertices
  std::size_t triangles = 0;       // faces of 3 vertices, plus n - 2 per n-gon (fan)
  std::size_t triangle_faces = 0;  // faces of exactly 3 vertices
};

// Checks, in parallel, and reports the lowest offending element so the message does not
// depend on the thread count: the mesh has faces; face_offsets start at 0, never decrease
// and end at face_indices.size(); every face has at least 3 vertices; every vertex index is
// in range; every vertex a face uses has a finite position; primitive counts fit in int32.
// Fills `counts` on success.
Status CheckSculpt(const Mesh& mesh, SculptCounts* counts);

}  // namespace dispex::trace
