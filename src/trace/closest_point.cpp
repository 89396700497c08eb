// Closest point on a triangle by Voronoi regions, following C. Ericson, "Real-Time Collision
// Detection" (2005), section 5.1.5: test the vertex regions, then the edge regions, and
// otherwise project onto the plane with barycentric coordinates from the same dot products.
// Every denominator is a squared edge length or the squared double area, so degenerate
// triangles are routed to the edge-only answer before any division.
#include "trace/closest_point.h"

#include <algorithm>

namespace dispex::trace {

Vec3d ClosestPointOnSegment(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
  const Vec3d ab = b - a;
  const double length2 = Dot(ab, ab);
  if (length2 <= 0) return a;
  const double t = std::clamp(Dot(p - a, ab) / length2, 0.0, 1.0);
  return a + t * ab;
}

namespace {

Vec3d ClosestOnEdges(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d candidates[3] = {ClosestPointOnSegment(p, a, b), ClosestPointOnSegment(p, b, c),
                               ClosestPointOnSegment(p, c, a)};
  const Vec3d* best = &candidates[0];
  for (const Vec3d& q : candidates) {
    if (Distance2(p, q) < Distance2(p, *best)) best = &q;
  }
  return *best;
}

}  // namespace

Vec3d ClosestPointOnTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d ab = b - a, ac = c - a, bc = c - b;
  const Vec3d normal = Cross(ab, ac);
  if (Dot(ab, ab) <= 0 || Dot(ac, ac) <= 0 || Dot(bc, bc) <= 0 || Dot(normal, normal) <= 0) {
    return ClosestOnEdges(p, a, b, c);
  }

  const Vec3d ap = p - a;
  const double d1 = Dot(ab, ap), d2 = Dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;

  const Vec3d bp = p - b;
  const double d3 = Dot(ab, bp), d4 = Dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;  // edge ab

  const Vec3d cp = p - c;
  const double d5 = Dot(ab, cp), d6 = Dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;  // edge ac

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * bc;  // edge bc
  }

  const double sum = va + vb + vc;                    // the squared double area, up to rounding
  if (!(sum > 0)) return ClosestOnEdges(p, a, b, c);  // a sliver that rounding made flat
  const double v = vb / sum, w = vc / sum;
  return a + v * ab + w * ac;
}

}  // namespace dispex::trace
