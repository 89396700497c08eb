// The samples of one cell traced at once (4 lanes; two blocks at once in AVX2), for the
// mapping's per-face driver (mapping_trace.cpp).
#include "extract/mapping/mapping_blocks.h"

#include <algorithm>
#include <cmath>

namespace dispex::extract::mapping {

// ---- The samples of one cell at once -------------------------------------------------------
// The cell's 3 x 3 slots (rings 0 and 1) against up to kLanes samples: the lattice's 16 points
// projected along each sample's normal in float, each edge's value once, and a triangle
// classified as surely met, surely missed (beyond a bound on the float error) or unsure; the
// met and the unsure go to the exact test in double (the same as TestQuad's).

namespace {

f4 Abs(f4 a) {
  return a < 0 ? -a : a;
}
f4 Max(f4 a, f4 b) {
  return a > b ? a : b;
}
f4 Min(f4 a, f4 b) {
  return a < b ? a : b;
}
unsigned Bits(i4 mask) {
#if defined(__SSE__)
  return static_cast<unsigned>(__builtin_ia32_movmskps(reinterpret_cast<f4>(mask)));
#else
  return (mask[0] & 1u) | (mask[1] & 2u) | (mask[2] & 4u) | (mask[3] & 8u);
#endif
}

// Triangle (a, b, c) of a face by the exact test: whether the line meets it.
bool ExactInside(const Line& line, const Float3& fa, const Float3& fb, const Float3& fc) {
  double xa, ya, xb, yb, xc, yc;
  line.Project(fa, xa, ya);
  line.Project(fb, xb, yb);
  line.Project(fc, xc, yc);
  return Inside(EdgeValue(xa, ya, xb, yb), EdgeValue(xb, yb, xc, yc), EdgeValue(xc, yc, xa, ya));
}

}  // namespace

// Rings 0 and 1 of cell (ci, cj), whose 9 slots are all quads, for the lanes: decided[l] when
// they decide lane l, settled[l] when it is undecided whatever more rings hold (a fold, a
// degenerate triangle); the others need more rings.
void TraceBlock(const MappingScratch& w, const Mesh& sculpt, int ci, int cj, const Lanes& b,
                const NormalQuery& query, const NormalHits& out, bool decided[kLanes],
                bool settled[kLanes]) {
  const int width = w.m + 2 * kMargin, points = width + 1;
  f4 px[16], py[16];
  f4 reach = {};
  for (int q = 0; q < 16; ++q) {
    const int x = ci - 1 + (q & 3) + kMargin, y = cj - 1 + (q >> 2) + kMargin;
    const float* v = &w.lattice[3 * static_cast<std::size_t>(y * points + x)];
    const f4 wx = v[0] - b.ox, wy = v[1] - b.oy, wz = v[2] - b.oz;
    px[q] = wx * b.e1x + wy * b.e1y + wz * b.e1z;
    py[q] = wx * b.e2x + wy * b.e2y + wz * b.e2z;
    reach = Max(reach, Abs(px[q]) + Abs(py[q]));
  }
  // An edge value's error: the projections are within 2^-19 of the coordinates' magnitude
  // (lattice and origin, relative to the centre; each step rounds to float once) and an edge
  // value multiplies projections of at most `reach`.
  const f4 magnitude = Max(Max(Abs(b.ox), Abs(b.oy)), Max(Abs(b.oz), f4{} + w.extent));
  const f4 tol = 4 * reach * magnitude * 0x1p-19f + reach * reach * 0x1p-19f;
  auto edge = [&](int a, int c) { return px[a] * py[c] - py[a] * px[c]; };
  f4 h[4][3], v[3][4];
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 3; ++x) h[y][x] = edge(y * 4 + x, y * 4 + x + 1);
  }
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) v[y][x] = edge(y * 4 + x, (y + 1) * 4 + x);
  }
  const unsigned active = (1u << b.count) - 1;
  Crossings x[kLanes];
  for (int l = 0; l < kLanes; ++l) x[l].distance = query.distance;
  i4 counter_clockwise = {}, clockwise = {};
  const Float3* p = sculpt.positions.data();
  for (int sy = 0; sy < 3; ++sy) {
    for (int sx = 0; sx < 3; ++sx) {
      const MappingScratch::Slot& slot = w.apron[static_cast<std::size_t>(
          (cj - 1 + sy + kMargin) * width + ci - 1 + sx + kMargin)];
      const int ring = sx == 1 && sy == 1 ? 0 : 1;
      const int c0 = sy * 4 + sx, c1 = c0 + 1, c2 = c0 + 5, c3 = c0 + 4;
      // The face's corner 2 at this slot corner; its triangle (v0 v1 v3) lies opposite it.
      const int corner2 = (2 - slot.corner) & 3;
      const bool main = (corner2 & 1) != 0;  // the diagonal runs through slot corners 0 and 2
      const f4 dg = main ? edge(c0, c2) : edge(c1, c3);
      const f4 bottom = h[sy][sx], right = v[sy][sx + 1], top = -h[sy + 1][sx], left = -v[sy][sx];
      const i4 ccw = bottom + right + top + left > 0;
      counter_clockwise |= ccw;
      clockwise |= ~ccw;
      // The slot's two triangles, each by its edge values and the slot corner it leaves out.
      const f4 tri[2][3] = {{bottom, main ? right : dg, main ? -dg : left},
                            {main ? dg : right, top, main ? left : -dg}};
      const int left_out[2] = {main ? 3 : 2, main ? 1 : 0};
      const std::int32_t* ids =
          sculpt.face_indices.data() + 4 * static_cast<std::size_t>(slot.face);
      for (int t = 0; t < 2; ++t) {
        const f4 low = Min(Min(tri[t][0], tri[t][1]), tri[t][2]);
        const f4 high = Max(Max(tri[t][0], tri[t][1]), tri[t][2]);
        const unsigned maybe = Bits((low >= -tol) | (high <= tol)) & active;
        if (maybe == 0) continue;
        const unsigned sure = Bits((low > tol) | (high < -tol));
        const bool first = left_out[t] == corner2;  // the face's (v0, v1, v3)
        const Float3& fa = p[ids[first ? 0 : 2]];
        const Float3& fb = p[ids[first ? 1 : 3]];
        const Float3& fc = p[ids[first ? 3 : 1]];
        for (int l = 0; l < b.count; ++l) {
          if (!(maybe & (1u << l))) continue;
          if (!(sure & (1u << l)) && !ExactInside(Line(b.o[l], b.d[l]), fa, fb, fc)) continue;
          double den = 0;
          const double tt = PlaneT(fa, fb, fc, b.o[l], b.d[l], den);
          if (!std::isfinite(tt)) {
            x[l].degenerate = true;
          } else {
            x[l].Add(static_cast<float>(tt), den, ring, slot.face);
          }
        }
      }
    }
  }
  const unsigned both = Bits(counter_clockwise) & Bits(clockwise);
  for (int l = 0; l < b.count; ++l) {
    settled[l] = x[l].degenerate || (both & (1u << l)) != 0;
    decided[l] = !settled[l] && Decide(x[l], 1, query.policy, b.k[l], out);
  }
}

