// The one double-precision 3-vector of dispex's internals: camera and shading arithmetic in
// render, exact closest points in trace, areas and normals wherever float positions are
// combined in double. Public headers use Float3 (dispex/mesh.h) for stored positions.
#pragma once

#include <cmath>

namespace dispex {

struct Vec3d {
  double x = 0, y = 0, z = 0;
};

inline Vec3d operator+(const Vec3d& a, const Vec3d& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3d operator-(const Vec3d& a, const Vec3d& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3d operator*(const Vec3d& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
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
inline double Length(const Vec3d& a) {
  return std::sqrt(Dot(a, a));
}
inline double Distance2(const Vec3d& a, const Vec3d& b) {
  return Dot(a - b, a - b);
}
// The unit vector along a; +z for the zero vector.
inline Vec3d Normalize(const Vec3d& a) {
  const double len = std::sqrt(Dot(a, a));
  return len > 0 ? a * (1.0 / len) : Vec3d{0, 0, 1};
}

// From and to any point type with x, y, z members (Float3).
template <class P>
Vec3d ToVec3d(const P& p) {
  return {p.x, p.y, p.z};
}
template <class P>
P FromVec3d(const Vec3d& v) {
  using T = decltype(P::x);
  return {static_cast<T>(v.x), static_cast<T>(v.y), static_cast<T>(v.z)};
}

}  // namespace dispex
