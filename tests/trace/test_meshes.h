// Meshes and independent reference answers for the trace tests: analytic shapes built in
// code, a minimal OBJ loader for the real meshes in tests/data (the mesh module's reader is
// not a dependency of dispex::trace), and brute-force double-precision oracles that share no
// code with the library.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "dispex/mesh.h"

namespace dispex::trace_test {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};
inline Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator*(double s, const Vec3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
inline double Dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double Length(const Vec3& a) {
  return std::sqrt(Dot(a, a));
}
inline Vec3 ToVec3(const Float3& p) {
  return {p.x, p.y, p.z};
}
inline Float3 ToFloat3(const Vec3& p) {
  return {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
}

// Appends a face to a mesh under construction (face_offsets must start as {0}).
void AddFace(Mesh& mesh, std::initializer_list<std::int32_t> vertices);
// An empty mesh ready for AddFace, positions reserved with the readers' +1 padding.
Mesh NewMesh(std::vector<Float3> positions);

// A cube-sphere: each cube face an n x n grid, welded along the cube's edges, projected on
// the sphere of `radius`; faces counter-clockwise seen from outside. With `triangles`, each
// quad is split into two triangles along alternating diagonals.
Mesh CubeSphere(int n, double radius, bool triangles);

// The plane z = height over [-1, 1]^2 as an m x m grid (m a multiple of 6): rows j % 3 == 0
// are quads, rows j % 3 == 1 pairs of triangles, rows j % 3 == 2 hexagons spanning two cells
// (fanned by the tracer, including one degenerate triangle). Faces face +z (counter-
// clockwise from above). cell_face[j * m + i] is the face covering cell (i, j).
struct PlaneMesh {
  Mesh mesh;
  int m = 0;
  std::vector<std::int32_t> cell_face;
};
PlaneMesh MixedPlane(int m, float height);

// Minimal OBJ loader for test data: `v` and `f` lines (v, v/vt, v/vt/vn, v//vn; negative
// indices). Aborts the test on malformed input.
Mesh LoadObj(const std::string& path);

// The triangles the faces are ray-traced as: quads as (v0,v1,v3), (v2,v3,v1), as Embree
// documents; other faces fanned from v0. Zero-area triangles are dropped.
struct OracleTriangle {
  Vec3 a, b, c;
  std::int32_t face = -1;
};
std::vector<OracleTriangle> OracleTriangles(const Mesh& mesh);

// Brute-force ray casting in double precision: the smallest t in [tmin, tmax] where
// origin + t dir meets a face, with the face and the triangle's right-hand normal. Also
// reports the smallest barycentric coordinate of the hit (how close to an edge it is).
struct OracleHit {
  double t = 0;
  std::int32_t face = -1;
  Vec3 normal;
  double min_barycentric = 0;
};
std::optional<OracleHit> OracleRay(const std::vector<OracleTriangle>& triangles, const Vec3& origin,
                                   const Vec3& dir, double tmin, double tmax);

// Brute-force closest point: distance to every face's triangles by projection onto the plane
// (inside test with barycentrics) or the nearest edge. Also reports the second-best distance
// over other faces (to tell unique answers from ties).
struct OraclePoint {
  double distance = 0;
  std::int32_t face = -1;
  Vec3 point;
  double second_distance = 0;
};
OraclePoint OracleClosest(const std::vector<OracleTriangle>& triangles, const Vec3& p);

}  // namespace dispex::trace_test
