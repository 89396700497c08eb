#include "extract/mapping/far_sheets.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>

namespace dispex::extract {

namespace {

// How far sample k's window reaches each way: up to its hit under the nearest policy
// (`nearest`: nothing nearer may exist), else the query's whole distance.
float Window(std::size_t k, const NormalQuery& query, bool nearest, const NormalHits& out) {
  return nearest && (out.flags[k] & HitFlags::kHit) ? std::fabs(out.t[k]) : query.distance;
}

// Each bound of the window o -+ w |n| is within a few roundings of the exact one; 2^-20 of the
// magnitudes covers them, and the smallest normal float covers underflow.
float RoundingMargin(const Float3& o, float w) {
  const float scale = std::max({std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)}) + w;
  return scale * 0x1p-20f + 0x1p-126f;
}

// The box of sample k's window into `box`, or false when it has none to check (a sample not
// decided, or one with no valid line: a miss by rule). `nearest`: the query's policy is
// HitPolicy::kNearest.
bool WindowBox(std::size_t k, std::span<const Float3> origins, std::span<const Float3> normals,
               const NormalQuery& query, bool nearest, const NormalHits& out,
               std::span<const std::uint8_t> undecided, Box& box) {
  const Float3& o = origins[k];
  const Float3& d = normals[k];
  const float w = Window(k, query, nearest, out);
  // Evaluated whole, without branches: most samples pass.
  const bool valid = !undecided[k] & std::isfinite(o.x) & std::isfinite(o.y) & std::isfinite(o.z) &
                     std::isfinite(d.x) & std::isfinite(d.y) & std::isfinite(d.z) &
                     ((d.x != 0) | (d.y != 0) | (d.z != 0)) & std::isfinite(w);
  if (!valid) return false;
  const float e = RoundingMargin(o, w);
  const float c[3] = {o.x, o.y, o.z}, n[3] = {d.x, d.y, d.z};
  for (int a = 0; a < 3; ++a) {
    const float r = w * std::fabs(n[a]);
    box.lower[a] = c[a] - r - e;
    box.upper[a] = c[a] + r + e;
  }
  return true;
}

void Grow(Box& into, const Box& box) {
  for (int a = 0; a < 3; ++a) {
    into.lower[a] = std::min(into.lower[a], box.lower[a]);
    into.upper[a] = std::max(into.upper[a], box.upper[a]);
  }
}

// Lane l of group g of boxes laid out as MappingScratch::window_boxes.
void StoreLane(float* boxes, std::size_t g, int l, const Box& box) {
  float* group = boxes + 24 * g;
  for (int a = 0; a < 3; ++a) {
    group[4 * a + l] = box.lower[static_cast<std::size_t>(a)];
    group[12 + 4 * a + l] = box.upper[static_cast<std::size_t>(a)];
  }
}

// The box of the windows of samples `ks` that have one (WindowBox), empty (lower > upper) when
// none has, and each sample's own box into `boxes` (MappingScratch::window_boxes; empty boxes
// for those with none and for the lanes after the last sample): the same bounds as WindowBox's,
// four samples at a time (SSE2, in every x86-64).
Box WindowsBox(std::span<const std::int32_t> ks, std::span<const Float3> origins,
               std::span<const Float3> normals, const NormalQuery& query, bool nearest,
               const NormalHits& out, std::span<const std::uint8_t> undecided,
               std::vector<float>& boxes) {
  Box all = Box::Empty();
  const std::size_t groups = (ks.size() + 3) / 4;
  boxes.resize(24 * groups);
  std::size_t s = 0;
#if defined(__SSE2__)
  const __m128 empty_lower = _mm_set1_ps(INFINITY), empty_upper = _mm_set1_ps(-INFINITY);
  __m128 lower[3] = {empty_lower, empty_lower, empty_lower};
  __m128 upper[3] = {empty_upper, empty_upper, empty_upper};
  const __m128 sign = _mm_set1_ps(-0.0f), largest = _mm_set1_ps(FLT_MAX), zero = _mm_setzero_ps();
  const __m128 scale = _mm_set1_ps(0x1p-20f), tiny = _mm_set1_ps(0x1p-126f);
  auto finite = [&](__m128 v) { return _mm_cmple_ps(_mm_andnot_ps(sign, v), largest); };
  auto select = [](__m128 mask, __m128 yes, __m128 no) {
    return _mm_or_ps(_mm_and_ps(mask, yes), _mm_andnot_ps(mask, no));
  };
  for (; s + 4 <= ks.size(); s += 4) {
    const std::size_t k[4] = {static_cast<std::size_t>(ks[s]), static_cast<std::size_t>(ks[s + 1]),
                              static_cast<std::size_t>(ks[s + 2]),
                              static_cast<std::size_t>(ks[s + 3])};
    const Float3 *o[4], *d[4];
    for (int l = 0; l < 4; ++l) {
      o[l] = &origins[k[l]];
      d[l] = &normals[k[l]];
    }
    // Built in registers: four scalar stores read back as one vector stall the load.
    const __m128 cv[3] = {_mm_setr_ps(o[0]->x, o[1]->x, o[2]->x, o[3]->x),
                          _mm_setr_ps(o[0]->y, o[1]->y, o[2]->y, o[3]->y),
                          _mm_setr_ps(o[0]->z, o[1]->z, o[2]->z, o[3]->z)};
    const __m128 nv[3] = {_mm_setr_ps(d[0]->x, d[1]->x, d[2]->x, d[3]->x),
                          _mm_setr_ps(d[0]->y, d[1]->y, d[2]->y, d[3]->y),
                          _mm_setr_ps(d[0]->z, d[1]->z, d[2]->z, d[3]->z)};
    const __m128 w =
        _mm_setr_ps(Window(k[0], query, nearest, out), Window(k[1], query, nearest, out),
                    Window(k[2], query, nearest, out), Window(k[3], query, nearest, out));
    __m128 valid =
        _mm_castsi128_ps(_mm_setr_epi32(undecided[k[0]] ? 0 : -1, undecided[k[1]] ? 0 : -1,
                                        undecided[k[2]] ? 0 : -1, undecided[k[3]] ? 0 : -1));
    __m128 nonzero = _mm_setzero_ps(), magnitude = _mm_setzero_ps();
    for (int a = 0; a < 3; ++a) {
      valid = _mm_and_ps(valid, _mm_and_ps(finite(cv[a]), finite(nv[a])));
      nonzero = _mm_or_ps(nonzero, _mm_cmpneq_ps(nv[a], zero));
      magnitude = _mm_max_ps(magnitude, _mm_andnot_ps(sign, cv[a]));
    }
    valid = _mm_and_ps(valid, _mm_and_ps(nonzero, finite(w)));
    // RoundingMargin: (the largest |coordinate| + w) 2^-20 + 2^-126.
    const __m128 e = _mm_add_ps(_mm_mul_ps(_mm_add_ps(magnitude, w), scale), tiny);
    float* group = boxes.data() + 6 * s;
    for (int a = 0; a < 3; ++a) {
      const __m128 r = _mm_mul_ps(w, _mm_andnot_ps(sign, nv[a]));
      const __m128 lo = select(valid, _mm_sub_ps(_mm_sub_ps(cv[a], r), e), empty_lower);
      const __m128 hi = select(valid, _mm_add_ps(_mm_add_ps(cv[a], r), e), empty_upper);
      _mm_storeu_ps(group + 4 * a, lo);
      _mm_storeu_ps(group + 12 + 4 * a, hi);
      lower[a] = _mm_min_ps(lo, lower[a]);
      upper[a] = _mm_max_ps(hi, upper[a]);
    }
  }
  for (int a = 0; a < 3; ++a) {
    alignas(16) float lo[4], hi[4];
    _mm_store_ps(lo, lower[a]);
    _mm_store_ps(hi, upper[a]);
    all.lower[a] = std::min({lo[0], lo[1], lo[2], lo[3]});
    all.upper[a] = std::max({hi[0], hi[1], hi[2], hi[3]});
  }
#endif
  for (std::size_t l = s; l < 4 * groups; ++l) {
    StoreLane(boxes.data(), l / 4, int(l % 4), Box::Empty());
  }
  Box box;
  for (; s < ks.size(); ++s) {
    const auto k = static_cast<std::size_t>(ks[s]);
    if (!WindowBox(k, origins, normals, query, nearest, out, undecided, box)) continue;
    Grow(all, box);
    StoreLane(boxes.data(), s / 4, int(s % 4), box);
  }
  return all;
}

// The lanes of group g of `boxes` (MappingScratch::window_boxes) whose box meets `box`, one bit
// per lane.
unsigned LanesMeeting(const float* boxes, std::size_t g, const Box& box) {
  const float* group = boxes + 24 * g;
#if defined(__SSE2__)
  __m128 meets = _mm_castsi128_ps(_mm_set1_epi32(-1));
  for (int a = 0; a < 3; ++a) {
    const __m128 lo = _mm_loadu_ps(group + 4 * a), hi = _mm_loadu_ps(group + 12 + 4 * a);
    meets = _mm_and_ps(meets, _mm_and_ps(_mm_cmple_ps(lo, _mm_set1_ps(box.upper[a])),
                                         _mm_cmple_ps(_mm_set1_ps(box.lower[a]), hi)));
  }
  return static_cast<unsigned>(_mm_movemask_ps(meets));
#else
  unsigned lanes = 0;
  for (int l = 0; l < 4; ++l) {
    bool meets = true;
    for (int a = 0; a < 3; ++a) {
      meets = meets && group[4 * a + l] <= box.upper[a] && box.lower[a] <= group[12 + 4 * a + l];
    }
    lanes |= meets ? 1u << l : 0u;
  }
  return lanes;
#endif
}

// Sample k's window, the segment o + t n for |t| <= w, prepared once for its tests: its
// origin, the reciprocals of its direction (a slab bound is a product, within an ulp of the
// quotient: far inside the margins below) and each axis's margin but the box's own share.
struct Segment {
  double c[3], inv[3], margin[3], w;
  bool parallel[3];

