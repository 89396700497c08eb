// The names of the points faces share in the crack-free tessellation (tessellation.cpp): each
// side of a Ptex face lies on a "line" of the cage -- a cage edge (quads cover it whole, n-gon
// sub-faces one half each) or, inside an n-gon, a spoke from an edge midpoint to the face
// centre -- and every point a face puts on a line is named exactly, by the line and a reduced
// fraction along it (or, at a line's ends, by the cage vertex, edge midpoint or face centre
// there), so the faces around a point find the same name.
//
// The small helpers are inline: the tessellation calls them in its sorts and per point.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"

namespace dispex::render::lines {

inline constexpr std::int32_t kBaseEdge = 0, kSpoke = 1;
enum : std::int32_t { kVertexPoint = 0, kEdgePoint = 1, kSpokePoint = 2, kCentrePoint = 3 };

// A line of the cage: a base edge (a < b, its vertices) or a spoke (a = base face, b = corner
// q: from the midpoint of the face's edge q to its centre). Parameters along a line run 0..2.
struct LineKey {
  std::int32_t kind = 0, a = 0, b = 0;
  auto operator<=>(const LineKey&) const = default;
};

// One side of one Ptex face on its line: from parameter p0 (the side's start, in the face's
// counter-clockwise order) to p1, cut into `segs` equal segments.
struct SideEntry {
  LineKey line;
  std::int32_t p0 = 0, p1 = 0;
  std::int32_t segs = 0;
  std::int32_t face = -1, side = 0;
};

// An exact parameter num / den on a line, reduced (0 / 1 for zero).
struct Frac {
  std::int32_t num = 0, den = 1;
};
inline bool FracLess(Frac x, Frac y) {
  return std::int64_t(x.num) * y.den < std::int64_t(y.num) * x.den;
}
inline Frac Reduce(std::int32_t num, std::int32_t den) {
  const std::int32_t g = std::gcd(num, den);
  return {num / g, den / g};
}

struct PointKey {
  std::int32_t kind = 0, a = 0, b = 0, num = 0, den = 0;
  auto operator<=>(const PointKey&) const = default;
};

// One face's view of one shared point, from one of its sides.
struct Record {
  PointKey key;
  std::int32_t face = 0;
  float u = 0, v = 0;
  std::int64_t line_point = 0;  // the point's index in the flat array of line points
  std::int32_t side = 0;        // the side of `face` whose line holds the point
};
// A total order. The side comes last: records equal up to it differ in nothing the mean
// displacement reads.
inline bool RecordLess(const Record& x, const Record& y) {
  if (x.key != y.key) return x.key < y.key;
  if (x.face != y.face) return x.face < y.face;
  if (x.u != y.u) return x.u < y.u;
  if (x.v != y.v) return x.v < y.v;
  if (x.line_point != y.line_point) return x.line_point < y.line_point;
  return x.side < y.side;
}

// The (u, v) of the point at fraction s along side `side` of a face (counter-clockwise from
// (0, 0)).
inline void SideUv(int side, double s, float& u, float& v) {
  switch (side) {
    case 0:
      u = static_cast<float>(s), v = 0;
      return;
    case 1:
      u = 1, v = static_cast<float>(s);
      return;
    case 2:
      u = static_cast<float>(1.0 - s), v = 1;
      return;
    default:
      u = 0, v = static_cast<float>(1.0 - s);
      return;
  }
}

// The name of the point at parameter t of `line`.
PointKey KeyOf(const Mesh& cage, const LineKey& line, Frac t);

// The four sides of Ptex face f, cut into kx (sides 0 and 2) and ky (sides 1 and 3) segments
// (see the conventions in include/dispex/subdiv.h: a quad's corners are its vertices 0..3;
// sub-face q of an n-gon runs from vertex q (0,0) to the midpoint of edge q (1,0), the centre
// (1,1) and the midpoint of edge q-1 (0,1)).
void FaceSides(const Mesh& cage, const LimitSurface& surface, int f, int kx, int ky,
               SideEntry out[4]);

// Grid point i of a side, as a parameter on its line.
inline Frac PointOnSide(const SideEntry& e, int i) {
  return Reduce(e.p0 * e.segs + (e.p1 - e.p0) * i, e.segs);
}

// Whether the side covers parameter t of its line (its ends included).
inline bool Covers(const SideEntry& e, Frac t) {
  const std::int64_t lo = std::min(e.p0, e.p1), hi = std::max(e.p0, e.p1);
  return std::int64_t(t.num) >= lo * t.den && std::int64_t(t.num) <= hi * t.den;
}

// Where parameter t of the line lies along the side, 0 at its start and 1 at its end.
inline double SigmaOf(const SideEntry& e, Frac t) {
  return double(std::int64_t(t.num) - std::int64_t(e.p0) * t.den) /
         double(std::int64_t(t.den) * (e.p1 - e.p0));
}

}  // namespace dispex::render::lines
