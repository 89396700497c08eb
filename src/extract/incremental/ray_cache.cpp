#include "extract/incremental/ray_cache.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "core/byte_record.h"
#include "core/cache_files.h"
#include "dispex/files.h"
#include "extract/incremental/face_keys.h"
#include "extract/incremental/sculpt_face_bounds.h"

namespace dispex::extract {
namespace {

constexpr char kMagic[8] = {'D', 'X', 'R', 'A', 'Y', 'S', '0', '2'};
constexpr const char* kPrefix = "rays-";
// The rays' box is grown by this fraction of their length: a hit may lie a little past the
// window (retries past a surface in the margin, trace.h).
constexpr double kLengthMargin = 0.05;

std::array<float, 3> At(const Float3& p, const Float3& n, double t) {
  return {static_cast<float>(double(p.x) + t * double(n.x)),
          static_cast<float>(double(p.y) + t * double(n.y)),
          static_cast<float>(double(p.z) + t * double(n.z))};
}

// Calls visit(cell index) for the cells of points of ray i at side * t, t in [from, to] (side
// 0: both sides), a step of half the smallest cell apart: every point of it lies within a
// quarter cell of one of them.
template <class Visit>
void ForEachCellOnRay(const RayGrid& grid, const LongRays& rays, std::size_t i, double from,
                      double to, std::int8_t side, Visit&& visit) {
  const double step = 0.5 * grid.min_cell_size();
  const auto steps = static_cast<std::int64_t>(std::ceil((to - from) / step));
  std::size_t last = std::numeric_limits<std::size_t>::max();
  for (double sign : {1.0, -1.0}) {
    if (side == -sign) continue;
    for (std::int64_t k = 0; k <= steps; ++k) {
      const double t = sign * std::min(to, from + double(k) * step);
      const std::size_t cell = grid.Index(grid.CellOf(At(rays.origins[i], rays.normals[i], t)));
      if (cell != last) visit(cell);
      last = cell;
    }
  }
}

struct Hits {
  std::vector<float> t;
  std::vector<std::int8_t> side;
};

// Per ray of `cast`, its nearest hit on the sculpt faces centred in a flagged cell (a BVH of
// only those, built with `options`), or infinity.
StatusOr<Hits> NearestOnCells(const Mesh& sculpt, const RayGrid& grid,
                              std::span<const std::uint8_t> cells, const TracerOptions& options,
                              const LongRays& rays, std::span<const std::size_t> cast) {
  std::vector<std::uint8_t> keep(sculpt.num_faces(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sculpt.num_faces(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      Corners corners;
                      for (std::size_t s = range.begin(); s != range.end(); ++s) {
                        const FaceBounds b = Bounds(corners.Of(sculpt, s));
                        keep[s] = cells[grid.Index(grid.CellOf(b.centre))];
                      }
                    });
  const Mesh part = SculptPart(sculpt, keep);
  keep = {};
  Hits hits{std::vector<float>(cast.size(), std::numeric_limits<float>::infinity()),
            std::vector<std::int8_t>(cast.size(), 0)};
  if (part.num_faces() == 0) return hits;
  std::vector<Float3> origins(cast.size()), normals(cast.size());
  for (std::size_t j = 0; j < cast.size(); ++j) {
    origins[j] = rays.origins[cast[j]];
    normals[j] = rays.normals[cast[j]];
  }
  DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<Tracer> tracer, MakeEmbreeTracer(part, options));
  LowerNearestHits(*tracer, origins, normals, rays.length, hits.t, hits.side);
  DISPEX_RETURN_IF_ERROR(tracer->status());
  return hits;
}

// `flags` with every cell within `radius` cells (Chebyshev) of a flagged one flagged too.
std::vector<std::uint8_t> Dilate(std::vector<std::uint8_t> flags, int radius) {
  constexpr int n = kRayGridCells;
  std::vector<std::uint8_t> next(flags.size());
  for (int axis = 0; axis < 3; ++axis) {
    const std::size_t stride = axis == 0 ? 1 : axis == 1 ? n : std::size_t{n} * n;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, flags.size(), std::size_t{1} << 12),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t c = range.begin(); c != range.end(); ++c) {
                          const int at = static_cast<int>((c / stride) % n);
                          const std::size_t row = c - static_cast<std::size_t>(at) * stride;
                          std::uint8_t any = 0;
                          for (int d = std::max(0, at - radius);
                               d <= std::min(n - 1, at + radius) && !any; ++d) {
                            any = flags[row + static_cast<std::size_t>(d) * stride];
                          }
                          next[c] = any;
                        }
                      });
    flags.swap(next);
  }
  return flags;
}

}  // namespace

