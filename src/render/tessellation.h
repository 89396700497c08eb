// The displaced limit surface as one triangle mesh (welded, or split where the faces of a map
// disagree), ready to ray-cast.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "dispex/vector_space.h"

namespace dispex::render {

// A triangle mesh with a unit shading normal per vertex.
struct ShadedMesh {
  Mesh mesh;                    // all faces triangles; positions with spare capacity for Embree
  std::vector<Float3> normals;  // one per vertex
};

// How the points shared by several faces (on cage edges, vertices, n-gon sub-face borders)
// are displaced.
enum class BoundaryDisplacement : std::uint8_t {
  kMean,     // one vertex, moved by the mean of every face's map value there: no cracks
  kPerFace,  // one copy per face, each moved by its own face's value, as a renderer reading
             // each face on its own does: cracks and steps where the faces' values differ
};

// Tessellates every Ptex face f of `surface` (except holes and faces with density {0, 0}) into
// density[f][0] x density[f][1] cells of its (u, v) square, evaluates the limit surface at the
// grid points and moves each along its limit normal by the map's value there (channel
// `channel`, bilinear as PtexFile::Sample reads it; no displacement when map is null). With
// `vector_space`, the map is a vector map: each point P moves to P + D, D =
// VectorFromChannels(*vector_space, the frame of the face at the point, its three channels
// read there) (include/dispex/vector_space.h), and `channel` is not used.
//
// Points on the cage's edges, vertices and (for n-gons) sub-face borders are shared by every
// face that touches them. With kMean they are one vertex, evaluated on the lowest-numbered such
// face, displaced by the mean of all those faces' map values there (of a vector map, the mean
// of their D in object space, each from its own face's frame and channels). With kPerFace every
// face has its own copy of each (the same limit position and normal, from the lowest-numbered
// face), displaced by that face's value at its own (u, v); a face meeting a point at two (u, v)
// gets a copy for each. Where neighbours have different densities, the cells along the shared
// border take the other side's extra points (a fan around the cell centre; with kPerFace the face's
// own copies of them), so the undisplaced mesh has no cracks and no T-junctions, and with
// kPerFace the displaced one opens exactly where the map's faces disagree. Vertex normals are
// the area-weighted mean of the displaced triangles' normals (the limit normal where that is
// zero); with kPerFace the copies of a point at the same displaced position count as one
// vertex, so shading is smooth where the faces agree and shows a seam where they do not. The
// result does not depend on the thread count.
//
// Requires: `cage` is the mesh `surface` was built from; density.size() == number of Ptex
// faces, each side in 1..1024 or both 0. Fails, naming the face, when the map's data is
// corrupt or not finite, or when the mesh would exceed 2^31 - 1 indices.
StatusOr<ShadedMesh> TessellateLimitSurface(
    const Mesh& cage, const LimitSurface& surface, std::span<const std::array<int, 2>> density,
    const PtexFile* map, int channel, BoundaryDisplacement boundary = BoundaryDisplacement::kMean,
    std::optional<VectorSpace> vector_space = std::nullopt);

// Triangulates any polygon mesh (fans) and gives it area-weighted vertex normals computed on
// its own polygons (Newell normals), for rendering meshes such as the sculpt.
ShadedMesh ShadePolygonMesh(const Mesh& mesh);

}  // namespace dispex::render
