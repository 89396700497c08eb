// The sculpt's half-edge adjacency (subdiv/quad_adjacency.h) on small meshes.
#include "subdiv/quad_adjacency.h"

#include <gtest/gtest.h>

#include <vector>

namespace dispex::subdiv {
namespace {

Mesh Quads(int num_vertices, const std::vector<std::int32_t>& corners) {
  Mesh mesh;
  mesh.source = "quads.obj";
  mesh.positions.resize(num_vertices);
  mesh.face_indices = corners;
  for (std::size_t f = 0; f <= corners.size() / 4; ++f) {
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(4 * f));
  }
  return mesh;
}

// A 2 x 2 grid of quads: vertices 0..8 row by row.
const std::vector<std::int32_t> kGrid = {0, 1, 4, 3, 1, 2, 5, 4, 3, 4, 7, 6, 4, 5, 8, 7};

TEST(QuadAdjacency, GridOfFourQuads) {
  auto adjacency = BuildQuadAdjacency(Quads(9, kGrid));
  ASSERT_TRUE(adjacency.ok()) << adjacency.status().message();
  // Quad 0's edge 1 (1 -> 4) is quad 1's edge 3 (4 -> 1); its edge 2 (4 -> 3) quad 2's 0.
  EXPECT_EQ(adjacency->opposite[1], 4u * 1 + 3);
  EXPECT_EQ(adjacency->opposite[4 * 1 + 3], 1u);
  EXPECT_EQ(adjacency->opposite[2], 4u * 2 + 0);
  EXPECT_EQ(adjacency->opposite[0], kNoHalfEdge);
  EXPECT_EQ(adjacency->valence, (std::vector<std::uint16_t>{1, 2, 1, 2, 4, 2, 1, 2, 1}));
  EXPECT_EQ(adjacency->boundary, (std::vector<std::uint8_t>{1, 1, 1, 1, 0, 1, 1, 1, 1}));
  EXPECT_EQ(adjacency->first_half_edge[4], 2u);  // quad 0's corner 2
  std::uint32_t count = 0;
  EXPECT_EQ(QuadComponents(*adjacency, count), (std::vector<std::uint32_t>{0, 0, 0, 0}));
  EXPECT_EQ(count, 1u);
}

TEST(QuadAdjacency, ComponentsNumberedByTheirLowestQuad) {
  // Quads 0 and 2 share an edge; quad 1 is apart.
  auto adjacency = BuildQuadAdjacency(Quads(10, {0, 1, 2, 3, 6, 7, 8, 9, 1, 4, 5, 2}));
  ASSERT_TRUE(adjacency.ok());
  std::uint32_t count = 0;
  EXPECT_EQ(QuadComponents(*adjacency, count), (std::vector<std::uint32_t>{0, 1, 0}));
  EXPECT_EQ(count, 2u);
}

TEST(QuadAdjacency, Errors) {
  std::vector<std::int32_t> flipped = kGrid;
  std::swap(flipped[4 * 3 + 1], flipped[4 * 3 + 3]);  // quad 3 wound the other way
  EXPECT_EQ(BuildQuadAdjacency(Quads(9, flipped)).status().message(),
            "quads.obj: faces 1 and 3 both run edge 5-4 from 5 to 4 (their windings disagree)");
  std::vector<std::int32_t> fin = kGrid;
  fin.insert(fin.end(), {4, 1, 9, 10});  // a third quad on edge 1-4
  EXPECT_EQ(BuildQuadAdjacency(Quads(11, fin)).status().message(),
            "quads.obj: edge 1-4 has more than two faces (0, 1, 4)");
  EXPECT_EQ(BuildQuadAdjacency(Quads(10, kGrid)).status().message(),
            "quads.obj: vertex 9 is used by no face");
  EXPECT_EQ(BuildQuadAdjacency(Quads(4, {0, 1, 2, 1})).status().message(),
            "quads.obj: face 0 uses vertex 1 twice");
}

}  // namespace
}  // namespace dispex::subdiv