RayGrid::RayGrid(const LongRays& rays) {
  box_ = Box::Empty();
  const double reach = double(rays.length) * (1 + kLengthMargin);
  for (std::size_t i = 0; i < rays.origins.size(); ++i) {
    for (double t : {-reach, reach}) {
      const std::array<float, 3> p = At(rays.origins[i], rays.normals[i], t);
      for (int k = 0; k < 3; ++k) {
        box_.lower[k] = std::min(box_.lower[k], p[k]);
        box_.upper[k] = std::max(box_.upper[k], p[k]);
      }
    }
  }
  min_cell_ = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (!(box_.lower[k] <= box_.upper[k])) box_.lower[k] = box_.upper[k] = 0;
    const double size = std::max(double(box_.upper[k]) - double(box_.lower[k]), 1e-30);
    scale_[k] = kRayGridCells / size;
    min_cell_ = std::min(min_cell_, size / kRayGridCells);
  }
}

std::array<int, 3> RayGrid::CellOf(const std::array<float, 3>& p) const {
  std::array<int, 3> c{};
  for (int k = 0; k < 3; ++k) {
    const double x = (double(p[k]) - double(box_.lower[k])) * scale_[k];
    c[k] = static_cast<int>(std::clamp(std::floor(x), 0.0, double(kRayGridCells - 1)));
  }
  return c;
}

Hash128 RaysKey(const LongRays& rays, const RayGrid& grid) {
  Hasher h;
  h.Add(std::string_view("dispex search distance rays 1")).Add(kRayGridCells);
  h.AddArray(rays.origins).AddArray(rays.normals).Add(rays.length);
  h.Add(grid.box());
  return h.Digest();
}

void KeySculptCells(const Mesh& sculpt, const RayGrid& grid, RayCache& cache) {
  std::vector<std::atomic<std::uint64_t>> lanes(2 * grid.num_cells());
  std::atomic<float> half_extent{0};
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, sculpt.num_faces(), 1 << 14),
      [&](const tbb::blocked_range<std::size_t>& range) {
        float local_half = 0;
        Corners corners;
        for (std::size_t s = range.begin(); s != range.end(); ++s) {
          const std::span<const float> xyz = corners.Of(sculpt, s);
          const FaceBounds b = Bounds(xyz);
          local_half = std::max(local_half, b.half_extent);
          const Hash128 key = HashBytes(std::as_bytes(xyz));
          const std::size_t cell = grid.Index(grid.CellOf(b.centre));
          lanes[2 * cell].fetch_add(key.low, std::memory_order_relaxed);
          lanes[2 * cell + 1].fetch_add(key.high, std::memory_order_relaxed);
        }
        float seen = half_extent.load(std::memory_order_relaxed);
        while (local_half > seen && !half_extent.compare_exchange_weak(seen, local_half)) {
        }
      });
  cache.cells.resize(grid.num_cells());
  for (std::size_t c = 0; c < cache.cells.size(); ++c) {
    cache.cells[c] = {lanes[2 * c].load(), lanes[2 * c + 1].load()};
  }
  cache.half_extent = std::nextafter(half_extent.load(), INFINITY);
}

std::string RayCachePath(const std::string& folder, const std::string& sculpt_path,
                         const std::string& base_fingerprint) {
  if (folder.empty()) return {};
  Hasher h;
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(sculpt_path, ec);
  h.Add(std::string_view(ec ? sculpt_path : absolute.lexically_normal().string()));
  h.Add(std::string_view(base_fingerprint));
  return (std::filesystem::path(folder) / (kPrefix + h.Digest().Hex() + ".bin")).string();
}

std::optional<RayCache> ReadRayCache(const std::string& path, const Hash128& rays_key) {
  const std::optional<CacheRecord> read =
      ReadCacheRecord(path, std::string_view(kMagic, sizeof(kMagic)));
  if (!read) return std::nullopt;
  const std::string_view body = read->bytes;
  RayCache cache;
  std::size_t at = sizeof(kMagic);
  if (!Take(body, at, cache.rays_key) || !(cache.rays_key == rays_key) ||
      !Take(body, at, cache.half_extent) || !TakeArray(body, at, cache.cells) ||
      !TakeArray(body, at, cache.nearest) || !TakeArray(body, at, cache.side) ||
      cache.side.size() != cache.nearest.size() || at != body.size() ||
      cache.cells.size() != std::size_t{kRayGridCells} * kRayGridCells * kRayGridCells) {
    return std::nullopt;
  }
  return cache;
}

bool WriteRayCache(const std::string& path, const RayCache& cache) {
  std::string bytes(kMagic, sizeof(kMagic));
  Append(bytes, cache.rays_key);
  Append(bytes, cache.half_extent);
  AppendArray(bytes, cache.cells);
  AppendArray(bytes, cache.nearest);
  AppendArray(bytes, cache.side);
  if (!WriteCacheRecord(path, std::move(bytes))) return false;
  EvictCacheFiles(std::filesystem::path(path).parent_path().string(), kPrefix, kRayCacheBytes,
                  path);
  return true;
}

