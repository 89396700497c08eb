// Normal queries against a plane made of quads, triangles and hexagons: t is exact, the face
// is the one under the query point, for every RayMode.
#include <gtest/gtest.h>

#include <random>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::MixedPlane;

class PlaneTest : public ::testing::TestWithParam<RayMode> {};

TEST_P(PlaneTest, AxisAlignedRaysGiveExactTAndTheFaceBelow) {
  constexpr int kM = 24;
  constexpr float kHeight = 0.25f;
  const trace_test::PlaneMesh plane = MixedPlane(kM, kHeight);
  TracerOptions options;
  options.ray_mode = GetParam();
  auto tracer = MakeEmbreeTracer(plane.mesh, options);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  EXPECT_EQ((*tracer)->stats().quads, 24u * 8);
  EXPECT_EQ((*tracer)->stats().triangles, 24u * 8 * 2 + 12u * 8 * 4);

  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coord(-0.99f, 0.99f), height(-2.0f, 2.0f);
  std::vector<Float3> origins, normals;
  std::vector<int> cells;
  const float cell = 2.0f / kM;
  while (origins.size() < 3000) {
    const float x = coord(rng), y = coord(rng);
    const float fx = (x + 1) / cell, fy = (y + 1) / cell;
    const int i = static_cast<int>(fx), j = static_cast<int>(fy);
    const float rx = fx - static_cast<float>(i), ry = fy - static_cast<float>(j);
    // Stay off cell borders and triangle diagonals; in triangle rows keep the lower-right
    // triangle (below the diagonal), which cell_face names.
    if (rx < 1e-3f || rx > 1 - 1e-3f || ry < 1e-3f || ry > 1 - 1e-3f) continue;
    if (j % 3 == 1 && !(ry < rx - 1e-3f)) continue;
    origins.push_back({x, y, height(rng)});
    normals.push_back({0, 0, origins.size() % 2 == 0 ? 1.0f : -1.0f});
    cells.push_back(j * kM + i);
  }
  const std::size_t n = origins.size();
  std::vector<float> t(n);
  std::vector<SculptPrimId> prim(n);
  std::vector<std::uint8_t> flags(n);
  TraceCounters counters;
  (*tracer)->TraceNormals(origins, normals, NormalQuery{3.0f, HitPolicy::kNearest},
                          NormalHits{t, prim, flags}, counters);
  EXPECT_EQ(counters.queries, n);
  EXPECT_EQ(counters.hits, n);
  EXPECT_EQ(counters.invalid, 0u);
  for (std::size_t k = 0; k < n; ++k) {
    // The line meets the plane where origin.z + t * n.z == height.
    const double expected = (static_cast<double>(kHeight) - origins[k].z) / normals[k].z;
    ASSERT_TRUE(flags[k] & HitFlags::kHit) << k;
    EXPECT_NEAR(t[k], expected, 1e-6 * std::max(1.0, std::fabs(expected))) << k;
    // Exact up to float rounding: within 2 ulps of the exact value (Embree's robust
    // intersection rounds a few times; measured at most 1.5 ulps).
    const float ulp = std::nextafter(std::fabs(static_cast<float>(expected)), 1e30f) -
                      std::fabs(static_cast<float>(expected));
    EXPECT_LE(std::fabs(t[k] - expected), 2.0 * ulp) << k;
    EXPECT_EQ(prim[k].value, plane.cell_face[static_cast<std::size_t>(cells[k])]) << k;
    EXPECT_EQ((flags[k] & HitFlags::kNegative) != 0, t[k] < 0) << k;
    // Faces point +z: a ray going up (+z) meets the back side.
    const float dir_z = (flags[k] & HitFlags::kNegative) ? -normals[k].z : normals[k].z;
    EXPECT_EQ((flags[k] & HitFlags::kBackFace) != 0, dir_z > 0) << k;
  }
}

TEST_P(PlaneTest, SlantedRaysMatchTheLinePlaneIntersection) {
  const trace_test::PlaneMesh plane = MixedPlane(12, -0.5f);
  TracerOptions options;
  options.ray_mode = GetParam();
  auto tracer = MakeEmbreeTracer(plane.mesh, options);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Float3> origins, normals;
  while (origins.size() < 2000) {
    const Float3 o{0.5f * u(rng), 0.5f * u(rng), u(rng)};
    trace_test::Vec3 n{0.3 * u(rng), 0.3 * u(rng), 1.0};
    n = (1 / trace_test::Length(n)) * n;
    origins.push_back(o);
    normals.push_back(trace_test::ToFloat3(n));
  }
  const std::size_t n = origins.size();
  std::vector<float> t(n);
  std::vector<std::uint8_t> flags(n);
  TraceCounters counters;
  (*tracer)->TraceNormals(origins, normals, NormalQuery{4.0f}, NormalHits{t, {}, flags}, counters);
  for (std::size_t k = 0; k < n; ++k) {
    const double expected = (-0.5 - static_cast<double>(origins[k].z)) / normals[k].z;
    ASSERT_TRUE(flags[k] & HitFlags::kHit) << k;
    EXPECT_NEAR(t[k], expected, 1e-6 * std::max(1.0, std::fabs(expected))) << k;
  }
}

INSTANTIATE_TEST_SUITE_P(AllModes, PlaneTest,
                         ::testing::Values(RayMode::kSingle, RayMode::kPacket4, RayMode::kPacket8,
                                           RayMode::kPacket16, RayMode::kStream),
                         [](const auto& param_info) {
                           return std::string(RayModeName(param_info.param));
                         });

}  // namespace
}  // namespace dispex
