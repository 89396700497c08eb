// The surface a review page shows: the base's limit surface on a grid per Ptex face, displaced
// by a map, as one mesh whose points on face borders are shared by the faces that meet there.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"

namespace dispex::view {

// How a map displaces points of one Ptex face: for n points at (u, v) (2 floats each) with
// their limit frames (3 floats per point in each), D (3 floats per point, object space) and
// the value the page colours by (the scalar, or D's normal part). Called from several threads
// at once for distinct or equal faces.
class MapDisplacement {
 public:
  virtual ~MapDisplacement() = default;
  virtual void Displace(PtexFaceId face, std::span<const float> uv,
                        const LimitEvaluator::Frames& frames, std::span<float> d,
                        std::span<float> value) const = 0;
};

// The quads per side of each Ptex face for `grid` quads per side of a quad face: grid on a
// quad, grid / 2 on an n-gon's sub-face, 0 on a hole.
std::vector<std::uint16_t> FaceQuads(const LimitSurface& surface, int grid);
// Vertices of the faces' grids when `quads` are their quads per side (an upper bound of the
// mesh's vertices: points shared by faces count once per face).
std::int64_t GridPoints(std::span<const std::uint16_t> quads);

struct SurfaceGrid {
  int grid = 0;
  std::vector<std::uint16_t> quads;  // per Ptex face (FaceQuads)
  // The mesh's vertices: first the points inside each face (not on its border), face after
  // face, row after row (v, then u, from 0); then the points on face borders, each once (a
  // point shared by several faces is the mean of their points: the displaced surface closes
  // where faces meet), in the order their first face lists them.
  std::vector<Float3> limit;         // P
  std::vector<Float3> displacement;  // D
  std::vector<float> value;
  // Per face with quads n > 0, the ids of its (n + 1)^2 - (n - 1)^2 border points, in the
  // order of its grid (rows of constant v from v = 0, u from 0 within a row).
  std::vector<std::uint32_t> border;
  std::int64_t triangles = 0;
  std::int64_t shared_points = 0;  // border points that faces share
};

// Evaluates the limit surface at every face's grid points ((i / n, j / n), i, j = 0..n),
// displaces them by `map` and joins the faces' border points (through the adjacency in
// `faces`, the map's face table: PtexAcrossEdge). Fails, naming the base face, where
// OpenSubdiv cannot evaluate a face, and naming `map_name` for values that are not finite.
StatusOr<SurfaceGrid> BuildSurfaceGrid(const LimitSurface& surface,
                                       std::span<const PtexFaceInfo> faces, int grid,
                                       const MapDisplacement& map, const std::string& map_name);

}  // namespace dispex::view
