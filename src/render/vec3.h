// Double-precision 3-vectors for the renderer's camera and shading arithmetic.
#pragma once

#include <cmath>

#include "dispex/mesh.h"

namespace dispex::render {

struct V3 {
  double x = 0, y = 0, z = 0;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double Dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 Cross(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// The unit vector along a; +z for the zero vector.
inline V3 Normalize(V3 a) {
  const double len = std::sqrt(Dot(a, a));
  return len > 0 ? a * (1.0 / len) : V3{0, 0, 1};
}
inline V3 ToV3(const Float3& f) { return {f.x, f.y, f.z}; }
inline Float3 ToFloat3(V3 v) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

}  // namespace dispex::render
