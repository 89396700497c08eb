#include "extract/incremental/face_keys.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <span>
#include <string>
#include <utility>

#include "dispex/version.h"
#include "extract/incremental/field_keys.h"
#include "extract/incremental/sculpt_face_bounds.h"

namespace dispex::extract {

namespace {

// The region each Ptex face's rays can reach: its patch's box grown by the longest search,
// plus a margin for the limit surface's approximation near extraordinary vertices and for
// rounding (a larger box only costs re-extraction, a smaller one stale faces).
std::vector<Box> ReachBoxes(const LimitSurface& surface, const std::vector<BaseFacePatch>& patches,
                            double reach) {
  std::vector<Box> boxes(static_cast<std::size_t>(surface.num_ptex_faces()));
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    const BaseFacePatch& p =
        patches[static_cast<std::size_t>(surface.base_face(PtexFaceId(f)).value)];
    const std::array<float, 3> lo{p.lower.x, p.lower.y, p.lower.z};
    const std::array<float, 3> hi{p.upper.x, p.upper.y, p.upper.z};
    double extent = 0;
    for (int k = 0; k < 3; ++k) extent = std::max(extent, double(hi[k]) - double(lo[k]));
    const double grow = 1.01 * reach + 0.05 * extent + 1e-6 * (1 + extent + reach);
    Box& b = boxes[static_cast<std::size_t>(f)];
    for (int k = 0; k < 3; ++k) {
      b.lower[k] = static_cast<float>(std::nextafter(double(lo[k]) - grow, -INFINITY));
      b.upper[k] = static_cast<float>(std::nextafter(double(hi[k]) + grow, INFINITY));
    }
  }
  return boxes;
}

// A uniform grid over the reach boxes, `per_side` cells per (median) box side, at most
// kMaxCells cells.
class CellGrid {
 public:
  static constexpr std::size_t kMaxCells = std::size_t{1} << 20;

  CellGrid(const std::vector<Box>& boxes, const std::vector<std::uint8_t>& skip, double per_side) {
    bounds_.lower = {INFINITY, INFINITY, INFINITY};
    bounds_.upper = {-INFINITY, -INFINITY, -INFINITY};
    std::vector<float> sides;
    for (std::size_t f = 0; f < boxes.size(); ++f) {
      if (skip[f]) continue;
      float side = 0;
      for (int k = 0; k < 3; ++k) {
        bounds_.lower[k] = std::min(bounds_.lower[k], boxes[f].lower[k]);
        bounds_.upper[k] = std::max(bounds_.upper[k], boxes[f].upper[k]);
        side = std::max(side, boxes[f].upper[k] - boxes[f].lower[k]);
      }
      sides.push_back(side);
    }
    if (sides.empty()) return;
    std::nth_element(sides.begin(), sides.begin() + sides.size() / 2, sides.end());
    double cell_side = std::max<double>(sides[sides.size() / 2] / per_side, 1e-30);
    for (;; cell_side *= 1.25) {
      std::size_t total = 1;
      for (int k = 0; k < 3; ++k) {
        const double span = double(bounds_.upper[k]) - double(bounds_.lower[k]);
        dims_[k] = static_cast<int>(std::clamp(std::ceil(span / cell_side), 1.0, 1024.0));
        scale_[k] = span > 0 ? dims_[k] / span : 0;
        total *= static_cast<std::size_t>(dims_[k]);
      }
      if (total <= kMaxCells) break;
    }
  }