#if defined(__x86_64__)
// ---- Two blocks at once, in AVX2 -------------------------------------------------------------

using f8 = float __attribute__((vector_size(32)));
using i8 = std::int32_t __attribute__((vector_size(32)));

// TraceBlock for two blocks at once: the 8 lanes of a 256-bit register hold two blocks of the
// same face (lane 4 h + l: block h's lane l), each of its own cell. Every lane's floats come
// from the operations TraceBlock does, in the same order (no fused multiply-add in either), so
// both kernels keep the same samples for the exact test and answer alike
// (tests/extract/mapping_test.cpp compares them).
//
// Why it is one long function: it is the mapping method's hot kernel, and its vector code must
// all stay inside this target("avx2") function. Lambdas and helper functions are compiled for
// the baseline ISA, not this function's: a step split out would take its 256-bit vectors
// through memory (a different ABI without AVX) and, wherever GCC does not inline it, run
// without AVX2.
__attribute__((target("avx2"))) void TraceBlockPair(const MappingScratch& w, const Mesh& sculpt,
                                                    const int ci[2], const int cj[2],
                                                    const Lanes* const blocks[2],
                                                    const NormalQuery& query, const NormalHits& out,
                                                    bool decided[2][kLanes],
                                                    bool settled[2][kLanes]) {
  const int width = w.m + 2 * kMargin, points = width + 1;
  const Lanes& A = *blocks[0];
  const Lanes& B = *blocks[1];
#define DISPEX_JOIN(field) __builtin_shufflevector(A.field, B.field, 0, 1, 2, 3, 4, 5, 6, 7)
  const f8 ox = DISPEX_JOIN(ox), oy = DISPEX_JOIN(oy), oz = DISPEX_JOIN(oz);
  const f8 e1x = DISPEX_JOIN(e1x), e1y = DISPEX_JOIN(e1y), e1z = DISPEX_JOIN(e1z);
  const f8 e2x = DISPEX_JOIN(e2x), e2y = DISPEX_JOIN(e2y), e2z = DISPEX_JOIN(e2z);
#undef DISPEX_JOIN
  f8 px[16], py[16];
  f8 reach = {};
  for (int q = 0; q < 16; ++q) {
    const float* v[2];
    for (int h = 0; h < 2; ++h) {
      const int x = ci[h] - 1 + (q & 3) + kMargin, y = cj[h] - 1 + (q >> 2) + kMargin;
      v[h] = &w.lattice[3 * static_cast<std::size_t>(y * points + x)];
    }
    const f8 vx = {v[0][0], v[0][0], v[0][0], v[0][0], v[1][0], v[1][0], v[1][0], v[1][0]};
    const f8 vy = {v[0][1], v[0][1], v[0][1], v[0][1], v[1][1], v[1][1], v[1][1], v[1][1]};
    const f8 vz = {v[0][2], v[0][2], v[0][2], v[0][2], v[1][2], v[1][2], v[1][2], v[1][2]};
    const f8 wx = vx - ox, wy = vy - oy, wz = vz - oz;
    px[q] = wx * e1x + wy * e1y + wz * e1z;
    py[q] = wx * e2x + wy * e2y + wz * e2z;
    const f8 ax = px[q] < 0 ? -px[q] : px[q], ay = py[q] < 0 ? -py[q] : py[q];
    const f8 sum = ax + ay;
    reach = reach > sum ? reach : sum;
  }
  // TraceBlock's bound on an edge value's error, lane by lane.
  const f8 aox = ox < 0 ? -ox : ox, aoy = oy < 0 ? -oy : oy, aoz = oz < 0 ? -oz : oz;
  const f8 extent = f8{} + w.extent;
  const f8 mxy = aox > aoy ? aox : aoy, mze = aoz > extent ? aoz : extent;
  const f8 magnitude = mxy > mze ? mxy : mze;
  const f8 tol = 4 * reach * magnitude * 0x1p-19f + reach * reach * 0x1p-19f;
#define DISPEX_EDGE(a, c) (px[a] * py[c] - py[a] * px[c])
  f8 hz[4][3], vt[3][4];
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 3; ++x) hz[y][x] = DISPEX_EDGE(y * 4 + x, y * 4 + x + 1);
  }
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) vt[y][x] = DISPEX_EDGE(y * 4 + x, (y + 1) * 4 + x);
  }
  const unsigned active = ((1u << A.count) - 1) | (((1u << B.count) - 1) << 4);
  Crossings x[2 * kLanes];
  for (int l = 0; l < 2 * kLanes; ++l) x[l].distance = query.distance;
  i8 counter_clockwise = {}, clockwise = {};
  const Float3* p = sculpt.positions.data();
  for (int sy = 0; sy < 3; ++sy) {
    for (int sx = 0; sx < 3; ++sx) {
      const MappingScratch::Slot* slot[2];
      int corner2[2];
      bool main[2];
      for (int h = 0; h < 2; ++h) {
        slot[h] = &w.apron[static_cast<std::size_t>((cj[h] - 1 + sy + kMargin) * width + ci[h] - 1 +
                                                    sx + kMargin)];
        corner2[h] = (2 - slot[h]->corner) & 3;
        main[h] = (corner2[h] & 1) != 0;
      }
      const int ring = sx == 1 && sy == 1 ? 0 : 1;
      const int c0 = sy * 4 + sx, c1 = c0 + 1, c2 = c0 + 5, c3 = c0 + 4;
      const std::int32_t ma = main[0] ? -1 : 0, mb = main[1] ? -1 : 0;
      const i8 is_main = {ma, ma, ma, ma, mb, mb, mb, mb};
      const f8 dg = is_main ? DISPEX_EDGE(c0, c2) : DISPEX_EDGE(c1, c3);
      const f8 bottom = hz[sy][sx], right = vt[sy][sx + 1], top = -hz[sy + 1][sx],
               left = -vt[sy][sx];
      const i8 ccw = bottom + right + top + left > 0;
      counter_clockwise |= ccw;
      clockwise |= ~ccw;
      const f8 tri[2][3] = {{bottom, is_main ? right : dg, is_main ? -dg : left},
                            {is_main ? dg : right, top, is_main ? left : -dg}};
      // A lane's exact value of the slot's diagonal (slot corner 0 to 2, or 1 to 3), once
      // computed: where a triangle is unsure only along the diagonal (texel centres at a
      // quarter of a cell lie on it), that value decides both triangles; see below.
      double diagonal[2 * kLanes];
      unsigned have_diagonal = 0;
      for (int t = 0; t < 2; ++t) {
        const f8 lo01 = tri[t][0] < tri[t][1] ? tri[t][0] : tri[t][1];
        const f8 low = lo01 < tri[t][2] ? lo01 : tri[t][2];
        const f8 hi01 = tri[t][0] > tri[t][1] ? tri[t][0] : tri[t][1];
        const f8 high = hi01 > tri[t][2] ? hi01 : tri[t][2];
        const i8 maybe_mask = (low >= -tol) | (high <= tol);
        const unsigned maybe =
            static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<f8>(maybe_mask))) &
            active;
        if (maybe == 0) continue;
        const i8 sure_mask = (low > tol) | (high < -tol);
        const auto sure =
            static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<f8>(sure_mask)));
        for (int l = 0; l < 2 * kLanes; ++l) {
          if (!(maybe & (1u << l))) continue;
          const int h = l >> 2, lane = l & 3;
          const Lanes& b = *blocks[h];
          const int left_out = t == 0 ? (main[h] ? 3 : 2) : (main[h] ? 1 : 0);
          const bool first = left_out == corner2[h];  // the face's (v0, v1, v3)
          const std::int32_t* ids =
              sculpt.face_indices.data() + 4 * static_cast<std::size_t>(slot[h]->face);
          const Float3& fa = p[ids[first ? 0 : 2]];
          const Float3& fb = p[ids[first ? 1 : 3]];
          const Float3& fc = p[ids[first ? 3 : 1]];
          if (!(sure & (1u << l))) {
            // The triangle's diagonal is tri[t][di] (dg, or -dg where `negated`). When its
            // two other edges lie beyond the float error with one sign, ExactInside's answer
            // is that the diagonal's exact value, seen the same way round, has that sign or
            // is 0: its other two exact values have the sign the float ones have (what "sure"
            // relies on), and ExactInside's three values are these, all negated or not.
            const int di = main[h] ? (t == 0 ? 2 : 0) : (t == 0 ? 1 : 2);
            const bool negated = (t == 0) == main[h];
            const float ea = tri[t][(di + 1) % 3][l], eb = tri[t][(di + 2) % 3][l];
            const bool positive = ea > tol[l] && eb > tol[l];
            const bool negative = ea < -tol[l] && eb < -tol[l];
            if (positive || negative) {
              if (!(have_diagonal & (1u << l))) {
                const Line line(b.o[lane], b.d[lane]);
                const int k = main[h] ? 0 : 1;  // the diagonal's first slot corner
                double xa, ya, xb, yb;
                line.Project(p[ids[(slot[h]->corner + k) & 3]], xa, ya);
                line.Project(p[ids[(slot[h]->corner + k + 2) & 3]], xb, yb);
                diagonal[l] = EdgeValue(xa, ya, xb, yb);
                have_diagonal |= 1u << l;
              }
              const double along = negated ? -diagonal[l] : diagonal[l];
              if (positive ? !(along >= 0) : !(along <= 0)) continue;
            } else if (!ExactInside(Line(b.o[lane], b.d[lane]), fa, fb, fc)) {
              continue;
            }
          }
          double den = 0;
          const double tt = PlaneT(fa, fb, fc, b.o[lane], b.d[lane], den);
          if (!std::isfinite(tt)) {
            x[l].degenerate = true;
          } else {
            x[l].Add(static_cast<float>(tt), den, ring, slot[h]->face);
          }
        }
      }
    }
  }
#undef DISPEX_EDGE
  const unsigned both =
      static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<f8>(counter_clockwise))) &
      static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<f8>(clockwise)));
  for (int h = 0; h < 2; ++h) {
    const Lanes& b = *blocks[h];
    for (int l = 0; l < b.count; ++l) {
      const int lane = 4 * h + l;
      settled[h][l] = x[lane].degenerate || (both & (1u << lane)) != 0;
      decided[h][l] = !settled[h][l] && Decide(x[lane], 1, query.policy, b.k[l], out);
    }
  }
}

bool CpuPairsBlocks() {
  return __builtin_cpu_supports("avx2") != 0;
}
#else
bool CpuPairsBlocks() {
  return false;
}
#endif

}  // namespace dispex::extract::mapping
