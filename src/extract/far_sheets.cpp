#include "extract/far_sheets.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace dispex::extract {

namespace {

// How far sample k's window reaches each way: up to its hit under the nearest policy (nothing
// nearer may exist), else the query's whole distance.
float Window(std::size_t k, const NormalQuery& query, const NormalHits& out) {
  const bool hit = out.flags[k] & HitFlags::kHit;
  return hit && query.policy == HitPolicy::kNearest ? std::fabs(out.t[k]) : query.distance;
}

// Each bound of the window o -+ w |n| is within a few roundings of the exact one; 2^-20 of the
// magnitudes covers them, and the smallest normal float covers underflow.
float RoundingMargin(const Float3& o, float w) {
  const float scale = std::max({std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)}) + w;
  return scale * 0x1p-20f + 0x1p-126f;
}

// The box of sample k's window, or false when it has none to check (a sample not decided, or
// one with no valid line: a miss by rule).
bool WindowBox(std::size_t k, std::span<const Float3> origins, std::span<const Float3> normals,
               const NormalQuery& query, const NormalHits& out,
               std::span<const std::uint8_t> undecided, Box& box) {
  if (undecided[k]) return false;
  const Float3& o = origins[k];
  const Float3& d = normals[k];
  const float c[3] = {o.x, o.y, o.z}, n[3] = {d.x, d.y, d.z};
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(c[a]) || !std::isfinite(n[a])) return false;
  }
  if (n[0] == 0 && n[1] == 0 && n[2] == 0) return false;
  const float w = Window(k, query, out);
  if (!std::isfinite(w)) return false;
  const float e = RoundingMargin(o, w);
  for (int a = 0; a < 3; ++a) {
    const float r = w * std::fabs(n[a]);
    box.lower[a] = c[a] - r - e;
    box.upper[a] = c[a] + r + e;
  }
  return true;
}

// Whether sample k's window, the segment o + t n for |t| <= w, meets `box` widened by its
// rounding margin (in double: a slab test, far tighter than the window's box where n is
// oblique to the axes).
bool SegmentMeets(const Float3& o, const Float3& d, double w, const Box& box) {
  const double c[3] = {o.x, o.y, o.z}, n[3] = {d.x, d.y, d.z};
  double t0 = -w, t1 = w;
  for (int a = 0; a < 3; ++a) {
    const double e = (std::max(std::fabs(double(box.lower[a])), std::fabs(double(box.upper[a]))) +
                      std::fabs(c[a]) + w) *
                         0x1p-20 +
                     0x1p-126;
    const double lo = double(box.lower[a]) - e, hi = double(box.upper[a]) + e;
    if (n[a] == 0) {
      if (c[a] < lo || c[a] > hi) return false;
      continue;
    }
    const double ta = (lo - c[a]) / n[a], tb = (hi - c[a]) / n[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
    if (t0 > t1) return false;
  }
  return true;
}

void Grow(Box& into, const Box& box) {
  for (int a = 0; a < 3; ++a) {
    into.lower[a] = std::min(into.lower[a], box.lower[a]);
    into.upper[a] = std::max(into.upper[a], box.upper[a]);
  }
}

}  // namespace

