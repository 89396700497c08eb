#include "extract/face_keys.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "dispex/version.h"

namespace dispex::extract {

namespace {

struct Box {
  std::array<float, 3> lower{}, upper{};
  bool Meets(const Box& other) const {
    for (int k = 0; k < 3; ++k) {
      if (lower[k] > other.upper[k] || other.lower[k] > upper[k]) return false;
    }
    return true;
  }
};

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

// The reach boxes binned in a uniform grid of about one box per cell.
class BoxGrid {
 public:
  BoxGrid(const std::vector<Box>& boxes, const std::vector<std::uint8_t>& skip) : boxes_(boxes) {
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
    // At most about eight cells per box.
    double volume = 1;
    for (int k = 0; k < 3; ++k) {
      volume *= std::max(double(bounds_.upper[k]) - double(bounds_.lower[k]), 1e-30);
    }
    const double cell_side = std::max<double>(
        {sides[sides.size() / 2], std::cbrt(volume / (8.0 * double(sides.size()))), 1e-30});
    for (int k = 0; k < 3; ++k) {
      const double span = double(bounds_.upper[k]) - double(bounds_.lower[k]);
      dims_[k] = static_cast<int>(std::clamp(std::ceil(span / cell_side), 1.0, 256.0));
      scale_[k] = span > 0 ? dims_[k] / span : 0;
    }
    cells_.assign(static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2] + 1, 0);
    // Two passes (count, fill) into flat arrays.
    std::vector<std::int32_t> counts(cells_.size(), 0);
    ForCells(skip, [&](std::size_t cell, std::int32_t) { ++counts[cell]; });
    for (std::size_t c = 0; c + 1 < cells_.size(); ++c) cells_[c + 1] = cells_[c] + counts[c];
    members_.resize(static_cast<std::size_t>(cells_.back()));
    std::fill(counts.begin(), counts.end(), 0);
    ForCells(skip, [&](std::size_t cell, std::int32_t f) {
      members_[static_cast<std::size_t>(cells_[cell] + counts[cell]++)] = f;
    });
  }

  // Calls visit(face) once for every reach box that meets `box`.
  template <class Visit>
  void ForEachMeeting(const Box& box, Visit visit) const {
    if (members_.empty() || !box.Meets(bounds_)) return;
    const auto [lo, hi] = CellRange(box);
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const std::size_t cell = Index(x, y, z);
          for (std::int32_t k = cells_[cell]; k < cells_[cell + 1]; ++k) {
            const std::int32_t f = members_[static_cast<std::size_t>(k)];
            const Box& other = boxes_[static_cast<std::size_t>(f)];
            if (!box.Meets(other)) continue;
            // A pair met in several cells counts in the cell of its overlap's lower corner.
            std::array<float, 3> corner;
            for (int a = 0; a < 3; ++a) corner[a] = std::max(box.lower[a], other.lower[a]);
            if (Index(Cell(corner[0], 0), Cell(corner[1], 1), Cell(corner[2], 2)) != cell) {
              continue;
            }
            visit(f);
          }
        }
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
  std::pair<std::array<int, 3>, std::array<int, 3>> CellRange(const Box& b) const {
    std::array<int, 3> lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = Cell(b.lower[k], k);
      hi[k] = Cell(b.upper[k], k);
    }
    return {lo, hi};
  }
  template <class Add>
  void ForCells(const std::vector<std::uint8_t>& skip, Add add) const {
    for (std::size_t f = 0; f < boxes_.size(); ++f) {
      if (skip[f]) continue;
      const auto [lo, hi] = CellRange(boxes_[f]);
      for (int z = lo[2]; z <= hi[2]; ++z) {
        for (int y = lo[1]; y <= hi[1]; ++y) {
          for (int x = lo[0]; x <= hi[0]; ++x) add(Index(x, y, z), static_cast<std::int32_t>(f));
        }
      }
    }
  }

  const std::vector<Box>& boxes_;
  Box bounds_;
  std::array<int, 3> dims_{1, 1, 1};
  std::array<double, 3> scale_{0, 0, 0};
  std::vector<std::int32_t> cells_;    // CSR offsets, one past the last cell at the end
  std::vector<std::int32_t> members_;  // face ids, cell after cell
};

