#include "test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

namespace dispex::trace_test {

void AddFace(Mesh& mesh, std::initializer_list<std::int32_t> vertices) {
  mesh.face_indices.insert(mesh.face_indices.end(), vertices.begin(), vertices.end());
  mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
}

Mesh NewMesh(std::vector<Float3> positions) {
  Mesh mesh;
  mesh.positions.reserve(positions.size() + 1);
  mesh.positions.assign(positions.begin(), positions.end());
  mesh.face_offsets = {0};
  return mesh;
}

Mesh CubeSphere(int n, double radius, bool triangles) {
  Mesh mesh = NewMesh({});
  std::map<std::array<int, 3>, std::int32_t> index;
  std::vector<Float3> positions;
  auto vertex = [&](const std::array<int, 3>& lattice) {
    auto [it, inserted] = index.try_emplace(lattice, static_cast<std::int32_t>(positions.size()));
    if (inserted) {
      const Vec3 q{2.0 * lattice[0] / n - 1, 2.0 * lattice[1] / n - 1, 2.0 * lattice[2] / n - 1};
      positions.push_back(ToFloat3((radius / Length(q)) * q));
    }
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {-1, 1}) {
      // u x v = outward normal (side * e_axis).
      const int u = side > 0 ? (axis + 1) % 3 : (axis + 2) % 3;
      const int v = side > 0 ? (axis + 2) % 3 : (axis + 1) % 3;
      auto at = [&](int i, int j) {
        std::array<int, 3> lattice{};
        lattice[axis] = side > 0 ? n : 0;
        lattice[u] = i;
        lattice[v] = j;
        return vertex(lattice);
      };
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const std::int32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
          if (!triangles) {
            AddFace(mesh, {a, b, c, d});
          } else if ((i + j) % 2 == 0) {
            AddFace(mesh, {a, b, c});
            AddFace(mesh, {a, c, d});
          } else {
            AddFace(mesh, {a, b, d});
            AddFace(mesh, {b, c, d});
          }
        }
      }
    }
  }
  mesh.positions.reserve(positions.size() + 1);
  mesh.positions.assign(positions.begin(), positions.end());
  return mesh;
}