  Segment(const Float3& o, const Float3& d, double window) : w(window) {
    const double n[3] = {d.x, d.y, d.z};
    c[0] = o.x;
    c[1] = o.y;
    c[2] = o.z;
    for (int a = 0; a < 3; ++a) {
      parallel[a] = n[a] == 0;
      inv[a] = parallel[a] ? 0 : 1 / n[a];
      margin[a] = (std::fabs(c[a]) + w) * 0x1p-20 + 0x1p-126;
    }
  }

  // Whether it meets `box` widened by its rounding margin (a slab test in double, far tighter
  // than the window's box where n is oblique to the axes).
  bool Meets(const Box& box) const {
    double t0 = -w, t1 = w;
    for (int a = 0; a < 3; ++a) {
      const double lower = box.lower[a], upper = box.upper[a];
      const double e = std::max(std::fabs(lower), std::fabs(upper)) * 0x1p-20 + margin[a];
      const double lo = lower - e, hi = upper + e;
      if (parallel[a]) {
        if (c[a] < lo || c[a] > hi) return false;
        continue;
      }
      const double ta = (lo - c[a]) * inv[a], tb = (hi - c[a]) * inv[a];
      t0 = std::max(t0, std::min(ta, tb));
      t1 = std::min(t1, std::max(ta, tb));
      if (t0 > t1) return false;
    }
    return true;
  }
};

// The block of cells under each column (row) of samples, into w.sample_block_of.
void BlockOfEachSampleRow(int m, int b, int n, MappingScratch& w) {
  w.sample_block_of.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto cell = static_cast<int>((std::int64_t{2} * i + 1) * m / (std::int64_t{2} * n));
    w.sample_block_of[static_cast<std::size_t>(i)] = cell / b;
  }
}

