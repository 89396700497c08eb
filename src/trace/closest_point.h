// Exact closest points on triangles, in double precision, for the sculpt's closest-point
// queries (the `verify` command's error measure).
#pragma once

#include "core/vec3.h"

namespace dispex::trace {

// The point of segment [a, b] nearest to p (a when a == b).
Vec3d ClosestPointOnSegment(const Vec3d& p, const Vec3d& a, const Vec3d& b);

// The point of triangle abc (its interior and edges) nearest to p. Degenerate triangles
// (repeated or collinear vertices) are handled as their edges.
Vec3d ClosestPointOnTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

}  // namespace dispex::trace