Status UpdateNearestHits(const Mesh& sculpt, const TracerOptions& tracer_options,
                         const LongRays& rays, const RayGrid& grid, const RayCache& previous,
                         RayCache& current, std::int64_t& recast) {
  const std::size_t num_rays = rays.origins.size();
  // Around a point, the faces that can matter: those meeting it (their box centres within one
  // half-extent h of it), and for the tie rule the faces sharing a vertex with those (within
  // 3h). A ray's steps leave every point of it within a quarter cell of one; a centre within
  // d of a point (per axis) lies at most floor(d / cell) + 1 cells from the point's cell.
  const double h = std::max(previous.half_extent, current.half_extent);
  const double cells_reach = 3 * h / grid.min_cell_size() + 0.25;
  const int radius =
      cells_reach > kRayGridCells ? kRayGridCells : static_cast<int>(std::floor(cells_reach)) + 1;
  std::vector<std::uint8_t> changed(grid.num_cells());
  for (std::size_t c = 0; c < changed.size(); ++c) {
    changed[c] = !(previous.cells[c] == current.cells[c]);
  }
  const std::vector<std::uint8_t> dirty = Dilate(std::move(changed), radius);

  // kKeep: no cell near the ray changed, nor did its hit. kLower: its previous hit's
  // neighbourhood is unchanged, so only a changed face can lower it. kRecast: its previous hit
  // may have moved.
  enum : std::uint8_t { kKeep, kLower, kRecast };
  const double reach = double(rays.length) * (1 + kLengthMargin);
  auto KindOfRay = [&](std::size_t i) -> std::uint8_t {
    bool near_change = false;
    ForEachCellOnRay(grid, rays, i, 0, reach, 0,
                     [&](std::size_t c) { near_change = near_change || dirty[c]; });
    if (!near_change) return kKeep;
    if (!std::isfinite(previous.nearest[i])) return kLower;
    for (double sign : {-1.0, 1.0}) {
      if (previous.side[i] == -sign) continue;
      const double t = sign * double(previous.nearest[i]);
      if (dirty[grid.Index(grid.CellOf(At(rays.origins[i], rays.normals[i], t)))]) return kRecast;
    }
    return kLower;
  };
  std::vector<std::uint8_t> kind(num_rays, kKeep);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_rays, 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        kind[i] = KindOfRay(i);
                      }
                    });
  std::vector<std::size_t> cast, recast_rays;
  for (std::size_t i = 0; i < num_rays; ++i) {
    if (kind[i] != kKeep) cast.push_back(i);
    if (kind[i] == kRecast) recast_rays.push_back(i);
  }
  recast = static_cast<std::int64_t>(cast.size());
  current.nearest = previous.nearest;
  current.side = previous.side;
  if (cast.empty()) return Status::Ok();

  // First against the sculpt centred near the changed cells: every changed face with the faces
  // around it, and the face of every previous hit that lay near a change (with those around
  // it). A hit on a face there whose neighbourhood the part lacks can only be farther than the
  // whole sculpt's (the tie rule picks the nearest of fewer faces), and an unchanged face's hit
  // is no nearer than the ray's previous |t| (it was there before): kLower takes the nearer of
  // its previous |t| and this.
  const std::vector<std::uint8_t> first_cells = Dilate(dirty, radius);
  DISPEX_ASSIGN_OR_RETURN(const Hits first,
                          NearestOnCells(sculpt, grid, first_cells, tracer_options, rays, cast));
  std::vector<float> first_of(num_rays, std::numeric_limits<float>::infinity());
  std::vector<std::int8_t> first_side(num_rays, 0);
  for (std::size_t j = 0; j < cast.size(); ++j) {
    const std::size_t i = cast[j];
    first_of[i] = first.t[j];
    first_side[i] = first.side[j];
    KeepNearerHit(current.nearest[i], current.side[i], first.t[j], first.side[j]);
  }
  // kRecast: its nearest is a changed face's (found above, whole around it) or an unchanged
  // face's at |t| from its previous |t| up to the first pass's. Where the sculpt along those
  // windows, with the faces around, was all in the first pass's part, the first pass's hit is
  // it; else the rays are cast again against the sculpt along their windows, and take the
  // nearer of the two passes.
  std::vector<std::uint8_t> window(grid.num_cells());
  for (std::size_t i : recast_rays) {
    const double from = previous.nearest[i];
    const double to = std::min(reach, double(first_of[i]));
    if (from <= to) {
      ForEachCellOnRay(grid, rays, i, from, to, previous.side[i],
                       [&](std::size_t c) { window[c] = 1; });
    }
  }
  const std::vector<std::uint8_t> second_cells = Dilate(std::move(window), radius);
  bool covered = true;
  for (std::size_t c = 0; c < second_cells.size() && covered; ++c) {
    covered = !second_cells[c] || first_cells[c];
  }
  Hits second;
  if (!covered) {
    DISPEX_ASSIGN_OR_RETURN(
        second, NearestOnCells(sculpt, grid, second_cells, tracer_options, rays, recast_rays));
  }
  for (std::size_t j = 0; j < recast_rays.size(); ++j) {
    const std::size_t i = recast_rays[j];
    current.nearest[i] = first_of[i];
    current.side[i] = first_side[i];
    if (!covered) KeepNearerHit(current.nearest[i], current.side[i], second.t[j], second.side[j]);
  }
  return Status::Ok();
}

}  // namespace dispex::extract
