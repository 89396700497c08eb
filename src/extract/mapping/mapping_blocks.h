// The samples of one cell traced at once, for the mapping's per-face driver (mapping_trace.cpp):
// rings 0 and 1 of up to kLanes samples against the cell's 3 x 3 slots in float lanes, the
// exact test in double where the float filter is unsure (mapping_blocks.cpp).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "extract/mapping/mapping_rays.h"

namespace dispex::extract::mapping {

constexpr int kLanes = 4;
using f4 = float __attribute__((vector_size(16)));
using i4 = std::int32_t __attribute__((vector_size(16)));

// The samples of one block: their index, origin and direction, and in float lanes the origins
// relative to the lattice's centre and each line's projection basis.
struct Lanes {
  int count = 0;
  std::size_t k[kLanes] = {};
  Float3 o[kLanes], d[kLanes];   // d FlushTiny'd
  f4 ox = {}, oy = {}, oz = {};  // origins relative to the lattice's centre
  f4 e1x = {}, e1y = {}, e1z = {}, e2x = {}, e2y = {}, e2z = {};  // Line's basis, in float
};

inline void AddLane(const MappingScratch& w, std::size_t k, const Float3& o, const Float3& d,
                    Lanes& b) {
  const int l = b.count++;
  b.k[l] = k;
  b.o[l] = o;
  b.d[l] = d;
  b.ox[l] = static_cast<float>(double(o.x) - w.centre[0]);
  b.oy[l] = static_cast<float>(double(o.y) - w.centre[1]);
  b.oz[l] = static_cast<float>(double(o.z) - w.centre[2]);
  const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  const float e1[3] = {ax <= ay && ax <= az ? 0
                       : ay <= az           ? -d.z
                                            : d.y,
                       ax <= ay && ax <= az ? d.z
                       : ay <= az           ? 0
                                            : -d.x,
                       ax <= ay && ax <= az ? -d.y
                       : ay <= az           ? d.x
                                            : 0};
  b.e1x[l] = e1[0], b.e1y[l] = e1[1], b.e1z[l] = e1[2];
  b.e2x[l] = d.y * e1[2] - d.z * e1[1];
  b.e2y[l] = d.z * e1[0] - d.x * e1[2];
  b.e2z[l] = d.x * e1[1] - d.y * e1[0];
}

// Rings 0 and 1 of cell (ci, cj), whose 9 slots are all quads, for the lanes: decided[l] when
// they decide lane l, settled[l] when it is undecided whatever more rings hold (a fold, a
// degenerate triangle); the others need more rings.
void TraceBlock(const MappingScratch& w, const Mesh& sculpt, int ci, int cj, const Lanes& b,
                const NormalQuery& query, const NormalHits& out, bool decided[kLanes],
                bool settled[kLanes]);

#if defined(__x86_64__)
// Two blocks of the same face at once, in AVX2 (8 lanes): the same answers as TraceBlock.
__attribute__((target("avx2"))) void TraceBlockPair(const MappingScratch& w, const Mesh& sculpt,
                                                    const int ci[2], const int cj[2],
                                                    const Lanes* const blocks[2],
                                                    const NormalQuery& query, const NormalHits& out,
                                                    bool decided[2][kLanes],
                                                    bool settled[2][kLanes]);
#endif

// Whether this CPU runs TraceBlockPair.
bool CpuPairsBlocks();

}  // namespace dispex::extract::mapping
