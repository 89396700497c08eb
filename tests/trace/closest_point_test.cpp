// Closest-point queries against brute force on small meshes (quads, triangles, n-gons), plus
// the max-distance cut-off and malformed points.
#include <gtest/gtest.h>

#include <random>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::Vec3;

void ExpectMatchesBruteForce(const Mesh& mesh, const std::vector<Float3>& points) {
  const auto oracle = trace_test::OracleTriangles(mesh);
  auto tracer = MakeEmbreeTracer(mesh);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  std::vector<ClosestPoint> out(points.size());
  TraceCounters counters;
  (*tracer)->ClosestPoints(points, std::numeric_limits<float>::infinity(), out, counters);
  EXPECT_EQ(counters.queries, points.size());
  EXPECT_EQ(counters.hits, points.size());
  EXPECT_EQ(counters.rays_cast, 0u);
  int unique = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Vec3 p = trace_test::ToVec3(points[k]);
    const trace_test::OraclePoint ref = trace_test::OracleClosest(oracle, p);
    ASSERT_TRUE(out[k].found()) << k;
    const double tolerance = 1e-6 * std::max(ref.distance, 1.0);
    EXPECT_NEAR(out[k].distance, ref.distance, tolerance) << k;
    // The reported point is where the distance is measured from.
    EXPECT_NEAR(trace_test::Length(trace_test::ToVec3(out[k].point) - p), ref.distance,
                2 * tolerance)
        << k;
    if (ref.second_distance > ref.distance + 1e-6) {
      EXPECT_EQ(out[k].prim.value, ref.face) << k;
      EXPECT_NEAR(out[k].point.x, ref.point.x, tolerance) << k;
      EXPECT_NEAR(out[k].point.y, ref.point.y, tolerance) << k;
      EXPECT_NEAR(out[k].point.z, ref.point.z, tolerance) << k;
      ++unique;
    }
  }
  // Many closest points are vertices or edges shared by several faces; enough are not.
  EXPECT_GT(unique, static_cast<int>(points.size()) / 4);
}

std::vector<Float3> RandomPoints(std::mt19937& rng, int count, double spread) {
  std::uniform_real_distribution<double> u(-spread, spread);
  std::vector<Float3> points;
  for (int k = 0; k < count; ++k) points.push_back(trace_test::ToFloat3({u(rng), u(rng), u(rng)}));
  return points;
}

TEST(ClosestPointTest, QuadSphere) {
  const Mesh mesh = trace_test::CubeSphere(6, 1.0, false);
  std::mt19937 rng(1);
  std::vector<Float3> points = RandomPoints(rng, 600, 1.6);
  // Points on the vertices themselves: distance 0.
  for (std::size_t v = 0; v < mesh.num_vertices(); v += 7) points.push_back(mesh.positions[v]);
  ExpectMatchesBruteForce(mesh, points);
}

TEST(ClosestPointTest, TriangleSphere) {
  const Mesh mesh = trace_test::CubeSphere(6, 1.0, true);
  std::mt19937 rng(2);
  ExpectMatchesBruteForce(mesh, RandomPoints(rng, 600, 1.6));
}

TEST(ClosestPointTest, MixedPlaneWithDegenerateFanTriangles) {
  const trace_test::PlaneMesh plane = trace_test::MixedPlane(6, 0.1f);
  std::mt19937 rng(3);
  ExpectMatchesBruteForce(plane.mesh, RandomPoints(rng, 600, 1.5));
}

TEST(ClosestPointTest, RealMixedMesh) {
  const Mesh blub =
      trace_test::LoadObj(DISPEX_TEST_DATA_DIR "/meshes/keenan_blub/blub_control_mesh.obj");
  std::mt19937 rng(4);
  ExpectMatchesBruteForce(blub, RandomPoints(rng, 600, 1.5));
}

TEST(ClosestPointTest, MaxDistanceAndMalformedPoints) {
  const Mesh mesh = trace_test::CubeSphere(4, 1.0, false);
  auto tracer = MakeEmbreeTracer(mesh);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Float3> points{{0, 0, 1.5f}, {0, 0, 1.2f}, {nan, 0, 0}};
  std::vector<ClosestPoint> out(points.size());
  TraceCounters counters;
  (*tracer)->ClosestPoints(points, 0.3f, out, counters);
  EXPECT_FALSE(out[0].found());  // 0.5 away
  EXPECT_EQ(out[0].distance, std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(out[0].point.x));
  ASSERT_TRUE(out[1].found());  // the cube-sphere's top vertex is at (0, 0, 1)
  EXPECT_FLOAT_EQ(out[1].distance, 0.2f);
  EXPECT_FLOAT_EQ(out[1].point.z, 1.0f);
  EXPECT_FALSE(out[2].found());
  EXPECT_EQ(counters.invalid, 1u);
  EXPECT_EQ(counters.hits, 1u);
}

}  // namespace
}  // namespace dispex
