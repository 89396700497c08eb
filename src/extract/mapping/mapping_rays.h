// Lines against the sculpt's quads, exactly (in double) as the Tracer's hit contract asks
// (mapping_trace.h), and one sample decided ring after ring: shared by the cell blocks
// (mapping_blocks.cpp) and the per-face driver (mapping_trace.cpp), inline in both.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/vec3.h"
#include "extract/mapping/mapping_lattice.h"
#include "extract/mapping/mapping_trace.h"

namespace dispex::extract::mapping {

// ---- Lines against quads -------------------------------------------------------------------

// Direction components below 2^-24 of the largest are zero (the Tracer's rule).
inline Float3 FlushTiny(const Float3& d) {
  const float floor = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}) * 0x1p-24f;
  return Float3{std::fabs(d.x) < floor ? 0.0f : d.x, std::fabs(d.y) < floor ? 0.0f : d.y,
                std::fabs(d.z) < floor ? 0.0f : d.z};
}

inline bool Finite(const Float3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// One sample's line o + t d and the plane across it the quads' corners are projected onto.
// Projections and edge values are computed the same way for every quad, so two triangles that
// share an edge see the line on opposite sides of it, or on it (this needs the products rounded
// one by one: no fused multiply-add, which ISO C++ mode leaves off).
struct Line {
  Float3 o, d;
  Vec3d origin, e1, e2;

  Line() = default;
  Line(const Float3& o_in, const Float3& d_in) : o(o_in), d(d_in), origin(ToVec3d(o_in)) {
    const Vec3d dir = ToVec3d(d);
    const double ax = std::fabs(dir.x), ay = std::fabs(dir.y), az = std::fabs(dir.z);
    e1 = ax <= ay && ax <= az ? Vec3d{0, dir.z, -dir.y}
         : ay <= az           ? Vec3d{-dir.z, 0, dir.x}
                              : Vec3d{dir.y, -dir.x, 0};
    e2 = Cross(dir, e1);
  }
  void Project(const Float3& v, double& px, double& py) const {
    const Vec3d w = ToVec3d(v) - origin;
    px = Dot(w, e1);
    py = Dot(w, e2);
  }
};

inline double EdgeValue(double ax, double ay, double bx, double by) {
  return ax * by - ay * bx;
}

inline bool Inside(double a, double b, double c) {
  return ((a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0)) &&
         (a != 0 || b != 0 || c != 0);
}

// The Tracer's t (batch_kernels.h, ExactT): the line against the plane of triangle (a, b, c).
inline double PlaneT(const Float3& fa, const Float3& fb, const Float3& fc, const Float3& o,
                     const Float3& d, double& den) {
  const Vec3d a = ToVec3d(fa);
  const Vec3d n = Cross(ToVec3d(fb) - a, ToVec3d(fc) - a);
  den = n.x * d.x + n.y * d.y + n.z * d.z;
  return (n.x * (double(fa.x) - o.x) + n.y * (double(fa.y) - o.y) + n.z * (double(fa.z) - o.z)) /
         den;
}

struct Candidate {
  float t = 0;         // along +d (a -n hit has t <= 0)
  int ring = INT_MAX;  // where it was found
  std::int32_t face = -1;
  bool front_plus = false;  // dot(+d, normal) <= 0
  bool found() const { return face >= 0; }
};

// One sample's crossings, as the rings are tested.
struct Crossings {
  float distance = 0;
  Candidate plus, minus;    // the nearest within the window on either side
  int any_ring = INT_MAX;   // the innermost ring where the line crossed a quad at all
  bool degenerate = false;  // crossed a triangle with no plane (t not finite)
  // Which way round the quads tested face the line (bit 0: counter-clockwise seen along -d,
  // bit 1: clockwise or edge-on): both means the sculpt folds over or stands edge-on nearby.
  unsigned orientations = 0;

  void Add(float t, double den, int ring, std::int32_t face) {
    any_ring = std::min(any_ring, ring);
    const bool front_plus = !(den > 0);
    if (!(t < 0) && t <= distance && (!plus.found() || t < plus.t)) {
      plus = {t, ring, face, front_plus};
    }
    const float tm = -t;
    if (!(tm < 0) && tm <= distance && (!minus.found() || tm < -minus.t)) {
      minus = {t, ring, face, front_plus};
    }
  }
};

// TestQuad with its corners' projections given: (x_k, y_k) that of the face's corner k.
inline void TestProjectedQuad(const Line& line, const Mesh& sculpt, std::int32_t face, int ring,
                              double x0, double y0, double x1, double y1, double x2, double y2,
                              double x3, double y3, Crossings& x) {
  const std::int32_t* ids = sculpt.face_indices.data() + 4 * static_cast<std::size_t>(face);
  const Float3* p = sculpt.positions.data();
  const Float3& v0 = p[ids[0]];
  const Float3& v1 = p[ids[1]];
  const Float3& v2 = p[ids[2]];
  const Float3& v3 = p[ids[3]];
  const double e01 = EdgeValue(x0, y0, x1, y1), e13 = EdgeValue(x1, y1, x3, y3);
  const double e30 = EdgeValue(x3, y3, x0, y0), e23 = EdgeValue(x2, y2, x3, y3);
  const double e12 = EdgeValue(x1, y1, x2, y2);
  x.orientations |= e01 + e12 + e23 + e30 > 0 ? 1u : 2u;
  double den = 0;
  if (Inside(e01, e13, e30)) {
    const double t = PlaneT(v0, v1, v3, line.o, line.d, den);
    if (!std::isfinite(t)) {
      x.degenerate = true;
    } else {
      x.Add(static_cast<float>(t), den, ring, face);
    }
  }
  if (Inside(e23, -e13, e12)) {
    const double t = PlaneT(v2, v3, v1, line.o, line.d, den);
    if (!std::isfinite(t)) {
      x.degenerate = true;
    } else {
      x.Add(static_cast<float>(t), den, ring, face);
    }
  }
}

inline void TestQuad(const Line& line, const Mesh& sculpt, std::int32_t face, int ring,
                     Crossings& x) {
  const std::int32_t* ids = sculpt.face_indices.data() + 4 * static_cast<std::size_t>(face);
  const Float3* p = sculpt.positions.data();
  double px[4], py[4];
  for (int k = 0; k < 4; ++k) line.Project(p[ids[k]], px[k], py[k]);
  TestProjectedQuad(line, sculpt, face, ring, px[0], py[0], px[1], py[1], px[2], py[2], px[3],
                    py[3], x);
}

// The hit `policy` keeps (TraceNormals' choice between the two rays), and whether it is -n's.
inline const Candidate* Kept(const Crossings& x, HitPolicy policy, bool& negative) {
  const Candidate* pick = nullptr;
  switch (policy) {
    case HitPolicy::kNearest:
      // A tie keeps +n; so does a +n hit at t = 0, after which -n is not cast.
      if (x.plus.found() && !(x.minus.found() && -x.minus.t < x.plus.t)) {
        pick = &x.plus;
      } else if (x.minus.found()) {
        pick = &x.minus;
      }
      break;
    case HitPolicy::kOutsideFirst:
      pick = x.plus.found() ? &x.plus : x.minus.found() ? &x.minus : nullptr;
      break;
    case HitPolicy::kInsideFirst:
      pick = x.minus.found() ? &x.minus : x.plus.found() ? &x.plus : nullptr;
      break;
  }
  negative = pick == &x.minus;
  return pick;
}

inline int CornerDistance(int ci, int cj, int m, int corner) {
  const int di = corner == 0 || corner == 3 ? ci : m - 1 - ci;
  const int dj = corner == 0 || corner == 1 ? cj : m - 1 - cj;
  return std::max(di, dj);
}

// Tests ring `r` around cell (ci, cj); false when part of it is not laid out.
inline bool TestRing(const MappingScratch& w, const Mesh& sculpt, const Line& line, int ci, int cj,
                     int r, Crossings& x, std::uint64_t& quads) {
  const int width = w.m + 2 * kMargin;
  auto test_slot = [&](int a, int b) {
    const MappingScratch::Slot& slot =
        w.apron[static_cast<std::size_t>((b + kMargin) * width + a + kMargin)];
    if (slot.state == kCell) {
      TestQuad(line, sculpt, slot.face, r, x);
      ++quads;
    }
    return slot.state != kUnknown;
  };
  bool complete = true;
  if (r == 0) {
    complete = test_slot(ci, cj);
  } else {
    for (int a = ci - r; a <= ci + r; ++a) {
      complete &= test_slot(a, cj - r);
      complete &= test_slot(a, cj + r);
    }
    for (int b = cj - r + 1; b <= cj + r - 1; ++b) {
      complete &= test_slot(ci - r, b);
      complete &= test_slot(ci + r, b);
    }
  }
  for (int c = 0; c < 4; ++c) {
    if (!w.fan_corner[c]) continue;
    const int offset = r - 1 - CornerDistance(ci, cj, w.m, c);
    if (offset < 0) continue;
    for (const MappingScratch::FanCell& cell : w.fans[c]) {
      if (cell.offset > offset) break;
      if (cell.offset < offset) continue;
      TestQuad(line, sculpt, cell.face, r, x);
      ++quads;
    }
  }
  return complete;
}

// ---- One sample, ring after ring -----------------------------------------------------------

// Writes sample k's answer when rings 0..r decide it; false when they do not yet.
inline bool Decide(const Crossings& x, int r, HitPolicy policy, std::size_t k,
                   const NormalHits& out) {
  bool negative = false;
  const Candidate* kept = Kept(x, policy, negative);
  if (kept != nullptr && kept->ring <= r - 1) {
    out.t[k] = kept->t;
    const bool back = negative ? kept->front_plus : !kept->front_plus;
    out.flags[k] = static_cast<std::uint8_t>(HitFlags::kHit | (negative ? HitFlags::kNegative : 0) |
                                             (back ? HitFlags::kBackFace : 0));
    if (!out.prim.empty()) out.prim[k] = SculptPrimId(kept->face);
    return true;
  }
  if (kept == nullptr && x.any_ring <= r - 1) {
    out.t[k] = std::numeric_limits<float>::quiet_NaN();
    out.flags[k] = 0;
    if (!out.prim.empty()) out.prim[k] = SculptPrimId();
    return true;
  }
  return false;
}

// Sample k over cell (ci, cj), rings 0 to kMaxRings; whether it was decided.
inline bool TraceRings(const MappingScratch& w, const Mesh& sculpt, const Line& line, int ci,
                       int cj, const NormalQuery& query, std::size_t k, const NormalHits& out,
                       std::uint64_t& quads) {
  Crossings x;
  x.distance = query.distance;
  for (int r = 0; r <= kMaxRings; ++r) {
    if (!TestRing(w, sculpt, line, ci, cj, r, x, quads) || x.degenerate || x.orientations == 3) {
      return false;
    }
    if (Decide(x, r, query.policy, k, out)) return true;
  }
  return false;
}

}  // namespace dispex::extract::mapping