// All n x n samples grouped by block of cells: block at's at
// w.block_samples[w.block_first[at] .. w.block_first[at + 1]). Rows and columns of a block are
// runs (the cells rise with i): its samples in row order.
void GroupGridByBlock(std::size_t un, std::size_t uper, MappingScratch& w) {
  w.block_samples.resize(un * un);
  std::size_t next = 0;
  std::size_t j0 = 0;
  for (std::size_t bj = 0; bj < uper; ++bj) {
    std::size_t j1 = j0;
    while (j1 < un && static_cast<std::size_t>(w.sample_block_of[j1]) == bj) ++j1;
    std::size_t i0 = 0;
    for (std::size_t bi = 0; bi < uper; ++bi) {
      std::size_t i1 = i0;
      while (i1 < un && static_cast<std::size_t>(w.sample_block_of[i1]) == bi) ++i1;
      for (std::size_t j = j0; j < j1; ++j) {
        for (std::size_t i = i0; i < i1; ++i) {
          w.block_samples[next++] = static_cast<std::int32_t>(j * un + i);
        }
      }
      w.block_first[bj * uper + bi + 1] = static_cast<std::int32_t>(next);
      i0 = i1;
    }
    j0 = j1;
  }
}

// The listed samples grouped by block of cells (a counting sort: in the given order within a
// block), laid out as GroupGridByBlock's.
void GroupListedByBlock(std::span<const std::int32_t> samples, std::size_t un, std::size_t uper,
                        MappingScratch& w) {
  const std::size_t num_blocks = uper * uper;
  auto block_of = [&](std::int32_t k) {
    const auto uk = static_cast<std::size_t>(k);
    return static_cast<std::size_t>(w.sample_block_of[uk / un]) * uper +
           static_cast<std::size_t>(w.sample_block_of[uk % un]);
  };
  for (std::int32_t k : samples) ++w.block_first[block_of(k) + 1];
  for (std::size_t at = 0; at < num_blocks; ++at) w.block_first[at + 1] += w.block_first[at];
  w.block_samples.resize(samples.size());
  w.block_fill.assign(w.block_first.begin(), w.block_first.end() - 1);
  for (std::int32_t k : samples) {
    w.block_samples[static_cast<std::size_t>(w.block_fill[block_of(k)]++)] = k;
  }
}

