// Area-weighted vertex normals of a polygon mesh, for the displaced limit surface
// (tessellation.cpp) and for meshes rendered as they are (ShadePolygonMesh, tessellation.h,
// defined in vertex_normals.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dispex/mesh.h"

namespace dispex::render {

// Vertex normals: for each vertex the sum of its faces' (area-weighted) normals, in face
// order, normalised; `fallback` (or +z) where the sum vanishes. A face listing a vertex twice
// counts once there.
void VertexNormals(std::size_t num_vertices, std::span<const std::uint32_t> face_offsets,
                   std::span<const std::int32_t> face_indices, std::span<const Float3> face_normals,
                   std::span<const Float3> fallback, std::vector<Float3>& normals);

}  // namespace dispex::render