  std::size_t num_cells() const { return static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2]; }
  // Whether a point lies within `grow` of the grid (a box grown by at most that reaches it).
  bool Near(const std::array<float, 3>& p, float grow) const {
    for (int k = 0; k < 3; ++k) {
      if (!(p[k] >= bounds_.lower[k] - grow && p[k] <= bounds_.upper[k] + grow)) return false;
    }
    return true;
  }
  // The cell of a point; points outside the grid go to the nearest border cell.
  std::size_t CellOf(const std::array<float, 3>& p) const {
    return Index(Cell(p[0], 0), Cell(p[1], 1), Cell(p[2], 2));
  }
  // Calls visit(cell) for every cell that meets `box` grown by `grow` on every side.
  template <class Visit>
  void ForEachCell(const Box& box, float grow, Visit visit) const {
    std::array<int, 3> lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = Cell(box.lower[k] - grow, k);
      hi[k] = Cell(box.upper[k] + grow, k);
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) visit(Index(x, y, z));
      }
    }
  }

 private:
  int Cell(float x, int axis) const {
    const double c = (double(x) - double(bounds_.lower[axis])) * scale_[axis];
    return static_cast<int>(std::clamp(std::floor(c), 0.0, double(dims_[axis] - 1)));
  }
  std::size_t Index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
  }

  Box bounds_;
  std::array<int, 3> dims_{1, 1, 1};
  std::array<double, 3> scale_{0, 0, 0};
};

// The longest distance a query's rays go.
double Reach(const ExtractSettings& settings) {
  return std::max<double>(settings.query.distance, settings.retry_query.distance);
}

// Per reach box, the order-free sum of the keys of the sculpt faces that can meet it: each
// sculpt face's key is added to the cell of its centroid, and a box sums the cells within the
// largest half-extent of a sculpt face from it (every face whose bounding box meets the box has
// its centroid there; faces in those cells that do not meet it only make the key change more
// often than it must).
// Also returns the largest half-extent of a sculpt face, and per box the number of sculpt faces
// in those cells.
std::vector<Hash128> SculptReachKeys(const Mesh& sculpt, const std::vector<Box>& boxes,
                                     const std::vector<std::uint8_t>& skip, float& half_extent,
                                     std::vector<std::int64_t>& reach_faces) {
  const CellGrid grid(boxes, skip, /*per_side=*/2);
  struct Sums {
    std::vector<Hash128> cells;
    std::vector<std::int64_t> counts;
    float half_extent = 0;
  };
  tbb::combinable<Sums> sums([&] {
    return Sums{std::vector<Hash128>(grid.num_cells()), std::vector<std::int64_t>(grid.num_cells()),
                0.0f};
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sculpt.num_faces(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      Sums& local = sums.local();
                      Corners corners;
                      for (std::size_t s = range.begin(); s != range.end(); ++s) {
                        const std::span<const float> xyz = corners.Of(sculpt, s);
                        const FaceBounds b = Bounds(xyz);
                        local.half_extent = std::max(local.half_extent, b.half_extent);
                        const std::size_t cell = grid.CellOf(b.centre);
                        local.cells[cell] += HashBytes(std::as_bytes(xyz));
                        ++local.counts[cell];
                      }
                    });
  std::vector<Hash128> cells(grid.num_cells());
  std::vector<std::int64_t> counts(grid.num_cells());
  half_extent = 0;
  sums.combine_each([&](const Sums& part) {
    for (std::size_t c = 0; c < cells.size(); ++c) {
      cells[c] += part.cells[c];
      counts[c] += part.counts[c];
    }
    half_extent = std::max(half_extent, part.half_extent);
  });
  // Rounding up the largest is rounding up each: nextafter is monotonic.
  half_extent = std::nextafter(half_extent, INFINITY);
  std::vector<Hash128> keys(boxes.size());
  reach_faces.assign(boxes.size(), 0);
  tbb::parallel_for(std::size_t{0}, boxes.size(), [&](std::size_t f) {
    if (skip[f]) return;
    grid.ForEachCell(boxes[f], half_extent, [&](std::size_t c) {
      keys[f] += cells[c];
      reach_faces[f] += counts[c];
    });
  });
  return keys;
}

}  // namespace