// The sculpt blocks that box `all` of block (bi, bj)'s windows meets and that are not near the
// block, into w.candidate_ids: the near ones are stamped in w.near_stamp (one entry per sculpt
// block, kept by the thread), so each block met is looked up once.
void CollectFarBlocks(const SculptBlocks& blocks, int bi, int bj, int per, const Box& all,
                      MappingScratch& w) {
  if (++w.stamp == 0) {
    std::fill(w.near_stamp.begin(), w.near_stamp.end(), 0);
    w.stamp = 1;
  }
  const int width = per + 2;
  for (int dj = 0; dj <= 2; ++dj) {
    for (int di = 0; di <= 2; ++di) {
      const auto slot = static_cast<std::size_t>((bj + dj) * width + bi + di);
      for (std::int32_t k = w.near_starts[slot]; k < w.near_starts[slot + 1]; ++k) {
        w.near_stamp[static_cast<std::size_t>(w.near_ids[static_cast<std::size_t>(k)])] = w.stamp;
      }
    }
  }
  w.candidate_ids.clear();
  blocks.ForEachMeeting(all, [&](std::int64_t id) {
    if (w.near_stamp[static_cast<std::size_t>(id)] != w.stamp) w.candidate_ids.push_back(id);
  });
}

// What the checks of one face's samples share.
struct FarCheck {
  const SculptMapping& mapping;
  const Mesh& sculpt;
  std::span<const Float3> origins, normals;
  const NormalQuery& query;
  bool nearest;  // the query's policy is HitPolicy::kNearest
  const NormalHits& out;
  std::span<std::uint8_t> undecided;
};

