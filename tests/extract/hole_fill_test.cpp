#include "extract/hole_fill.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace dispex {
namespace {

using namespace extract;

TEST(PullPush, NothingToFillAndNothingValid) {
  PullPushScratch scratch;
  std::vector<float> v = {1, 2, 3, 4};
  std::vector<std::uint8_t> all = {1, 1, 1, 1}, none = {0, 0, 0, 0};
  EXPECT_EQ(FillHolesPullPush(v.data(), all.data(), 2, 2, scratch), 0);
  EXPECT_EQ(FillHolesPullPush(v.data(), none.data(), 2, 2, scratch), -1);
  EXPECT_EQ(v, (std::vector<float>{1, 2, 3, 4}));
}

TEST(PullPush, SingleValidSampleSpreadsEverywhere) {
  PullPushScratch scratch;
  for (auto [nx, ny] : {std::pair{8, 8}, {16, 4}, {1, 32}, {5, 7}}) {
    std::vector<float> v(static_cast<std::size_t>(nx * ny), 99.0f);
    std::vector<std::uint8_t> valid(v.size(), 0);
    std::size_t k = v.size() / 3;
    v[k] = -0.25f;
    valid[k] = 1;
    EXPECT_EQ(FillHolesPullPush(v.data(), valid.data(), nx, ny, scratch),
              static_cast<int>(v.size() - 1));
    for (float x : v) EXPECT_FLOAT_EQ(x, -0.25f) << nx << "x" << ny;
  }
}

TEST(PullPush, KeepsValidSamplesAndStaysWithinTheirRange) {
  PullPushScratch scratch;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> value(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    int nx = 1 << (trial % 7), ny = 1 << ((trial / 7) % 7);
    std::vector<float> v(static_cast<std::size_t>(nx * ny));
    std::vector<std::uint8_t> valid(v.size());
    float lo = 1e9f, hi = -1e9f;
    for (std::size_t i = 0; i < v.size(); ++i) {
      valid[i] = (rng() % 3) != 0;
      v[i] = value(rng);
      if (valid[i]) lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
    }
    if (std::count(valid.begin(), valid.end(), 1) == 0) continue;
    std::vector<float> before = v;
    FillHolesPullPush(v.data(), valid.data(), nx, ny, scratch);
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (valid[i]) {
        EXPECT_EQ(v[i], before[i]);
      } else {
        EXPECT_GE(v[i], lo - 1e-6f);
        EXPECT_LE(v[i], hi + 1e-6f);
      }
    }
  }
}

TEST(PullPush, SmallHoleInASmoothFieldIsCloseToTheField) {
  PullPushScratch scratch;
  const int n = 64;
  std::vector<float> v(n * n), truth(n * n);
  std::vector<std::uint8_t> valid(n * n, 1);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      truth[y * n + x] = 0.01f * std::sin(0.1f * x) + 0.002f * y;
      v[y * n + x] = truth[y * n + x];
      if (std::hypot(x - 30, y - 20) < 4) valid[y * n + x] = 0, v[y * n + x] = 0;
    }
  }
  EXPECT_GT(FillHolesPullPush(v.data(), valid.data(), n, n, scratch), 40);
  for (int i = 0; i < n * n; ++i) EXPECT_NEAR(v[i], truth[i], 0.004f);
}

TEST(EdgeMeans, AveragesEachEdge) {
  // 3x2 grid: rows v=0: 1 2 3, v=1: 4 5 6.
  std::vector<float> v = {1, 2, 3, 4, 5, 6};
  EdgeMeans e = ComputeEdgeMeans(v.data(), 3, 2);
  EXPECT_FLOAT_EQ(e.mean[0], 2);    // bottom
  EXPECT_FLOAT_EQ(e.mean[1], 4.5);  // right: 3, 6
  EXPECT_FLOAT_EQ(e.mean[2], 5);    // top
  EXPECT_FLOAT_EQ(e.mean[3], 2.5);  // left: 1, 4
}

TEST(FillEmptyFaces, FillsChainsInRoundsAndReportsIslands) {
  // Faces 0-1-2-3 in a row (edge 1 of each touches edge 3 of the next); face 4 isolated.
  // Face 0 has data; 1 and 2 missed entirely; 3 has data; 4 missed.
  std::vector<std::int32_t> adj = {-1, 1,  -1, -1,  //
                                   -1, 2,  -1, 0,   //
                                   -1, 3,  -1, 1,   //
                                   -1, -1, -1, 2,   //
                                   -1, -1, -1, -1};
  std::vector<std::int8_t> edges = {0, 3, 0, 0, 0, 3, 0, 1, 0, 3, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0};
  std::vector<std::uint8_t> filled = {1, 0, 0, 1, 0};
  std::vector<EdgeMeans> means(5);
  means[0].mean[1] = 2.0f;  // face 0's right edge
  means[3].mean[3] = 4.0f;  // face 3's left edge
  std::vector<PtexFaceInfo> faces(5);
  for (std::size_t i = 0; i < adj.size(); ++i) {
    faces[i / 4].adjfaces[i % 4] = adj[i];
    faces[i / 4].adjedges[i % 4] = static_cast<std::uint8_t>(edges[i]);
  }
  CrossFaceFill fill = FillEmptyFaces(filled, means, faces);
  ASSERT_EQ(fill.faces.size(), 2u);
  EXPECT_EQ(fill.faces[0], 1);
  EXPECT_FLOAT_EQ(fill.values[0], 2.0f);
  EXPECT_EQ(fill.faces[1], 2);
  EXPECT_FLOAT_EQ(fill.values[1], 4.0f);
  EXPECT_EQ(fill.unreachable, 1u);
  EXPECT_EQ(filled, (std::vector<std::uint8_t>{1, 1, 1, 1, 0}));
}

}  // namespace
}  // namespace dispex
