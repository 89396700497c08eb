// The automatic search distance's long rays kept for the next incremental run, in the cache
// folder (CacheFolder): each ray's nearest |t| over the sculpt, and a key of the sculpt per cell
// of a grid over where the rays go. After an edit only the rays that pass near a cell whose key
// changed are cast again, against a BVH of the sculpt near them, and every ray's |t| is the one
// a BVH of the whole sculpt gives (LowerNearestHits): the estimate, and so the map, is the same
// bytes as a full extraction's, without that BVH.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/hash128.h"
#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/trace.h"
#include "extract/box.h"

namespace dispex::extract {

// EstimateSearchDistance's long rays: origins[i] +- t normals[i], |t| <= length.
struct LongRays {
  std::span<const Float3> origins, normals;
  float length = 0;
};

// kRayGridCells^3 cells over the box of every ray (a little longer than `length`); a point
// outside is in the nearest cell.
inline constexpr int kRayGridCells = 64;
class RayGrid {
 public:
  explicit RayGrid(const LongRays& rays);
  std::size_t num_cells() const {
    return std::size_t{kRayGridCells} * kRayGridCells * kRayGridCells;
  }
  std::array<int, 3> CellOf(const std::array<float, 3>& p) const;
  std::size_t Index(const std::array<int, 3>& c) const {
    return (static_cast<std::size_t>(c[2]) * kRayGridCells + static_cast<std::size_t>(c[1])) *
               kRayGridCells +
           static_cast<std::size_t>(c[0]);
  }
  double min_cell_size() const { return min_cell_; }
  const Box& box() const { return box_; }

 private:
  Box box_;
  std::array<double, 3> scale_{};  // cells per unit
  double min_cell_ = 0;
};

struct RayCache {
  Hash128 rays_key;               // the rays (origins, normals, length) and the grid: RaysKey
  float half_extent = 0;          // the largest half-size of a sculpt face's bounding box
  std::vector<Hash128> cells;     // per cell: the order-free sum of the keys of the sculpt faces
                                  // whose box centre is in it (their corners' positions)
  std::vector<float> nearest;     // per ray: |t| of its nearest hit on the sculpt, or infinity
  std::vector<std::int8_t> side;  // per ray: the side of that hit (LowerNearestHits)
};

Hash128 RaysKey(const LongRays& rays, const RayGrid& grid);

// Fills cache.cells and cache.half_extent for `sculpt`. Parallel, deterministic.
void KeySculptCells(const Mesh& sculpt, const RayGrid& grid, RayCache& cache);

// The cache file in `folder` of the rays of the base `base_fingerprint` over the sculpt file at
// `sculpt_path` ("" without a folder). Whatever sculpt the file was written for, the update is
// exact; the same file only keeps it local.
std::string RayCachePath(const std::string& folder, const std::string& sculpt_path,
                         const std::string& base_fingerprint);
// A cache file as written, or nullopt when it is missing, damaged or not for `rays_key`.
std::optional<RayCache> ReadRayCache(const std::string& path, const Hash128& rays_key);
// Writes it (false when it cannot be), then keeps the folder's ray files within kRayCacheBytes
// (least recently written first out).
inline constexpr std::uint64_t kRayCacheBytes = std::uint64_t{1} << 30;
bool WriteRayCache(const std::string& path, const RayCache& cache);

// Every ray's nearest |t| over `sculpt` into current.nearest, from `previous` (the same rays
// over the sculpt as it was) and current.cells (KeySculptCells of `sculpt`): a ray none of whose
// cells within reach of a sculpt face's neighbourhood changed keeps its |t|; the others are cast
// against a BVH (built with `tracer_options`) of the sculpt centred near the changed cells and
// near the rays whose previous hit lies there. `recast`: how many were cast.
Status UpdateNearestHits(const Mesh& sculpt, const TracerOptions& tracer_options,
                         const LongRays& rays, const RayGrid& grid, const RayCache& previous,
                         RayCache& current, std::int64_t& recast);

}  // namespace dispex::extract
