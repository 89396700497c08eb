// The base cage's UVs as a function of the limit surface's (Ptex face, u, v), and its inverse:
// the Ptex place of every texel centre of a UDIM tile.
//
// The rule is linear face-varying interpolation (OpenSubdiv's Sdc FVAR_LINEAR_ALL; Blender's
// Subdivision Surface modifier with "UV Smooth: None"): the UV of a limit point is bilinear in
// its Ptex coordinates, over a quad's four corner UVs, and on sub-face k of an n-gon over the
// corners of the quad the first Catmull-Clark split cuts from it -- the face's corner k, the
// midpoint of edge k (corner k to k+1), the face's centroid and the midpoint of edge k-1 -- at
// Ptex (0,0), (1,0), (1,1) and (0,1), the sub-face parameterisation of Far::PtexIndices
// (include/dispex/subdiv.h). Every later split of a bilinear quad is bilinear again, so this
// is exact at every level (docs/UV_MAPS.md).
//
// UDIM tiles: tile (tu, tv) covers UV [tu, tu+1) x [tv, tv+1) and is numbered 1001 + tu + 10 tv
// (tu in 0..9, tv >= 0). Texel (i, j) of an N x N tile has its centre at
// (tu + (i+0.5)/N, tv + (j+0.5)/N): j counts from v = 0 up (an image's bottom row).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"

namespace dispex {

class PtexUvCharts {
 public:
  // Fails with "<cage>: ..." when the cage has no UVs (naming the first face without when only
  // some faces have them) or when `surface` is not the cage's (face counts differ).
  static StatusOr<PtexUvCharts> Build(const Mesh& cage, const LimitSurface& surface);

  // The UV at (u, v) of `face` (in range; u, v in [0, 1]).
  void Evaluate(PtexFaceId face, double u, double v, double uv[2]) const {
    const double* c = corners(face);
    const double w0 = (1 - u) * (1 - v), w1 = u * (1 - v), w2 = u * v, w3 = (1 - u) * v;
    uv[0] = w0 * c[0] + w1 * c[2] + w2 * c[4] + w3 * c[6];
    uv[1] = w0 * c[1] + w1 * c[3] + w2 * c[5] + w3 * c[7];
  }
  // The face's UVs at Ptex (0,0), (1,0), (1,1), (0,1), as (u, v) pairs.
  const double* corners(PtexFaceId face) const {
    return &corners_[8 * static_cast<std::size_t>(face.value)];
  }

  int num_ptex_faces() const { return static_cast<int>(corners_.size() / 8); }

 private:
  std::vector<double> corners_;
};

// The UDIM number of the tile holding `uv` (floor of each coordinate), or 0 when that tile
// is outside 1001..1999's columns 0..9 (u < 0, u >= 10 or v < 0, v >= 99).
int UdimOfUv(double u, double v);

// Where each texel centre of the tiles a cage's UVs touch lies on the limit surface.
struct UvTexelPlace {
  std::int32_t face = -1;  // Ptex face; -1: the centre is in no UV face (a seam's outside)
  float u = 0, v = 0;
};

struct UvTile {
  int udim = 0;
  std::vector<UvTexelPlace> places;  // N x N, row-major, i fastest, row 0 at v = tile's 0
  std::int64_t inside = 0;           // texel centres in some UV face
  std::vector<std::int32_t> faces;   // the Ptex faces whose UVs reach the tile, ascending
};

struct UvRaster {
  int resolution = 0;         // N
  std::vector<UvTile> tiles;  // by UDIM number, ascending
  std::int64_t inside = 0;    // texel centres in some UV face
  // Texel centres clearly inside two or more UV faces (more than 1e-4 of their Ptex (u, v)
  // range from each one's border): overlapping UVs. Each such texel goes to the face it lies
  // deepest in (the largest distance to that face's border in Ptex units; the lower Ptex face
  // id on a tie), so the result depends on neither face order nor threads.
  std::int64_t overlap_texels = 0;
  std::vector<std::int32_t> overlap_faces;  // Ptex faces involved, ascending
  // UV faces whose UVs leave, in part, the tiles UDIM can number (u < 0 or >= 10, v < 0 or
  // >= 99): only their part inside those tiles is rasterised. By Ptex face, ascending.
  std::vector<std::int32_t> faces_outside_udim;
};

// Rasterises every Ptex face's UV footprint (hole faces excepted) into N x N tiles, inverting
// the bilinear rule per texel centre. `resolution` must be 1..16384. Parallel over bands of
// rows; the result does not depend on threads.
StatusOr<UvRaster> RasterizeUvCharts(const PtexUvCharts& charts, const LimitSurface& surface,
                                     int resolution);

// Fills the texels `filled` marks 0 by dilation, `padding` rings of texels outward from the
// filled ones: each pass gives every empty texel that has filled 8-neighbours (filled before
// the pass) the mean of those, channel by channel, and marks it filled. `values` holds
// `channels` floats per texel of an N x N tile (row-major); texels beyond the padding keep
// their value. Deterministic (each pass reads the previous one only).
void DilateTile(int resolution, int channels, int padding, std::span<float> values,
                std::span<std::uint8_t> filled);

}  // namespace dispex
