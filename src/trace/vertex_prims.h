// The scene's primitives around each sculpt vertex: which faces meet where a ray hits an edge
// or a vertex, for the tie rule of the normal queries (batch_kernels.h, ResolveTie).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex::trace {

// Primitives are numbered over both geometries of an EmbreeScene: quads 0..num_quads-1, then
// the triangles. Within one vertex the order is not fixed (the build is parallel); users treat
// each list as a set.
struct VertexPrims {
  std::vector<std::uint32_t> offsets;  // per vertex, into prims; num_vertices + 1 entries
  std::vector<std::uint32_t> prims;
  std::size_t num_quads = 0;
  // Per primitive: 1 where the sculpt folds, i.e. two triangles around one of its vertices
  // face against each other (normals at more than 90 degrees): overlapping sheets may meet a
  // ray there within rounding of each other.
  std::vector<std::uint8_t> folded;

  std::span<const std::uint32_t> around(std::int32_t vertex) const {
    const auto v = static_cast<std::size_t>(vertex);
    return {prims.data() + offsets[v], prims.data() + offsets[v + 1]};
  }
};

// Whether a table of these primitives fits (fewer than 2^32 corners), else why not.
Status CheckVertexPrimsFit(std::size_t num_quads, std::size_t num_triangles);

// From the index arrays the scene holds (4 ids per quad, 3 per triangle; either may be empty),
// every id below num_vertices, and the positions. Precondition: CheckVertexPrimsFit.
VertexPrims BuildVertexPrims(const std::int32_t* quads, std::size_t num_quads,
                             const std::int32_t* triangles, std::size_t num_triangles,
                             const Float3* positions, std::size_t num_vertices);

}  // namespace dispex::trace
