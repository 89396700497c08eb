// ValidateMesh and RequireClean on meshes built in code, with counts worked out by hand.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

Mesh MakeMesh(std::vector<Float3> positions, const std::vector<std::vector<int>>& faces) {
  Mesh mesh;
  mesh.source = "built.obj";
  mesh.positions = std::move(positions);
  mesh.face_offsets.push_back(0);
  for (const auto& face : faces) {
    for (int v : face) mesh.face_indices.push_back(v);
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
  }
  return mesh;
}

const std::vector<Float3> kCubePositions = {{-1, -1, 1}, {1, -1, 1}, {-1, 1, 1},   {1, 1, 1},
                                            {-1, 1, -1}, {1, 1, -1}, {-1, -1, -1}, {1, -1, -1}};
const std::vector<std::vector<int>> kCubeFaces = {{0, 1, 3, 2}, {2, 3, 5, 4}, {4, 5, 7, 6},
                                                  {6, 7, 1, 0}, {1, 7, 5, 3}, {6, 0, 2, 4}};

TEST(MeshValidation, ClosedCubeIsClean) {
  const Mesh cube = MakeMesh(kCubePositions, kCubeFaces);
  const MeshValidation v = ValidateMesh(cube);
  EXPECT_TRUE(v.clean());
  EXPECT_EQ(v.boundary_edges, 0u);
  EXPECT_EQ(v.non_manifold_edges, 0u);
  EXPECT_EQ(v.inconsistent_edges, 0u);
  EXPECT_TRUE(v.warnings.empty());
  EXPECT_TRUE(RequireClean(cube, v).ok());
}

TEST(MeshValidation, OpenBoxHasBoundaryOnly) {
  auto faces = kCubeFaces;
  faces.pop_back();
  const MeshValidation v = ValidateMesh(MakeMesh(kCubePositions, faces));
  EXPECT_EQ(v.boundary_edges, 4u);
  EXPECT_TRUE(v.clean());  // open meshes are fine
  EXPECT_TRUE(v.warnings.empty());
}

TEST(MeshValidation, FlippedFaceIsInconsistentOnItsFourEdges) {
  auto faces = kCubeFaces;
  faces[2] = {6, 7, 5, 4};  // reversed
  const Mesh mesh = MakeMesh(kCubePositions, faces);
  const MeshValidation v = ValidateMesh(mesh);
  EXPECT_EQ(v.inconsistent_edges, 4u);
  EXPECT_EQ(v.boundary_edges, 0u);
  EXPECT_FALSE(v.clean());
  ASSERT_EQ(v.warnings.size(), 1u);
  // The first offending edge by vertex ids is 4-5 (faces 1 and 2).
  EXPECT_EQ(v.warnings[0],
            "4 inconsistently wound edges (both faces run the same way) (first: edge 4-5, faces "
            "1, 2)");
  const Status strict = RequireClean(mesh, v);
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.message(), "built.obj: mesh is not clean: " + v.warnings[0]);
}

TEST(MeshValidation, NonManifoldDegenerateUnreferenced) {
  // Three quads around the edge 0-1 (a "book"), a degenerate triangle, an unused vertex 9.
  const std::vector<Float3> p = {{0, 0, 0}, {0, 0, 1},  {1, 0, 1},  {1, 0, 0}, {0, 1, 1},
                                 {0, 1, 0}, {-1, 0, 1}, {-1, 0, 0}, {5, 5, 5}, {9, 9, 9}};
  const Mesh mesh = MakeMesh(p, {{0, 1, 2, 3}, {1, 0, 5, 4}, {0, 1, 6, 7}, {8, 2, 8}});
  const MeshValidation v = ValidateMesh(mesh);
  EXPECT_EQ(v.non_manifold_edges, 1u);
  EXPECT_EQ(v.degenerate_faces, 1u);
  EXPECT_EQ(v.unreferenced_vertices, 1u);
  // Edge 0-1 is used 3 times; the other quad sides once each (9); the triangle 8-2-8 has the
  // sides 8-2 and 2-8: one edge used twice, in opposite directions (consistent).
  EXPECT_EQ(v.boundary_edges, 9u);
  EXPECT_EQ(v.inconsistent_edges, 0u);
  ASSERT_EQ(v.warnings.size(), 3u);
  EXPECT_EQ(v.warnings[0], "1 unreferenced vertices (first: vertex 9)");
  EXPECT_EQ(v.warnings[1],
            "1 degenerate faces with a repeated vertex (first: face 3: vertices 8 2 8)");
  EXPECT_EQ(v.warnings[2],
            "1 non-manifold edges used by more than two faces (first: edge 0-1, faces 0, 1, 2)");
  const Status strict = RequireClean(mesh, v);
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.message().find('\n'), std::string::npos);
}

// A regular grid: (n-1)^2 quads, 4(n-1) boundary edges, nothing else; and the same answer for
// one thread and many.
TEST(MeshValidation, GridCountsAndThreadIndependence) {
  const int n = 400;
  std::vector<Float3> p;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) p.push_back({static_cast<float>(i), static_cast<float>(j), 0});
  }
  std::vector<std::vector<int>> faces;
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i;
      faces.push_back({a, a + 1, a + n + 1, a + n});
    }
  }
  faces[1234] = {faces[1234][0], faces[1234][3], faces[1234][2], faces[1234][1]};  // flip one
  const Mesh mesh = MakeMesh(p, faces);
  MeshValidation one;
  tbb::task_arena(1).execute([&] { one = ValidateMesh(mesh); });
  const MeshValidation many = ValidateMesh(mesh);
  EXPECT_EQ(one.boundary_edges, 4u * (n - 1));
  EXPECT_EQ(one.inconsistent_edges, 4u);
  EXPECT_EQ(one.warnings, many.warnings);
  EXPECT_EQ(one.boundary_edges, many.boundary_edges);
  EXPECT_EQ(one.inconsistent_edges, many.inconsistent_edges);
}

}  // namespace
}  // namespace dispex
