// Boxes of blocks of sculpt cells, for finding the sculpt a sample's ray window could meet
// outside the cells the mapping tested (far_sheets.h): per Ptex face of a SculptMapping, its
// m x m grid of cells cut into blocks of b x b cells (b = min(4, m)), each block's axis-aligned
// box of its quads' corners (the sculpt's floats, exactly), and a uniform grid over the boxes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "dispex/mesh.h"
#include "extract/box.h"

namespace dispex::extract {

class SculptMapping;

class SculptBlocks {
 public:
  static constexpr int kBlock = 4;  // cells per block side (fewer on grids under 4 x 4)

  // The blocks of every Ptex face of `mapping` over `sculpt` (its matched mesh). The same for
  // any thread count.
  static SculptBlocks Build(const SculptMapping& mapping, const Mesh& sculpt);

  bool empty() const { return boxes_.empty(); }
  // Cells per block side and blocks per grid side of Ptex face `face` (0 for a hole).
  int block_size(int face) const { return sizes_[static_cast<std::size_t>(face)]; }
  int blocks_per_side(int face) const { return per_side_[static_cast<std::size_t>(face)]; }
  // The id of block (bi, bj) of `face`.
  std::int64_t id(int face, int bi, int bj) const {
    return offsets_[static_cast<std::size_t>(face)] + std::int64_t{bj} * blocks_per_side(face) + bi;
  }
  const Box& box(std::int64_t id) const { return boxes_[static_cast<std::size_t>(id)]; }
  std::int64_t num_blocks() const { return static_cast<std::int64_t>(boxes_.size()); }
  // The Ptex face and block coordinates (bi, bj) of block `id`.
  struct Place {
    int face = 0, bi = 0, bj = 0;
  };
  Place block(std::int64_t id) const;
  std::size_t bytes() const;
  // The side of the grid's cells.
  float cell_size() const { return cell_; }

  // Calls fn(id) once for each block whose box meets `query`, in an order fixed by the boxes.
  template <typename Fn>
  void ForEachMeeting(const Box& query, Fn&& fn) const {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = Cell(a, query.lower[a]);
      hi[a] = Cell(a, query.upper[a]);
      if (query.upper[a] < origin_[a] || lo[a] > hi[a]) return;
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const std::size_t c = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
          const Entry* end = entries_.data() + starts_[c + 1];
          for (const Entry* e = entries_.data() + starts_[c]; e != end; ++e) {
            if (!e->box.Meets(query)) continue;
            // Once: in the grid cell of the lower corner of the boxes' overlap.
            bool first = true;
            const int at[3] = {x, y, z};
            for (int a = 0; a < 3 && first; ++a) {
              first = Cell(a, std::max(e->box.lower[a], query.lower[a])) == at[a];
            }
            if (first) fn(std::int64_t{e->id});
          }
        }
      }
    }
  }

 private:
  // The grid cell along `axis` of coordinate v, clamped to the grid.
  int Cell(int axis, float v) const {
    const float x = std::floor((v - origin_[axis]) * inverse_cell_);
    if (!(x >= 0)) return 0;  // below the grid, or NaN
    return x >= float(dims_[axis] - 1) ? dims_[axis] - 1 : static_cast<int>(x);
  }

  // A block in a grid cell, its box beside its id so that a query reads the cell in order.
  struct Entry {
    Box box;
    std::int32_t id = 0;
  };

  std::vector<std::int32_t> sizes_, per_side_;  // per Ptex face
  std::vector<std::int64_t> offsets_;           // per Ptex face: its first block's id
  std::vector<Box> boxes_;                      // per block
  // The grid: cells of side cell_ from origin_, dims_ per axis; each cell's blocks (those
  // whose box overlaps it) at entries_[starts_[c] .. starts_[c + 1]).
  float origin_[3] = {0, 0, 0};
  float cell_ = 1, inverse_cell_ = 1;
  int dims_[3] = {1, 1, 1};
  std::vector<std::int64_t> starts_;
  std::vector<Entry> entries_;
};

}  // namespace dispex::extract
