// ComputeBounds, BoundingBox::diagonal and MedianEdgeLength against values worked out by hand
// or by a full sort done here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "dispex/mesh.h"

namespace dispex {
namespace {

TEST(MeshMeasure, BoundsAndDiagonal) {
  Mesh mesh;
  mesh.positions = {{1, 2, 3}, {-4, 5, 0.5f}, {2, -6, 7}};
  mesh.face_offsets = {0, 3};
  mesh.face_indices = {0, 1, 2};
  const BoundingBox box = ComputeBounds(mesh);
  EXPECT_EQ(box.min.x, -4);
  EXPECT_EQ(box.min.y, -6);
  EXPECT_EQ(box.min.z, 0.5f);
  EXPECT_EQ(box.max.x, 2);
  EXPECT_EQ(box.max.y, 5);
  EXPECT_EQ(box.max.z, 7);
  EXPECT_FLOAT_EQ(box.diagonal(), std::sqrt(36.0f + 121.0f + 42.25f));
  EXPECT_EQ(BoundingBox{}.diagonal(), 0);
  EXPECT_EQ(ComputeBounds(Mesh{}).diagonal(), 0);
  EXPECT_EQ(MedianEdgeLength(Mesh{}), 0);
}

TEST(MeshMeasure, MedianOddAndEven) {
  Mesh tri;  // sides 3, 4, 5
  tri.positions = {{0, 0, 0}, {3, 0, 0}, {3, 4, 0}};
  tri.face_offsets = {0, 3};
  tri.face_indices = {0, 1, 2};
  EXPECT_DOUBLE_EQ(MedianEdgeLength(tri), 4.0);
  Mesh quad;  // a 1 x 3 rectangle: sides 1, 3, 1, 3 -> (1 + 3) / 2
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 3, 0}, {0, 3, 0}};
  quad.face_offsets = {0, 4};
  quad.face_indices = {0, 1, 2, 3};
  EXPECT_DOUBLE_EQ(MedianEdgeLength(quad), 2.0);
}

// More than 2^22 face sides: the median is taken over a deterministic sample. It must stay
// between the 45th and 55th percentiles of the exact distribution (computed here by a sort),
// even though quads alternate short and long sides.
TEST(MeshMeasure, SampledMedianOfAHugeGrid) {
  const int n = 1100;  // 1099^2 quads, 4.8M sides
  Mesh mesh;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      // Unequal spacing: x steps grow along the row, y steps are 2.5 times larger.
      mesh.positions.push_back(
          {static_cast<float>(i + 1e-4 * i * i), static_cast<float>(2.5 * j + 3e-4 * j * j), 0});
    }
  }
  mesh.face_offsets.push_back(0);
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i;
      for (int v : {a, a + 1, a + n + 1, a + n}) mesh.face_indices.push_back(v);
      mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
    }
  }
  std::vector<double> all;
  all.reserve(mesh.face_indices.size());
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    for (std::size_t k = 0; k < 4; ++k) {
      const Float3& a = mesh.positions[face[k]];
      const Float3& b = mesh.positions[face[(k + 1) % 4]];
      all.push_back(std::hypot(double{a.x} - b.x, double{a.y} - b.y, double{a.z} - b.z));
    }
  }
  std::sort(all.begin(), all.end());
  const double median = MedianEdgeLength(mesh);
  EXPECT_GE(median, all[all.size() * 45 / 100]);
  EXPECT_LE(median, all[all.size() * 55 / 100]);
  EXPECT_EQ(MedianEdgeLength(mesh), median);  // deterministic
}

}  // namespace
}  // namespace dispex