Hash128 MeshContentKey(const Mesh& mesh) {
  Hasher h;
  h.AddArray(std::span<const Float3>(mesh.positions));
  h.AddArray(std::span<const std::uint32_t>(mesh.face_offsets));
  h.AddArray(std::span<const std::int32_t>(mesh.face_indices));
  const SubdivTags& t = mesh.tags;
  h.Add(t.creases.size());
  for (const auto& c : t.creases) h.Add(c.v0.value).Add(c.v1.value).Add(c.sharpness);
  h.Add(t.corners.size());
  for (const auto& c : t.corners) h.Add(c.vertex.value).Add(c.sharpness);
  h.Add(t.holes.size());
  for (const auto& face : t.holes) h.Add(face.value);
  h.Add(static_cast<int>(t.boundary)).Add(static_cast<int>(t.crease_method));
  h.Add(static_cast<int>(t.triangles));
  return h.Digest();
}

Hash128 SettingsKey(const ExtractSettings& s) {
  Hasher h;
  h.Add(std::string_view(std::string("dispex face key 1 ") + Version()));
  h.Add(s.query.distance).Add(static_cast<int>(s.query.policy));
  h.Add(s.retry_query.distance).Add(static_cast<int>(s.retry_query.policy));
  h.Add(static_cast<int>(s.spectral.rule)).Add(s.spectral.tolerance);
  h.Add(s.spectral.nonzero_threshold).Add(s.spectral.fixed_ulog2).Add(s.spectral.fixed_vlog2);
  h.Add(s.spectral.pin_edges).Add(s.spectral.edge_tolerance);
  h.Add(static_cast<int>(s.holes)).Add(static_cast<int>(s.data_type));
  h.Add(static_cast<int>(s.watertight)).Add(s.edge_step_budget).Add(s.max_samples_log2);
  // Rays' keys stay as they were; a map of either method re-uses only its own faces.
  if (s.mapping) h.Add(std::string_view("mapping"));
  if (s.interpolate) h.Add(std::string_view("interpolate"));
  return h.Digest();
}

void AddGridKey(Hasher& h, const Mesh& sculpt, int m, std::span<const VertexId> grid,
                std::vector<Float3>& scratch) {
  h.Add(m);
  scratch.clear();
  for (const VertexId id : grid) {
    scratch.push_back(sculpt.positions[static_cast<std::size_t>(id.value)]);
  }
  h.AddArray(std::span<const Float3>(scratch));
}

void AddFieldKey(Hasher& h, const ExtractInputs& inputs, std::span<const BaseFacePatch> patches,
                 int f, std::vector<VertexId>& ids, std::vector<int>& faces,
                 std::vector<Float3>& points) {
  FaceFieldVertices(*inputs.grids, f, inputs.sculpt, ids, faces);
  AddGridKey(h, inputs.sculpt, inputs.grids->grid_size(f), ids, points);
  for (const int g : faces) {
    const PtexFaceId face(g);
    const BaseFacePatch& patch =
        patches[static_cast<std::size_t>(inputs.surface.base_face(face).value)];
    h.Add(g).Add(patch.key[0]).Add(patch.key[1]).Add(inputs.surface.sub_face(face));
  }
}

namespace {

// Interpolated (ExtractSettings::interpolate), a face reads its grid of sculpt vertices and the
// row beyond each edge: its key holds their key (ComputeFieldKeys). No rays: no reach boxes.
FaceKeys GridFaceKeys(const ExtractInputs& inputs, const ExtractSettings& settings,
                      const std::vector<BaseFacePatch>& patches, const std::string& cache_folder) {
  const LimitSurface& surface = inputs.surface;
  const auto num_faces = static_cast<std::size_t>(surface.num_ptex_faces());
  const Hash128 settings_key = SettingsKey(settings);
  const FieldKeys fields = ComputeFieldKeys(inputs, patches, cache_folder);
  FaceKeys out;
  out.keys.resize(num_faces);
  out.reach_faces.resize(num_faces);
  out.fields_kept = fields.kept;
  tbb::parallel_for(std::size_t{0}, num_faces, [&](std::size_t f) {
    Hasher h;
    h.Add(settings_key);
    AddFacePatchKey(h, surface, patches, settings, f);
    h.Add(fields.keys[f]);
    const int m = inputs.grids->grid_size(static_cast<int>(f));
    out.reach_faces[f] = std::int64_t{m} * m;
    out.keys[f] = h.Digest();
  });
  return out;
}

}  // namespace