PlaneMesh MixedPlane(int m, float height) {
  PlaneMesh plane;
  plane.m = m;
  std::vector<Float3> positions;
  for (int j = 0; j <= m; ++j) {
    for (int i = 0; i <= m; ++i) {
      positions.push_back({-1.0f + 2.0f * static_cast<float>(i) / static_cast<float>(m),
                           -1.0f + 2.0f * static_cast<float>(j) / static_cast<float>(m), height});
    }
  }
  plane.mesh = NewMesh(positions);
  Mesh& mesh = plane.mesh;
  plane.cell_face.assign(static_cast<std::size_t>(m * m), -1);
  auto at = [&](int i, int j) { return static_cast<std::int32_t>(j * (m + 1) + i); };
  auto face_id = [&] { return static_cast<std::int32_t>(mesh.num_faces()); };
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < m; ++i) {
      const std::size_t cell = static_cast<std::size_t>(j * m + i);
      if (j % 3 == 0) {
        plane.cell_face[cell] = face_id();
        AddFace(mesh, {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      } else if (j % 3 == 1) {
        // Two triangles: the cell's face id is that of the lower-right one; tests avoid the
        // diagonal and pick by position.
        plane.cell_face[cell] = face_id();
        AddFace(mesh, {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        AddFace(mesh, {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      } else if (i % 2 == 0) {
        plane.cell_face[cell] = plane.cell_face[cell + 1] = face_id();
        AddFace(mesh, {at(i, j), at(i + 1, j), at(i + 2, j), at(i + 2, j + 1), at(i + 1, j + 1),
                       at(i, j + 1)});
      }
    }
  }
  return plane;
}

Mesh LoadObj(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<Float3> positions;
  Mesh mesh = NewMesh({});
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      Float3 p;
      s >> p.x >> p.y >> p.z;
      positions.push_back(p);
    } else if (tag == "f") {
      std::string corner;
      while (s >> corner) {
        long v = std::stol(corner.substr(0, corner.find('/')));
        v = v < 0 ? static_cast<long>(positions.size()) + v : v - 1;
        mesh.face_indices.push_back(static_cast<std::int32_t>(v));
      }
      mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
    }
  }
  mesh.positions.reserve(positions.size() + 1);
  mesh.positions.assign(positions.begin(), positions.end());
  mesh.source = path;
  return mesh;
}

std::vector<OracleTriangle> OracleTriangles(const Mesh& mesh) {
  std::vector<OracleTriangle> triangles;
  for (std::size_t face = 0; face < mesh.num_faces(); ++face) {
    const auto f = mesh.face(face);
    auto p = [&](std::size_t k) { return ToVec3(mesh.positions[static_cast<std::size_t>(f[k])]); };
    const auto id = static_cast<std::int32_t>(face);
    auto add = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
      const Vec3 normal = Cross(b - a, c - a);
      if (Dot(normal, normal) > 0) triangles.push_back({a, b, c, id});
    };
    if (f.size() == 4) {
      add(p(0), p(1), p(3));
      add(p(2), p(3), p(1));
    } else {
      for (std::size_t k = 1; k + 1 < f.size(); ++k) add(p(0), p(k), p(k + 1));
    }
  }
  return triangles;
}

std::optional<OracleHit> OracleRay(const std::vector<OracleTriangle>& triangles, const Vec3& origin,
                                   const Vec3& dir, double tmin, double tmax) {
  std::optional<OracleHit> best;
  for (const auto& [a, b, c, face] : triangles) {
    {
      // Plane intersection, then barycentrics of the hit point by signed areas.
      const Vec3 normal = Cross(b - a, c - a);
      const double area2 = Dot(normal, normal);
      const double denom = Dot(normal, dir);
      if (area2 == 0 || denom == 0) continue;
      const double t = Dot(normal, a - origin) / denom;
      if (t < tmin || t > tmax) continue;
      const Vec3 x = origin + t * dir;
      const double l0 = Dot(Cross(b - x, c - x), normal) / area2;
      const double l1 = Dot(Cross(c - x, a - x), normal) / area2;
      const double l2 = Dot(Cross(a - x, b - x), normal) / area2;
      const double lmin = std::min({l0, l1, l2});
      if (lmin < -1e-12) continue;
      if (!best || t < best->t) {
        best = OracleHit{t, face, (1 / std::sqrt(area2)) * normal, lmin};
      }
    }
  }
  return best;
}

namespace {

double SegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b, Vec3* closest) {
  const Vec3 ab = b - a;
  const double l2 = Dot(ab, ab);
  double t = l2 > 0 ? Dot(p - a, ab) / l2 : 0;
  t = std::min(1.0, std::max(0.0, t));
  *closest = a + t * ab;
  return Length(p - *closest);
}

}  // namespace

OraclePoint OracleClosest(const std::vector<OracleTriangle>& triangles, const Vec3& p) {
  // OracleTriangles lists a face's triangles consecutively: keep the best per face, then the
  // best and second best over faces.
  const double inf = std::numeric_limits<double>::infinity();
  OraclePoint result{inf, -1, {}, inf};
  auto commit = [&](std::int32_t face, double distance, const Vec3& point) {
    if (face < 0) return;
    if (distance < result.distance) {
      result.second_distance = result.distance;
      result.distance = distance;
      result.face = face;
      result.point = point;
    } else if (distance < result.second_distance) {
      result.second_distance = distance;
    }
  };
  std::int32_t face_now = -1;
  double face_best = inf;
  Vec3 face_point;
  for (const auto& [a, b, c, face] : triangles) {
    if (face != face_now) {
      commit(face_now, face_best, face_point);
      face_now = face;
      face_best = inf;
    }
    const Vec3 normal = Cross(b - a, c - a);
    const double area2 = Dot(normal, normal);
    const Vec3 q = p - (Dot(p - a, normal) / area2) * normal;  // projection on the plane
    const double l0 = Dot(Cross(b - q, c - q), normal);
    const double l1 = Dot(Cross(c - q, a - q), normal);
    const double l2 = Dot(Cross(a - q, b - q), normal);
    if (l0 >= 0 && l1 >= 0 && l2 >= 0 && Length(p - q) < face_best) {
      face_best = Length(p - q);
      face_point = q;
    }
    for (const auto& [s, e] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      Vec3 on_edge;
      const double d = SegmentDistance(p, s, e, &on_edge);
      if (d < face_best) {
        face_best = d;
        face_point = on_edge;
      }
    }
  }
  commit(face_now, face_best, face_point);
  return result;
}

}  // namespace dispex::trace_test