std::uint64_t CheckFarSheets(const SculptMapping& mapping, const Mesh& sculpt, int face, int n,
                             std::span<const std::int32_t> samples, std::span<const Float3> origins,
                             std::span<const Float3> normals, const NormalQuery& query,
                             const NormalHits& out, std::span<std::uint8_t> undecided,
                             MappingScratch& w) {
  const SculptBlocks& blocks = mapping.blocks();
  if (blocks.empty()) return 0;
  const int m = mapping.grid_size(face), b = blocks.block_size(face);
  const int per = blocks.blocks_per_side(face);
  if (per == 0) return 0;
  if (w.near_face != face) LayOutNearBlocks(mapping, face, w);
  const std::size_t count = samples.empty() ? static_cast<std::size_t>(n) * n : samples.size();
  auto index = [&](std::size_t s) {
    return samples.empty() ? s : static_cast<std::size_t>(samples[s]);
  };
  // The block of cells under each column (row) of samples, and the block of sample k (on a
  // texel grid, n a power of two, k's row and column are a shift and a mask).
  w.sample_block_of.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto cell = static_cast<int>((std::int64_t{2} * i + 1) * m / (std::int64_t{2} * n));
    w.sample_block_of[static_cast<std::size_t>(i)] = cell / b;
  }
  const auto un = static_cast<std::size_t>(n);
  const bool power_of_two = std::has_single_bit(un);
  const int shift = std::countr_zero(un);
  auto block_of = [&](std::size_t k) {
    const std::size_t i = power_of_two ? k & (un - 1) : k % un;
    const std::size_t j = power_of_two ? k >> shift : k / un;
    return static_cast<std::size_t>(w.sample_block_of[j]) * static_cast<std::size_t>(per) +
           static_cast<std::size_t>(w.sample_block_of[i]);
  };
  // Per block of samples, the box of their windows.
  const auto num_blocks = static_cast<std::size_t>(per) * static_cast<std::size_t>(per);
  w.sample_boxes.resize(num_blocks);
  w.sample_box_used.assign(num_blocks, 0);
  Box box;
  for (std::size_t s = 0; s < count; ++s) {
    const std::size_t k = index(s);
    if (!WindowBox(k, origins, normals, query, out, undecided, box)) continue;
    const std::size_t at = block_of(k);
    if (w.sample_box_used[at]) {
      Grow(w.sample_boxes[at], box);
    } else {
      w.sample_boxes[at] = box;
      w.sample_box_used[at] = 1;
    }
  }
  // Its candidates: the sculpt blocks the box meets that are not near.
  const int width = per + 2;
  w.candidate_starts.assign(1, 0);
  w.candidate_ids.clear();
  // The near blocks of a block of samples are stamped in near_stamp (one entry per sculpt
  // block, kept by the thread), so each block met is looked up once.
  if (w.near_stamp.size() != static_cast<std::size_t>(blocks.num_blocks())) {
    w.near_stamp.assign(static_cast<std::size_t>(blocks.num_blocks()), 0);
    w.stamp = 0;
  }
  for (int bj = 0; bj < per; ++bj) {
    for (int bi = 0; bi < per; ++bi) {
      const std::size_t at = static_cast<std::size_t>(bj) * per + bi;
      if (w.sample_box_used[at]) {
        if (++w.stamp == 0) {
          std::fill(w.near_stamp.begin(), w.near_stamp.end(), 0);
          w.stamp = 1;
        }
        for (int dj = 0; dj <= 2; ++dj) {
          for (int di = 0; di <= 2; ++di) {
            const auto slot = static_cast<std::size_t>((bj + dj) * width + bi + di);
            for (std::int32_t k = w.near_starts[slot]; k < w.near_starts[slot + 1]; ++k) {
              w.near_stamp[static_cast<std::size_t>(w.near_ids[static_cast<std::size_t>(k)])] =
                  w.stamp;
            }
          }
        }
        blocks.ForEachMeeting(w.sample_boxes[at], [&](std::int64_t id) {
          if (w.near_stamp[static_cast<std::size_t>(id)] != w.stamp) w.candidate_ids.push_back(id);
        });
      }
      w.candidate_starts.push_back(static_cast<std::int32_t>(w.candidate_ids.size()));
    }
  }
  if (w.candidate_ids.empty()) return 0;
  // The samples of blocks with candidates, one by one.
  std::uint64_t sent = 0;
  for (std::size_t s = 0; s < count; ++s) {
    const std::size_t k = index(s);
    const std::size_t at = block_of(k);
    if (w.candidate_starts[at] == w.candidate_starts[at + 1]) continue;
    if (!WindowBox(k, origins, normals, query, out, undecided, box)) continue;
    const float window = Window(k, query, out);
    // A crossing within rounding beyond the window's end counts: the ray path may find it inside.
    const Float3& o = origins[k];
    const float reach = window + RoundingMargin(o, window);
    for (std::int32_t c = w.candidate_starts[at]; c < w.candidate_starts[at + 1]; ++c) {
      const std::int64_t id = w.candidate_ids[static_cast<std::size_t>(c)];
      const Box& candidate = blocks.box(id);
      if (candidate.Meets(box) && SegmentMeets(o, normals[k], window, candidate) &&
          WindowCrossesBlock(mapping, sculpt, id, o, normals[k], reach)) {
        undecided[k] = 1;
        ++sent;
        break;
      }
    }
  }
  return sent;
}

}  // namespace dispex::extract
