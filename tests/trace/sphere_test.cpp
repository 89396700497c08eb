// Normal queries against a fine quad cube-sphere and a triangulated one, compared with a
// brute-force double-precision intersection of the line with every face's triangles.
#include <gtest/gtest.h>

#include <random>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::Vec3;

struct SphereCase {
  const char* name;
  bool triangles;
  RayMode mode;
  BuildQuality quality = BuildQuality::kLow;
};

// Names the case in test output (instead of its bytes).
void PrintTo(const SphereCase& c, std::ostream* os) {
  *os << c.name;
}

class SphereTest : public ::testing::TestWithParam<SphereCase> {};

TEST_P(SphereTest, NearestHitMatchesBruteForce) {
  constexpr double kRadius = 1.0;
  const Mesh sphere = trace_test::CubeSphere(12, kRadius, GetParam().triangles);
  const auto oracle = trace_test::OracleTriangles(sphere);
  TracerOptions options;
  options.ray_mode = GetParam().mode;
  options.quality = GetParam().quality;
  auto tracer = MakeEmbreeTracer(sphere, options);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();

  // Base points on spheres of radius 0.6 and 1.3 with radial and tilted normals: the line
  // crosses the surface once or twice within the search distance.
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0, 1);
  constexpr float kDistance = 0.8f;
  std::vector<Float3> origins, normals;
  for (int k = 0; k < 1500; ++k) {
    Vec3 dir{g(rng), g(rng), g(rng)};
    dir = (1 / trace_test::Length(dir)) * dir;
    const double r = k % 2 == 0 ? 0.6 : 1.3;
    Vec3 n = dir + Vec3{0.3 * g(rng), 0.3 * g(rng), 0.3 * g(rng)};
    n = (1 / trace_test::Length(n)) * n;
    origins.push_back(trace_test::ToFloat3(r * dir));
    normals.push_back(trace_test::ToFloat3(n));
  }
  const std::size_t n = origins.size();
  std::vector<float> t(n);
  std::vector<SculptPrimId> prim(n);
  std::vector<std::uint8_t> flags(n);
  TraceCounters counters;
  (*tracer)->TraceNormals(origins, normals, NormalQuery{kDistance}, NormalHits{t, prim, flags},
                          counters);

  int hits = 0, checked_faces = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 o = trace_test::ToVec3(origins[k]);
    const Vec3 d = trace_test::ToVec3(normals[k]);
    const auto plus = trace_test::OracleRay(oracle, o, d, 0, kDistance);
    const auto minus = trace_test::OracleRay(oracle, o, -1.0 * d, 0, kDistance);
    // Skip lines that pass within float rounding of the search distance's end.
    if ((plus && plus->t > kDistance - 1e-5) || (minus && minus->t > kDistance - 1e-5)) continue;
    const bool take_minus = minus && (!plus || minus->t < plus->t);
    const auto& ref = take_minus ? minus : plus;
    ASSERT_EQ(ref.has_value(), (flags[k] & HitFlags::kHit) != 0) << k;
    if (!ref) {
      EXPECT_TRUE(std::isnan(t[k]));
      EXPECT_FALSE(prim[k].valid());
      continue;
    }
    ++hits;
    const double expected = take_minus ? -ref->t : ref->t;
    // 1e-6 relative to |t| (and to the unit radius, for t near 0).
    EXPECT_NEAR(t[k], expected, 1e-6 * std::max(std::fabs(expected), kRadius)) << k;
    EXPECT_EQ((flags[k] & HitFlags::kNegative) != 0, take_minus) << k;
    const Vec3 ray_dir = take_minus ? -1.0 * d : d;
    EXPECT_EQ((flags[k] & HitFlags::kBackFace) != 0, trace_test::Dot(ray_dir, ref->normal) > 0)
        << k;
    if (ref->min_barycentric > 1e-4) {  // clear of any edge: the face is unambiguous
      EXPECT_EQ(prim[k].value, ref->face) << k;
      ++checked_faces;
    }
  }
  EXPECT_GT(hits, 1000);
  EXPECT_GT(checked_faces, 900);
  EXPECT_EQ(counters.hits, static_cast<std::uint64_t>(std::count_if(
                               flags.begin(), flags.end(),
                               [](std::uint8_t f) { return (f & HitFlags::kHit) != 0; })));
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, SphereTest,
    ::testing::Values(SphereCase{"quads_packet8", false, RayMode::kPacket8},
                      SphereCase{"triangles_packet8", true, RayMode::kPacket8},
                      SphereCase{"quads_single", false, RayMode::kSingle},
                      SphereCase{"triangles_stream", true, RayMode::kStream},
                      SphereCase{"quads_packet16", false, RayMode::kPacket16},
                      SphereCase{"quads_medium", false, RayMode::kPacket8, BuildQuality::kMedium},
                      SphereCase{"triangles_high", true, RayMode::kPacket4, BuildQuality::kHigh}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace dispex