// The order-free sum of the keys of the sculpt faces each reach box meets.
std::vector<Hash128> SculptReachKeys(const Mesh& sculpt, const std::vector<Box>& boxes,
                                     const std::vector<std::uint8_t>& skip) {
  const BoxGrid grid(boxes, skip);
  tbb::combinable<std::vector<Hash128>> sums([&] { return std::vector<Hash128>(boxes.size()); });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sculpt.num_faces(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<Hash128>& keys = sums.local();
                      std::vector<float> corners;
                      for (std::size_t s = range.begin(); s != range.end(); ++s) {
                        const std::span<const std::int32_t> face = sculpt.face(s);
                        Box box;
                        box.lower = {INFINITY, INFINITY, INFINITY};
                        box.upper = {-INFINITY, -INFINITY, -INFINITY};
                        corners.clear();
                        for (std::int32_t v : face) {
                          const Float3& p = sculpt.positions[static_cast<std::size_t>(v)];
                          const std::array<float, 3> xyz{p.x, p.y, p.z};
                          for (int k = 0; k < 3; ++k) {
                            box.lower[k] = std::min(box.lower[k], xyz[k]);
                            box.upper[k] = std::max(box.upper[k], xyz[k]);
                            corners.push_back(xyz[k]);
                          }
                        }
                        const Hash128 key = HashBytes(std::as_bytes(std::span(corners)));
                        grid.ForEachMeeting(
                            box, [&](std::int32_t f) { keys[static_cast<std::size_t>(f)] += key; });
                      }
                    });
  std::vector<Hash128> total(boxes.size());
  sums.combine_each([&](const std::vector<Hash128>& part) {
    for (std::size_t f = 0; f < total.size(); ++f) total[f] += part[f];
  });
  return total;
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
  h.Add(std::string_view("dispex face key 1 " DISPEX_VERSION_STRING));
  h.Add(s.query.distance).Add(static_cast<int>(s.query.policy));
  h.Add(s.retry_query.distance).Add(static_cast<int>(s.retry_query.policy));
  h.Add(static_cast<int>(s.spectral.rule)).Add(s.spectral.tolerance);
  h.Add(s.spectral.nonzero_threshold).Add(s.spectral.fixed_ulog2).Add(s.spectral.fixed_vlog2);
  h.Add(s.spectral.pin_edges).Add(s.spectral.edge_tolerance);
  h.Add(static_cast<int>(s.holes)).Add(static_cast<int>(s.data_type));
  h.Add(static_cast<int>(s.watertight)).Add(s.edge_step_budget).Add(s.max_samples_log2);
  return h.Digest();
}

std::vector<Hash128> ComputeFaceKeys(const ExtractInputs& inputs, const ExtractSettings& settings) {
  const LimitSurface& surface = inputs.surface;
  const auto num_faces = static_cast<std::size_t>(surface.num_ptex_faces());
  const std::vector<BaseFacePatch> patches = BaseFacePatches(surface);
  const double reach = std::max<double>(settings.query.distance, settings.retry_query.distance);
  const std::vector<Box> boxes = ReachBoxes(surface, patches, reach);
  std::vector<std::uint8_t> skip(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f) skip[f] = surface.is_hole(PtexFaceId(int(f)));
  const std::vector<Hash128> sculpt = SculptReachKeys(inputs.sculpt, boxes, skip);
  Hasher global;
  global.Add(SettingsKey(settings)).Add(inputs.tracer->stats().scale);
  const Hash128 settings_key = global.Digest();

  std::vector<Hash128> keys(num_faces);
  tbb::parallel_for(std::size_t{0}, num_faces, [&](std::size_t f) {
    const PtexFaceId face(static_cast<int>(f));
    const BaseFacePatch& patch = patches[static_cast<std::size_t>(surface.base_face(face).value)];
    Hasher h;
    h.Add(settings_key);
    h.Add(patch.key[0]).Add(patch.key[1]);
    h.Add(surface.sub_face(face)).Add(skip[f]).Add(settings.plan.log2[f]);
    h.Add(sculpt[f]);
    keys[f] = h.Digest();
  });
  return keys;
}

}  // namespace dispex::extract