// Sample k's window against sculpt block `id` (its quads gathered into `quads` on first
// need): whether it crosses a quad of the block.
bool WindowCrossesBlock(const FarCheck& c, std::size_t k, std::int64_t id, const Box& candidate,
                        bool& gathered, BlockQuads& quads) {
  const float window = Window(k, c.query, c.nearest, c.out);
  const Segment segment(c.origins[k], c.normals[k], window);
  if (!segment.Meets(candidate)) return false;
  // The quads of the quarters of the block whose boxes the window meets too.
  if (!gathered) {
    GatherBlockQuads(c.mapping, c.sculpt, id, quads);
    gathered = true;
  }
  unsigned quarters = 0;
  for (int q = 0; q < quads.quarters(); ++q) {
    quarters |= segment.Meets(quads.quarter_box[q]) ? 1u << q : 0u;
  }
  if (quarters == 0) return false;
  // A crossing within rounding beyond the window's end counts: the ray path may find it
  // inside.
  const float reach = window + RoundingMargin(c.origins[k], window);
  return WindowCrossesQuads(quads, c.sculpt, quarters, c.origins[k], c.normals[k], reach);
}

// Each candidate (w.candidate_ids) against the samples of a block whose window boxes
// (w.window_boxes) meet its box, four boxes at a time; a sample undecided by one candidate is
// not tested against the next. Returns the samples it left undecided.
std::uint64_t CheckCandidates(const FarCheck& c, std::span<const std::int32_t> block_samples,
                              MappingScratch& w, BlockQuads& quads) {
  const SculptBlocks& blocks = c.mapping.blocks();
  const std::size_t groups = (block_samples.size() + 3) / 4;
  std::uint64_t sent = 0;
  for (const std::int64_t id : w.candidate_ids) {
    const Box& candidate = blocks.box(id);
    bool gathered = false;
    for (std::size_t g = 0; g < groups; ++g) {
      for (unsigned lanes = LanesMeeting(w.window_boxes.data(), g, candidate); lanes != 0;
           lanes &= lanes - 1) {
        const auto k = static_cast<std::size_t>(
            block_samples[4 * g + static_cast<std::size_t>(std::countr_zero(lanes))]);
        if (c.undecided[k]) continue;
        if (WindowCrossesBlock(c, k, id, candidate, gathered, quads)) {
          c.undecided[k] = 1;
          ++sent;
        }
      }
    }
  }
  return sent;
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
  // The samples of each block of cells at block_samples[block_first[at] .. block_first[at + 1]).
  BlockOfEachSampleRow(m, b, n, w);
  const auto un = static_cast<std::size_t>(n), uper = static_cast<std::size_t>(per);
  w.block_first.assign(uper * uper + 1, 0);
  if (samples.empty()) {
    GroupGridByBlock(un, uper, w);
  } else {
    GroupListedByBlock(samples, un, uper, w);
  }
  if (w.near_stamp.size() != static_cast<std::size_t>(blocks.num_blocks())) {
    w.near_stamp.assign(static_cast<std::size_t>(blocks.num_blocks()), 0);
    w.stamp = 0;
  }
  const FarCheck check{mapping, sculpt,   origins,
                       normals, query,    query.policy == HitPolicy::kNearest,
                       out,     undecided};
  std::uint64_t sent = 0;
  BlockQuads quads;
  for (int bj = 0; bj < per; ++bj) {
    for (int bi = 0; bi < per; ++bi) {
      const std::size_t at = static_cast<std::size_t>(bj) * uper + static_cast<std::size_t>(bi);
      const std::span<const std::int32_t> block_samples(
          w.block_samples.data() + w.block_first[at],
          static_cast<std::size_t>(w.block_first[at + 1] - w.block_first[at]));
      // The box of the block's windows, and the sculpt blocks it meets that are not near.
      const Box all = WindowsBox(block_samples, origins, normals, query, check.nearest, out,
                                 undecided, w.window_boxes);
      if (!(all.lower[0] <= all.upper[0])) continue;
      CollectFarBlocks(blocks, bi, bj, per, all, w);
      sent += CheckCandidates(check, block_samples, w, quads);
    }
  }
  return sent;
}

}  // namespace dispex::extract