FaceKeys ComputeFaceKeys(const ExtractInputs& inputs, const ExtractSettings& settings,
                         const std::string& cache_folder) {
  const LimitSurface& surface = inputs.surface;
  const auto num_faces = static_cast<std::size_t>(surface.num_ptex_faces());
  const std::vector<BaseFacePatch> patches = BaseFacePatches(surface);
  if (settings.interpolate) return GridFaceKeys(inputs, settings, patches, cache_folder);
  FaceKeys out;
  out.reach_boxes = ReachBoxes(surface, patches, Reach(settings));
  if (settings.retry_query.distance > settings.query.distance) {
    out.first_search_boxes = ReachBoxes(surface, patches, settings.query.distance);
  }
  std::vector<std::uint8_t> skip(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f) skip[f] = surface.is_hole(PtexFaceId(int(f)));
  const std::vector<Hash128> sculpt = SculptReachKeys(inputs.sculpt, out.reach_boxes, skip,
                                                      out.sculpt_half_extent, out.reach_faces);
  Hasher global;
  global.Add(SettingsKey(settings)).Add(TracerScale(inputs.base));
  const Hash128 settings_key = global.Digest();

  out.keys.resize(num_faces);
  tbb::parallel_for(std::size_t{0}, num_faces, [&](std::size_t f) {
    Hasher h;
    h.Add(settings_key);
    AddFacePatchKey(h, surface, patches, settings, f);
    h.Add(sculpt[f]);
    out.keys[f] = h.Digest();
  });
  return out;
}

void AddFacePatchKey(Hasher& h, const LimitSurface& surface, std::span<const BaseFacePatch> patches,
                     const ExtractSettings& settings, std::size_t f) {
  const PtexFaceId face(static_cast<int>(f));
  const BaseFacePatch& patch = patches[static_cast<std::size_t>(surface.base_face(face).value)];
  h.Add(patch.key[0]).Add(patch.key[1]);
  h.Add(surface.sub_face(face)).Add(surface.is_hole(face)).Add(settings.plan.log2[f]);
}

namespace {

// Per Ptex face: whether the reach grid leaves it out, a hole or one `faces` does not flag
// (empty: every face flagged).
std::vector<std::uint8_t> SkippedFaces(const LimitSurface& surface,
                                       std::span<const std::uint8_t> faces) {
  std::vector<std::uint8_t> skip(static_cast<std::size_t>(surface.num_ptex_faces()));
  for (std::size_t f = 0; f < skip.size(); ++f) {
    skip[f] = (!faces.empty() && !faces[f]) || surface.is_hole(PtexFaceId(static_cast<int>(f)));
  }
  return skip;
}

}  // namespace

Mesh SculptWithinReach(const ExtractInputs& inputs, const FaceKeys& keys,
                       std::span<const std::uint8_t> faces, bool first_search) {
  const LimitSurface& surface = inputs.surface;
  const Mesh& sculpt = inputs.sculpt;
  const std::vector<Box>& boxes =
      first_search && !keys.first_search_boxes.empty() ? keys.first_search_boxes : keys.reach_boxes;
  const float half_extent = keys.sculpt_half_extent;
  const std::vector<std::uint8_t> skip = SkippedFaces(surface, faces);
  Mesh part;
  part.source = sculpt.source;
  part.face_offsets.push_back(0);
  if (std::count(skip.begin(), skip.end(), 0) == 0) return part;  // no face: no sculpt
  // Finer than the keys' grid: the part of the sculpt to build a BVH of is found once. Every
  // face whose centre's cell a box, grown by the largest half-extent, reaches.
  const CellGrid grid(boxes, skip, /*per_side=*/6);
  std::vector<std::uint8_t> marked(grid.num_cells(), 0);
  for (std::size_t f = 0; f < boxes.size(); ++f) {
    if (!skip[f]) grid.ForEachCell(boxes[f], half_extent, [&](std::size_t c) { marked[c] = 1; });
  }
  std::vector<std::uint8_t> keep(sculpt.num_faces());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sculpt.num_faces(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      Corners corners;
                      for (std::size_t s = range.begin(); s != range.end(); ++s) {
                        const std::array<float, 3> centre = Bounds(corners.Of(sculpt, s)).centre;
                        // Beyond the grid's reach a face is out of reach: not kept for the
                        // border cell CellOf would give it.
                        keep[s] = grid.Near(centre, half_extent) && marked[grid.CellOf(centre)];
                      }
                    });
  return SculptPart(sculpt, keep);
}

