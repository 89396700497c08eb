#include "extract/mapping/sculpt_blocks.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "extract/mapping/mapping_trace.h"

namespace dispex::extract {

SculptBlocks SculptBlocks::Build(const SculptMapping& mapping, const Mesh& sculpt) {
  SculptBlocks out;
  const auto num_ptex = static_cast<std::size_t>(mapping.num_ptex_faces());
  out.sizes_.resize(num_ptex, 0);
  out.per_side_.resize(num_ptex, 0);
  out.offsets_.resize(num_ptex + 1, 0);
  for (std::size_t f = 0; f < num_ptex; ++f) {
    const int m = mapping.grid_size(static_cast<int>(f));
    const int b = std::min(kBlock, m);
    out.sizes_[f] = b;
    out.per_side_[f] = b > 0 ? m / b : 0;
    out.offsets_[f + 1] = out.offsets_[f] + std::int64_t{out.per_side_[f]} * out.per_side_[f];
  }
  out.boxes_.resize(static_cast<std::size_t>(out.offsets_.back()));
  if (out.boxes_.empty()) return out;
  const Float3* p = sculpt.positions.data();
  tbb::parallel_for(std::size_t{0}, num_ptex, [&](std::size_t f) {
    const int b = out.sizes_[f], per = out.per_side_[f];
    for (int bj = 0; bj < per; ++bj) {
      for (int bi = 0; bi < per; ++bi) {
        Box box = Box::Empty();
        for (int j = bj * b; j < (bj + 1) * b; ++j) {
          for (int i = bi * b; i < (bi + 1) * b; ++i) {
            const std::int32_t* ids =
                sculpt.face_indices.data() + 4 * static_cast<std::size_t>(SculptMapping::FaceOf(
                                                     mapping.cell(static_cast<int>(f), i, j)));
            for (int k = 0; k < 4; ++k) {
              const Float3& v = p[ids[k]];
              const float c[3] = {v.x, v.y, v.z};
              for (int a = 0; a < 3; ++a) {
                box.lower[a] = std::min(box.lower[a], c[a]);
                box.upper[a] = std::max(box.upper[a], c[a]);
              }
            }
          }
        }
        out.boxes_[static_cast<std::size_t>(out.id(static_cast<int>(f), bi, bj))] = box;
      }
    }
  });
  // The grid: cells about the mean block's largest side, at most about 2 cells per block.
  double lower[3] = {INFINITY, INFINITY, INFINITY}, upper[3] = {-INFINITY, -INFINITY, -INFINITY};
  double side = 0;
  for (const Box& box : out.boxes_) {
    double largest = 0;
    for (int a = 0; a < 3; ++a) {
      lower[a] = std::min(lower[a], double(box.lower[a]));
      upper[a] = std::max(upper[a], double(box.upper[a]));
      largest = std::max(largest, double(box.upper[a]) - double(box.lower[a]));
    }
    side += largest;
  }
  side /= static_cast<double>(out.boxes_.size());
  double extent = 0;
  for (int a = 0; a < 3; ++a) extent = std::max(extent, upper[a] - lower[a]);
  side = std::max(side, extent * 0x1p-10);
  if (!(side > 0)) side = 1;
  const double cap = 2.0 * static_cast<double>(out.boxes_.size()) + 64;
  for (;;) {
    double cells = 1;
    for (int a = 0; a < 3; ++a) cells *= std::floor((upper[a] - lower[a]) / side) + 1;
    if (cells <= cap) break;
    side *= 1.25;
  }
  out.cell_ = static_cast<float>(side);
  out.inverse_cell_ = 1 / out.cell_;
  for (int a = 0; a < 3; ++a) {
    out.origin_[a] = static_cast<float>(lower[a]);
    out.dims_[a] = static_cast<int>(std::floor((upper[a] - lower[a]) / side)) + 1;
  }
  const std::size_t num_cells = static_cast<std::size_t>(out.dims_[0]) * out.dims_[1] *
                                static_cast<std::size_t>(out.dims_[2]);
  out.starts_.assign(num_cells + 1, 0);
  auto for_each_cell = [&](const Box& box, auto&& fn) {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = out.Cell(a, box.lower[a]);
      hi[a] = out.Cell(a, box.upper[a]);
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          fn((static_cast<std::size_t>(z) * out.dims_[1] + y) * out.dims_[0] + x);
        }
      }
    }
  };
  for (const Box& box : out.boxes_)
    for_each_cell(box, [&](std::size_t c) { ++out.starts_[c + 1]; });
  for (std::size_t c = 0; c < num_cells; ++c) out.starts_[c + 1] += out.starts_[c];
  out.entries_.resize(static_cast<std::size_t>(out.starts_.back()));
  std::vector<std::int64_t> fill(out.starts_.begin(), out.starts_.end() - 1);
  for (std::size_t b = 0; b < out.boxes_.size(); ++b) {
    for_each_cell(out.boxes_[b], [&](std::size_t c) {
      out.entries_[static_cast<std::size_t>(fill[c]++)] = {out.boxes_[b],
                                                           static_cast<std::int32_t>(b)};
    });
  }
  return out;
}

SculptBlocks::Place SculptBlocks::block(std::int64_t id) const {
  // offsets_ is ascending, one entry per Ptex face plus the end: the face is the last whose
  // first block is at or before `id` (faces without blocks share their successor's offset).
  const auto it = std::upper_bound(offsets_.begin(), offsets_.end(), id) - 1;
  const int face = static_cast<int>(it - offsets_.begin());
  const std::int64_t k = id - *it;
  const int per = per_side_[static_cast<std::size_t>(face)];
  return Place{face, static_cast<int>(k % per), static_cast<int>(k / per)};
}

std::size_t SculptBlocks::bytes() const {
  return (sizes_.capacity() + per_side_.capacity()) * sizeof(std::int32_t) +
         (offsets_.capacity() + starts_.capacity()) * sizeof(std::int64_t) +
         entries_.capacity() * sizeof(Entry) + boxes_.capacity() * sizeof(Box);
}

}  // namespace dispex::extract
