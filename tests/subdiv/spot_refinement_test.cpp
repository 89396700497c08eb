// Refinement keeps the limit surface: Spot's level-2 cage (spot_quadrangulated.obj, made by
// an independent Catmull-Clark refinement) and Spot's control cage have the same limit
// surface. The face correspondence comes from the topology alone: the level-2 mesh that
// RefineUniform makes from the control cage is matched to the file's faces by growing a
// half-edge isomorphism from one seed face (checked against the file's convention that its
// first vertices are the cage's vertices), never by position.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <queue>
#include <string>
#include <utility>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "subdiv_test_util.h"

namespace dispex {
namespace {

std::string DataPath(const std::string& relative) {
  return (std::filesystem::path(DISPEX_TEST_DATA_DIR) / "meshes" / relative).string();
}

// Directed edge (a, b) -> (face, corner of a) for a mesh of quads.
using HalfEdges = std::map<std::pair<int, int>, std::pair<int, int>>;

HalfEdges BuildHalfEdges(const Mesh& m) {
  HalfEdges h;
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    const auto fv = m.face(f);
    for (int k = 0; k < 4; ++k) h[{fv[k], fv[(k + 1) % 4]}] = {static_cast<int>(f), k};
  }
  return h;
}

// Grows the isomorphism a -> b from the seed (face fa corner 0 <-> face fb corner rot).
// Returns false on any contradiction. face_map[fa] = {fb, rot}: corner k of fa is corner
// (k + rot) % 4 of fb.
bool GrowIsomorphism(const Mesh& a, const Mesh& b, const HalfEdges& ha, const HalfEdges& hb,
                     int seed_a, int seed_b, int seed_rot,
                     std::vector<std::pair<int, int>>& face_map, std::vector<int>& vertex_map) {
  face_map.assign(a.num_faces(), {-1, 0});
  vertex_map.assign(a.num_vertices(), -1);
  std::vector<int> vertex_back(b.num_vertices(), -1);
  std::vector<char> b_used(b.num_faces(), 0);
  std::queue<int> queue;
  auto assign = [&](int fa, int fb, int rot) {
    if (face_map[fa].first >= 0) return face_map[fa].first == fb && face_map[fa].second == rot;
    if (b_used[fb]) return false;
    const auto va = a.face(fa);
    const auto vb = b.face(fb);
    for (int k = 0; k < 4; ++k) {
      const int x = va[k], y = vb[(k + rot) % 4];
      if (vertex_map[x] >= 0 && vertex_map[x] != y) return false;
      if (vertex_back[y] >= 0 && vertex_back[y] != x) return false;
      vertex_map[x] = y;
      vertex_back[y] = x;
    }
    face_map[fa] = {fb, rot};
    b_used[fb] = 1;
    queue.push(fa);
    return true;
  };
  if (!assign(seed_a, seed_b, seed_rot)) return false;
  while (!queue.empty()) {
    const int fa = queue.front();
    queue.pop();
    const auto va = a.face(fa);
    const auto [fb, rot] = face_map[fa];
    const auto vb = b.face(fb);
    for (int k = 0; k < 4; ++k) {
      // The face across edge k of fa, and across the matching edge of fb.
      auto ia = ha.find({va[(k + 1) % 4], va[k]});
      auto ib = hb.find({vb[(k + rot + 1) % 4], vb[(k + rot) % 4]});
      if ((ia == ha.end()) != (ib == hb.end())) return false;
      if (ia == ha.end()) continue;
      const auto [ga, ca] = ia->second;  // ga's corner ca is vertex va[k+1]
      const auto [gb, cb] = ib->second;
      if (!assign(ga, gb, ((cb - ca) % 4 + 4) % 4)) return false;
    }
  }
  return true;
}

TEST(SpotRefinementTest, LevelTwoCageHasTheSameLimitSurface) {
  StatusOr<Mesh> cage = ReadMesh(DataPath("keenan_spot/spot_control_mesh.obj"));
  StatusOr<Mesh> quads = ReadMesh(DataPath("keenan_spot/spot_quadrangulated.obj"));
  ASSERT_TRUE(cage.ok() && quads.ok());
  StatusOr<LimitSurface> cage_surface = LimitSurface::Build(*cage);
  StatusOr<LimitSurface> quad_surface = LimitSurface::Build(*quads);
  ASSERT_TRUE(cage_surface.ok() && quad_surface.ok());
  RefineOptions options;
  options.face_charts = true;
  StatusOr<RefinedMesh> level2 = RefineUniform(*cage_surface, 2, options);
  ASSERT_TRUE(level2.ok());
  ASSERT_EQ(level2->mesh.num_faces(), quads->num_faces());
  ASSERT_EQ(level2->mesh.num_vertices(), quads->num_vertices());

  // The level-2 id of every cage vertex, from OpenSubdiv's refinement hierarchy.
  const subdiv_test::FarLimit far = subdiv_test::FarUniformLimit(*cage, 2);
  ASSERT_EQ(far.base_vertex_child.size(), cage->num_vertices());

  // Seed: the file's face 0 at its corner 0, a cage vertex (id < 188); try each face of the
  // refined mesh around that vertex, each alignment.
  const HalfEdges hq = BuildHalfEdges(*quads);
  const HalfEdges hm = BuildHalfEdges(level2->mesh);
  const int seed_vertex = quads->face(0)[0];
  ASSERT_LT(seed_vertex, static_cast<int>(cage->num_vertices()));
  const int target = far.base_vertex_child[seed_vertex];
  std::vector<std::pair<int, int>> face_map;
  std::vector<int> vertex_map;
  int matches = 0;
  std::vector<std::pair<int, int>> good_faces;
  std::vector<int> good_vertices;
  for (std::size_t f = 0; f < level2->mesh.num_faces(); ++f) {
    const auto fv = level2->mesh.face(f);
    for (int k = 0; k < 4; ++k) {
      if (fv[k] != target) continue;
      if (!GrowIsomorphism(*quads, level2->mesh, hq, hm, 0, static_cast<int>(f), k, face_map,
                           vertex_map)) {
        continue;
      }
      // The file's first vertices must be the cage's vertices.
      bool cage_vertices_match = true;
      for (std::size_t v = 0; v < cage->num_vertices(); ++v) {
        cage_vertices_match = cage_vertices_match && vertex_map[v] == far.base_vertex_child[v];
      }
      if (!cage_vertices_match) continue;
      ++matches;
      good_faces = face_map;
      good_vertices = vertex_map;
    }
  }
  ASSERT_EQ(matches, 1) << "the topology must determine the correspondence uniquely";
  for (const auto& [fb, rot] : good_faces) ASSERT_GE(fb, 0);

  // Sample both limit surfaces at the same points.
  const double diag = subdiv_test::BoundsDiagonal(*cage);
  LimitEvaluator eval_q(*quad_surface), eval_c(*cage_surface);
  const int n = 4;
  std::vector<float> pq(3 * n * n), nq(3 * n * n);
  double max_err = 0, max_angle = 0;
  for (std::size_t q = 0; q < quads->num_faces(); ++q) {
    ASSERT_TRUE(eval_q.EvaluateGrid(PtexFaceId(static_cast<int>(q)), n, n, pq, nq).ok());
    const auto [m, rot] = good_faces[q];
    const float* chart = &level2->face_uvs[8 * static_cast<std::size_t>(m)];
    float c[4][2];  // cage (u,v) of the file face's corners 0..3
    for (int k = 0; k < 4; ++k) {
      c[k][0] = chart[2 * ((k + rot) % 4)];
      c[k][1] = chart[2 * ((k + rot) % 4) + 1];
    }
    std::vector<float> uv;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const float s = (i + 0.5f) / n, t = (j + 0.5f) / n;
        for (int d = 0; d < 2; ++d) {
          uv.push_back((1 - s) * (1 - t) * c[0][d] + s * (1 - t) * c[1][d] + s * t * c[2][d] +
                       (1 - s) * t * c[3][d]);
        }
      }
    }
    std::vector<float> pc(3 * n * n), nc(3 * n * n);
    ASSERT_TRUE(eval_c.EvaluatePoints(level2->face_ptex[m], uv, pc, nc).ok());
    for (int k = 0; k < n * n; ++k) {
      double e2 = 0;
      for (int d = 0; d < 3; ++d)
        e2 += (pq[3 * k + d] - pc[3 * k + d]) * (pq[3 * k + d] - pc[3 * k + d]);
      max_err = std::max(max_err, std::sqrt(e2) / diag);
      const double ref[3] = {nc[3 * k], nc[3 * k + 1], nc[3 * k + 2]};
      max_angle = std::max(max_angle, subdiv_test::AngleBetween(&nq[3 * k], ref));
    }
  }
  EXPECT_LT(max_err, 1e-4);
  EXPECT_LT(max_angle, 5e-3);
  std::printf(
      "  spot level 2 vs cage: %zu faces, max distance %.2e of the diagonal, normals "
      "%.2e rad\n",
      quads->num_faces(), max_err, max_angle);
}

}  // namespace
}  // namespace dispex