Mesh SculptPart(const Mesh& sculpt, std::span<const std::uint8_t> keep) {
  // In blocks, in parallel: what each block holds is counted, the blocks' offsets summed in
  // order, and each block written at its offset, so the part is the one a pass in order makes.
  constexpr std::size_t kBlock = std::size_t{1} << 16;
  const std::size_t num_faces = sculpt.num_faces(), num_vertices = sculpt.num_vertices();
  const auto blocks = [](std::size_t n) { return (n + kBlock - 1) / kBlock; };
  const auto offsets_of = [](std::vector<std::size_t>& counts) {  // exclusive, in place
    std::size_t total = 0;
    for (std::size_t& c : counts) total += std::exchange(c, total);
    return total;
  };
  std::vector<std::uint8_t> used(num_vertices, 0);
  tbb::parallel_for(std::size_t{0}, blocks(num_faces), [&](std::size_t b) {
    for (std::size_t s = b * kBlock; s < std::min(num_faces, (b + 1) * kBlock); ++s) {
      if (!keep[s]) continue;
      for (std::int32_t v : sculpt.face(s)) {
        std::atomic_ref<std::uint8_t>(used[static_cast<std::size_t>(v)])
            .store(1, std::memory_order_relaxed);
      }
    }
  });
  std::vector<std::size_t> vertex_at(blocks(num_vertices), 0);
  tbb::parallel_for(std::size_t{0}, vertex_at.size(), [&](std::size_t b) {
    for (std::size_t v = b * kBlock; v < std::min(num_vertices, (b + 1) * kBlock); ++v) {
      vertex_at[b] += used[v];
    }
  });
  Mesh part;
  part.source = sculpt.source;
  const std::size_t part_vertices = offsets_of(vertex_at);
  part.positions.reserve(part_vertices + 1);  // Embree reads 16 bytes at the last vertex
  part.positions.resize(part_vertices);
  std::vector<std::int32_t> vertex(num_vertices, -1);
  tbb::parallel_for(std::size_t{0}, vertex_at.size(), [&](std::size_t b) {
    std::size_t next = vertex_at[b];
    for (std::size_t v = b * kBlock; v < std::min(num_vertices, (b + 1) * kBlock); ++v) {
      if (!used[v]) continue;
      vertex[v] = static_cast<std::int32_t>(next);
      part.positions[next++] = sculpt.positions[v];
    }
  });
  std::vector<std::size_t> face_at(blocks(num_faces), 0), corner_at(blocks(num_faces), 0);
  tbb::parallel_for(std::size_t{0}, face_at.size(), [&](std::size_t b) {
    for (std::size_t s = b * kBlock; s < std::min(num_faces, (b + 1) * kBlock); ++s) {
      if (!keep[s]) continue;
      ++face_at[b];
      corner_at[b] += sculpt.face_size(s);
    }
  });
  const std::size_t part_faces = offsets_of(face_at), part_corners = offsets_of(corner_at);
  part.face_offsets.resize(part_faces + 1);
  part.face_offsets[part_faces] = static_cast<std::uint32_t>(part_corners);
  part.face_indices.resize(part_corners);
  tbb::parallel_for(std::size_t{0}, face_at.size(), [&](std::size_t b) {
    std::size_t face = face_at[b], corner = corner_at[b];
    for (std::size_t s = b * kBlock; s < std::min(num_faces, (b + 1) * kBlock); ++s) {
      if (!keep[s]) continue;
      part.face_offsets[face++] = static_cast<std::uint32_t>(corner);
      for (std::int32_t v : sculpt.face(s)) {
        part.face_indices[corner++] = vertex[static_cast<std::size_t>(v)];
      }
    }
  });
  return part;
}

