// Exact closest points on triangles, in double precision, for the sculpt's closest-point
// queries (the `verify` command's error measure).
#pragma once

namespace dispex::trace {

struct Vec3d {
  double x = 0, y = 0, z = 0;
};

inline Vec3d operator+(const Vec3d& a, const Vec3d& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3d operator-(const Vec3d& a, const Vec3d& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3d operator*(double s, const Vec3d& a) {
  return {s * a.x, s * a.y, s * a.z};
}
inline double Dot(const Vec3d& a, const Vec3d& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3d Cross(const Vec3d& a, const Vec3d& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double Distance2(const Vec3d& a, const Vec3d& b) {
  return Dot(a - b, a - b);
}

// The point of segment [a, b] nearest to p (a when a == b).
Vec3d ClosestPointOnSegment(const Vec3d& p, const Vec3d& a, const Vec3d& b);

// The point of triangle abc (its interior and edges) nearest to p. Degenerate triangles
// (repeated or collinear vertices) are handled as their edges.
Vec3d ClosestPointOnTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

}  // namespace dispex::trace
