// The Ptex place of every texel centre of the UDIM tiles a cage's UVs touch (see
// dispex/uv_charts.h): each face's UV footprint rasterised, the bilinear rule inverted per
// texel centre.
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "dispex/uv_charts.h"

namespace dispex {

namespace {

constexpr int kBandRows = 16;
// A texel centre counts as inside a face down to this far outside its Ptex [0,1]^2 (rounding),
// and as overlapping when it is this far inside two faces.
constexpr double kInsideSlack = 1e-9;
constexpr double kOverlapDepth = 1e-4;

double Cross(const double a[2], const double b[2]) {
  return a[0] * b[1] - a[1] * b[0];
}

// The Ptex (u, v) at which the face's bilinear UV map reaches `p`, and how deep inside [0,1]^2
// that is (min(u, 1-u, v, 1-v); negative outside). Of the quadratic's two roots, the deeper.
struct Inverse {
  double u = 0, v = 0, depth = -1;
};

Inverse InvertBilinear(const double* c, const double p[2]) {
  const double e[2] = {c[2] - c[0], c[3] - c[1]};
  const double f[2] = {c[6] - c[0], c[7] - c[1]};
  const double g[2] = {c[0] - c[2] + c[4] - c[6], c[1] - c[3] + c[5] - c[7]};
  const double h[2] = {p[0] - c[0], p[1] - c[1]};
  const double k2 = Cross(g, f);
  const double k1 = Cross(e, f) + Cross(h, g);
  const double k0 = Cross(h, e);
  const double disc = k1 * k1 - 4 * k0 * k2;
  Inverse best;
  if (!(disc >= 0)) return best;
  // Both roots without cancellation: q / k2 and k0 / q.
  const double q = -0.5 * (k1 + std::copysign(std::sqrt(disc), k1));
  double roots[2];
  int count = 0;
  if (q != 0) roots[count++] = k0 / q;
  if (k2 != 0) roots[count++] = q / k2;
  for (int r = 0; r < count; ++r) {
    const double v = roots[r];
    if (!std::isfinite(v)) continue;
    const double dx = e[0] + g[0] * v, dy = e[1] + g[1] * v;
    double u;
    if (std::abs(dx) >= std::abs(dy)) {
      if (dx == 0) continue;
      u = (h[0] - f[0] * v) / dx;
    } else {
      u = (h[1] - f[1] * v) / dy;
    }
    const double depth = std::min(std::min(u, 1 - u), std::min(v, 1 - v));
    if (std::isfinite(depth) && depth > best.depth) best = {u, v, depth};
  }
  return best;
}

struct FaceBox {
  double min[2], max[2];
};

FaceBox BoxOf(const double* c) {
  FaceBox b{{c[0], c[1]}, {c[0], c[1]}};
  for (int k = 1; k < 4; ++k) {
    for (int a = 0; a < 2; ++a) {
      b.min[a] = std::min(b.min[a], c[2 * k + a]);
      b.max[a] = std::max(b.max[a], c[2 * k + a]);
    }
  }
  return b;
}

// Tiles [first, last] along one axis that a face spanning [lo, hi] touches: a face ending
// exactly on a tile's border does not touch the next tile.
void TileRange(double lo, double hi, int& first, int& last) {
  first = static_cast<int>(std::floor(lo));
  last = std::max(first, static_cast<int>(std::ceil(hi)) - 1);
}

}  // namespace

StatusOr<UvRaster> RasterizeUvCharts(const PtexUvCharts& charts, const LimitSurface& surface,
                                     int resolution) {
  if (resolution < 1 || resolution > 16384) {
    return Status::Error(fmt::format("resolution = {}: must be 1..16384", resolution));
  }
  UvRaster raster;
  raster.resolution = resolution;
  const int n = charts.num_ptex_faces();
  std::vector<FaceBox> boxes(static_cast<std::size_t>(n));
  std::map<int, std::vector<std::int32_t>> tile_faces;
  for (int p = 0; p < n; ++p) {
    if (surface.is_hole(PtexFaceId(p))) continue;
    const FaceBox b = BoxOf(charts.corners(PtexFaceId(p)));
    boxes[static_cast<std::size_t>(p)] = b;
    int u0, u1, v0, v1;
    TileRange(b.min[0], b.max[0], u0, u1);
    TileRange(b.min[1], b.max[1], v0, v1);
    if (!(b.min[0] >= 0 && b.min[1] >= 0) || u1 > 9 || v1 > 98) {
      raster.faces_outside_udim.push_back(p);
      u0 = std::max(u0, 0);
      v0 = std::max(v0, 0);
      u1 = std::min(u1, 9);
      v1 = std::min(v1, 98);
    }
    for (int tv = v0; tv <= v1; ++tv) {
      for (int tu = u0; tu <= u1; ++tu) tile_faces[1001 + tu + 10 * tv].push_back(p);
    }
  }
  const auto texels = static_cast<std::size_t>(resolution) * static_cast<std::size_t>(resolution);
  std::vector<const std::vector<std::int32_t>*> lists;
  for (const auto& [udim, faces] : tile_faces) {
    raster.tiles.push_back({udim, std::vector<UvTexelPlace>(texels), 0, faces});
    lists.push_back(&faces);
  }
  const int bands = (resolution + kBandRows - 1) / kBandRows;
  const std::size_t tasks = raster.tiles.size() * static_cast<std::size_t>(bands);
  std::vector<std::int64_t> band_inside(tasks, 0), band_overlaps(tasks, 0);
  std::vector<std::set<std::int32_t>> band_overlap_faces(tasks);
  const double scale = resolution;
  tbb::parallel_for(std::size_t{0}, tasks, [&](std::size_t task) {
    UvTile& tile = raster.tiles[task / static_cast<std::size_t>(bands)];
    const int band = static_cast<int>(task % static_cast<std::size_t>(bands));
    const int row0 = band * kBandRows, row1 = std::min(resolution, row0 + kBandRows);
    const int tu = (tile.udim - 1001) % 10, tv = (tile.udim - 1001) / 10;
    std::vector<double> depth(static_cast<std::size_t>(kBandRows * resolution), -1.0);
    std::vector<std::uint8_t> overlapped(depth.size(), 0);
    for (std::int32_t p : *lists[task / static_cast<std::size_t>(bands)]) {
      const FaceBox& b = boxes[static_cast<std::size_t>(p)];
      const int i0 = std::max(0, static_cast<int>(std::ceil((b.min[0] - tu) * scale - 0.5)));
      const int i1 =
          std::min(resolution - 1, static_cast<int>(std::floor((b.max[0] - tu) * scale - 0.5)));
      const int j0 = std::max(row0, static_cast<int>(std::ceil((b.min[1] - tv) * scale - 0.5)));
      const int j1 =
          std::min(row1 - 1, static_cast<int>(std::floor((b.max[1] - tv) * scale - 0.5)));
      const double* c = charts.corners(PtexFaceId(p));
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
          const double centre[2] = {tu + (i + 0.5) / scale, tv + (j + 0.5) / scale};
          const Inverse inv = InvertBilinear(c, centre);
          if (inv.depth < -kInsideSlack) continue;
          const std::size_t local = static_cast<std::size_t>(j - row0) * resolution + i;
          UvTexelPlace& place = tile.places[static_cast<std::size_t>(j) * resolution + i];
          if (place.face >= 0 && inv.depth > kOverlapDepth && depth[local] > kOverlapDepth) {
            if (!overlapped[local]) ++band_overlaps[task];
            overlapped[local] = 1;
            band_overlap_faces[task].insert(place.face);
            band_overlap_faces[task].insert(p);
          }
          if (inv.depth > depth[local]) {
            if (place.face < 0) ++band_inside[task];
            depth[local] = inv.depth;
            place.face = p;
            place.u = static_cast<float>(std::clamp(inv.u, 0.0, 1.0));
            place.v = static_cast<float>(std::clamp(inv.v, 0.0, 1.0));
          }
        }
      }
    }
  });
  std::set<std::int32_t> overlap_faces;
  for (std::size_t t = 0; t < tasks; ++t) {
    raster.inside += band_inside[t];
    raster.tiles[t / static_cast<std::size_t>(bands)].inside += band_inside[t];
    raster.overlap_texels += band_overlaps[t];
    overlap_faces.insert(band_overlap_faces[t].begin(), band_overlap_faces[t].end());
  }
  raster.overlap_faces.assign(overlap_faces.begin(), overlap_faces.end());
  return raster;
}

void DilateTile(int resolution, int channels, int padding, std::span<float> values,
                std::span<std::uint8_t> filled) {
  const int n = resolution;
  std::vector<std::uint8_t> before;
  std::vector<float> sum(static_cast<std::size_t>(channels));
  for (int pass = 0; pass < padding; ++pass) {
    before.assign(filled.begin(), filled.end());
    bool changed = false;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const std::size_t t = static_cast<std::size_t>(j) * n + i;
        if (before[t]) continue;
        int count = 0;
        std::fill(sum.begin(), sum.end(), 0.0f);
        for (int dj = -1; dj <= 1; ++dj) {
          for (int di = -1; di <= 1; ++di) {
            const int x = i + di, y = j + dj;
            if (x < 0 || y < 0 || x >= n || y >= n) continue;
            const std::size_t s = static_cast<std::size_t>(y) * n + x;
            if (!before[s]) continue;
            ++count;
            for (int c = 0; c < channels; ++c) sum[c] += values[s * channels + c];
          }
        }
        if (count == 0) continue;
        for (int c = 0; c < channels; ++c) values[t * channels + c] = sum[c] / count;
        filled[t] = 1;
        changed = true;
      }
    }
    if (!changed) break;
  }
}

}  // namespace dispex