ReachRuns RunsWithinReach(const ExtractInputs& inputs, const FaceKeys& keys,
                          std::span<const int> faces, int rings, std::size_t part_faces) {
  const LimitSurface& surface = inputs.surface;
  const Mesh& sculpt = inputs.sculpt;
  const std::vector<Box>& boxes = keys.reach_boxes;
  const float half_extent = keys.sculpt_half_extent;
  const std::vector<std::uint8_t> skip = SkippedFaces(surface, {});
  // SculptWithinReach's cells over every face, with the sculpt faces whose centre each holds.
  const CellGrid grid(boxes, skip, /*per_side=*/6);
  tbb::enumerable_thread_specific<std::vector<std::int64_t>> local(
      [&] { return std::vector<std::int64_t>(grid.num_cells(), 0); });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sculpt.num_faces(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<std::int64_t>& counts = local.local();
                      Corners corners;
                      for (std::size_t s = range.begin(); s != range.end(); ++s) {
                        const std::array<float, 3> centre = Bounds(corners.Of(sculpt, s)).centre;
                        if (grid.Near(centre, half_extent)) ++counts[grid.CellOf(centre)];
                      }
                    });
  std::vector<std::int64_t> counts(grid.num_cells(), 0);
  for (const std::vector<std::int64_t>& c : local) {
    for (std::size_t i = 0; i < c.size(); ++i) counts[i] += c[i];
  }

  std::vector<std::uint8_t> in_run(boxes.size(), 0), marked(grid.num_cells(), 0);
  std::vector<int> run_faces, added;  // the faces and rings in the run; those f adds
  std::vector<std::size_t> run_cells;
  std::int64_t held = 0;
  // Adds face f and its rings to the run; the sculpt faces that adds to the run's part.
  auto add = [&](int f) {
    added.clear();
    std::vector<int> ring{f};
    if (!in_run[static_cast<std::size_t>(f)]) added.push_back(f);
    in_run[static_cast<std::size_t>(f)] = 1;
    for (int step = 0; step < rings; ++step) {
      std::vector<int> next;
      for (int g : ring) {
        for (std::int32_t h : inputs.faces[static_cast<std::size_t>(g)].adjfaces) {
          if (h < 0 || in_run[static_cast<std::size_t>(h)]) continue;
          in_run[static_cast<std::size_t>(h)] = 1;
          added.push_back(h);
          next.push_back(h);
        }
      }
      ring = std::move(next);
    }
    std::int64_t more = 0;
    for (int g : added) {
      run_faces.push_back(g);
      if (skip[static_cast<std::size_t>(g)]) continue;
      grid.ForEachCell(boxes[static_cast<std::size_t>(g)], half_extent, [&](std::size_t c) {
        if (marked[c]) return;
        marked[c] = 1;
        run_cells.push_back(c);
        more += counts[c];
      });
    }
    return more;
  };
  auto clear = [&] {
    for (int g : run_faces) in_run[static_cast<std::size_t>(g)] = 0;
    for (std::size_t c : run_cells) marked[c] = 0;
    run_faces.clear();
    run_cells.clear();
    held = 0;
  };
  ReachRuns out;
  out.runs.emplace_back();
  for (int f : faces) {
    held += add(f);
    if (!out.runs.back().empty() && held > static_cast<std::int64_t>(part_faces)) {
      clear();
      out.runs.emplace_back();
      held = add(f);
    }
    out.runs.back().push_back(f);
    if (out.runs.back().size() == 1 && held > out.largest_single) {
      out.largest_single = held;
      out.largest_face = f;
    }
  }
  return out;
}

}  // namespace dispex::extract
