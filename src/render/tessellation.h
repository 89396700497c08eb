// The displaced limit surface as one welded triangle mesh, ready to ray-cast.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"

namespace dispex::render {

// A triangle mesh with a unit shading normal per vertex.
struct ShadedMesh {
  Mesh mesh;                    // all faces triangles; positions with spare capacity for Embree
  std::vector<Float3> normals;  // one per vertex
};

// Tessellates every Ptex face f of `surface` (except holes and faces with density {0, 0}) into
// density[f][0] x density[f][1] cells of its (u, v) square, evaluates the limit surface at the
// grid points and moves each along its limit normal by the map's value there (channel
// `channel`, bilinear as PtexFile::Sample reads it; no displacement when map is null).
//
// Points on the cage's edges, vertices and (for n-gons) sub-face borders are shared by every
// face that touches them: they are one vertex, evaluated on the lowest-numbered such face,
// displaced by the mean of all those faces' map values there. Where neighbours have different
// densities, the cells along the shared border take the other side's extra points (a fan
// around the cell centre), so the mesh has no cracks and no T-junctions. Vertex normals are
// the area-weighted mean of the displaced triangles' normals (the limit normal where that is
// zero). The result does not depend on the thread count.
//
// Requires: `cage` is the mesh `surface` was built from; density.size() == number of Ptex
// faces, each side in 1..1024 or both 0. Fails, naming the face, when the map's data is
// corrupt or not finite, or when the mesh would exceed 2^31 - 1 indices.
StatusOr<ShadedMesh> TessellateLimitSurface(const Mesh& cage, const LimitSurface& surface,
                                            std::span<const std::array<int, 2>> density,
                                            const PtexFile* map, int channel);

// Triangulates any polygon mesh (fans) and gives it area-weighted vertex normals computed on
// its own polygons (Newell normals), for rendering meshes such as the sculpt.
ShadedMesh ShadePolygonMesh(const Mesh& mesh);

}  // namespace dispex::render
