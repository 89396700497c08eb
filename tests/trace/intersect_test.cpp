// Tracer::Intersect, the generic batch used to render the tessellated surface: the ray's
// [tnear, tfar] window, unit outward normals, malformed rays, against brute force.
#include <gtest/gtest.h>

#include <random>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::Vec3;

TEST(IntersectTest, WindowSelectsWhichSheetIsHit) {
  // Sheets at z = 0 and z = 1 (quads facing +z).
  Mesh mesh = trace_test::NewMesh({{-1, -1, 0},
                                   {1, -1, 0},
                                   {1, 1, 0},
                                   {-1, 1, 0},
                                   {-1, -1, 1},
                                   {1, -1, 1},
                                   {1, 1, 1},
                                   {-1, 1, 1}});
  trace_test::AddFace(mesh, {0, 1, 2, 3});
  trace_test::AddFace(mesh, {4, 5, 6, 7});
  auto tracer = MakeEmbreeTracer(mesh);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Float3 up{0, 0, 2};  // not unit: t is the ray parameter
  const std::vector<Ray> rays{
      {{0.2f, 0.1f, -1}, 0, up, inf},         // first sheet at t = 0.5
      {{0.2f, 0.1f, -1}, 0.6f, up, inf},      // skips it: second sheet at t = 1
      {{0.2f, 0.1f, -1}, 0, up, 0.4f},        // ends before: miss
      {{0.2f, 0.1f, -1}, 0.5f, up, 0.5f},     // zero-length window on the sheet: hit at 0.5
      {{0.2f, 0.1f, 3}, 0, {0, 0, -1}, inf},  // from above: upper sheet's front at t = 2
      {{0.2f, 0.1f, -1}, 0.7f, up, 0.6f},     // tnear > tfar: invalid
      {{0.2f, 0.1f, -1}, -1, up, inf},        // tnear < 0: invalid
      {{0.2f, 0.1f, -1}, 0, {0, 0, 0}, inf},  // zero direction: invalid
      {{0.2f, nan, -1}, 0, up, inf},          // NaN origin: invalid
      {{0.2f, 0.1f, -1}, 0, up, nan},         // NaN tfar: invalid
  };
  std::vector<RayHit> hits(rays.size());
  TraceCounters counters;
  (*tracer)->Intersect(rays, hits, counters);
  EXPECT_EQ(counters.queries, rays.size());
  EXPECT_EQ(counters.invalid, 5u);
  // Five valid rays, and the miss cast once more by the vertex guard.
  EXPECT_EQ(counters.rays_cast, 6u);
  EXPECT_EQ(counters.repair_rays, 1u);
  EXPECT_EQ(counters.hits, 4u);
  EXPECT_FLOAT_EQ(hits[0].t, 0.5f);
  EXPECT_EQ(hits[0].prim.value, 0);
  EXPECT_FLOAT_EQ(hits[1].t, 1.0f);
  EXPECT_EQ(hits[1].prim.value, 1);
  EXPECT_FALSE(hits[2].hit());
  EXPECT_TRUE(std::isnan(hits[2].t));
  EXPECT_FLOAT_EQ(hits[3].t, 0.5f);
  EXPECT_FLOAT_EQ(hits[4].t, 2.0f);
  EXPECT_EQ(hits[4].prim.value, 1);
  EXPECT_EQ(hits[4].normal.z, 1.0f);
  for (std::size_t k = 5; k < rays.size(); ++k) EXPECT_FALSE(hits[k].hit()) << k;
}

// The closed-window contract at the ends (include/dispex/trace.h): two sheets 1e-6 apart, much
// closer than Embree's window margin, in every RayMode.
TEST(IntersectTest, WindowEndsAreClosedOnDispexT) {
  const float gap = 1e-6f;
  Mesh mesh = trace_test::NewMesh({{-1, -1, 0},
                                   {1, -1, 0},
                                   {1, 1, 0},
                                   {-1, 1, 0},
                                   {-1, -1, gap},
                                   {1, -1, gap},
                                   {1, 1, gap},
                                   {-1, 1, gap}});
  trace_test::AddFace(mesh, {0, 1, 2, 3});
  trace_test::AddFace(mesh, {4, 5, 6, 7});
  const float inf = std::numeric_limits<float>::infinity();
  const Float3 up{0, 0, 1};
  const Float3 below{0.3f, -0.2f, -1};
  const float t_a = 1.0f;                                   // sheet 0 from below
  const float t_b = static_cast<float>(1.0 + double(gap));  // sheet 1, as dispex rounds it
  const std::vector<Ray> rays{
      {below, 0, up, inf},                          // sheet 0 at t = 1
      {below, std::nextafter(t_a, 2.0f), up, inf},  // starts just past sheet 0: sheet 1
      {below, t_b, up, t_b},                        // zero-length window on sheet 1
      {below, t_a, up, t_a},                        // zero-length window on sheet 0
      {below, 0, up, std::nextafter(t_a, 0.0f)},    // ends just before sheet 0: miss
      {{0.3f, -0.2f, 0}, 0, up, inf},               // origin on sheet 0: hit at t = 0
      {{0.3f, -0.2f, 0}, 1e-7f, up, inf},           // skips it: sheet 1
  };
  for (const RayMode mode : {RayMode::kSingle, RayMode::kPacket4, RayMode::kPacket8,
                             RayMode::kPacket16, RayMode::kStream}) {
    TracerOptions options;
    options.ray_mode = mode;
    auto tracer = MakeEmbreeTracer(mesh, options);
    ASSERT_TRUE(tracer.ok()) << tracer.status().message();
    std::vector<RayHit> hits(rays.size());
    TraceCounters counters;
    (*tracer)->Intersect(rays, hits, counters);
    const char* name = RayModeName(mode).data();
    EXPECT_EQ(hits[0].t, t_a) << name;
    EXPECT_EQ(hits[0].prim.value, 0) << name;
    EXPECT_EQ(hits[1].t, t_b) << name;
    EXPECT_EQ(hits[1].prim.value, 1) << name;
    EXPECT_EQ(hits[2].t, t_b) << name;
    EXPECT_EQ(hits[2].prim.value, 1) << name;
    EXPECT_EQ(hits[3].t, t_a) << name;
    EXPECT_EQ(hits[3].prim.value, 0) << name;
    EXPECT_FALSE(hits[4].hit()) << name;
    EXPECT_EQ(hits[5].t, 0.0f) << name;
    EXPECT_EQ(hits[5].prim.value, 0) << name;
    EXPECT_EQ(hits[6].t, gap) << name;
    EXPECT_EQ(hits[6].prim.value, 1) << name;

    // A normal query from a point on sheet 0: the +n ray's hit at t = 0.
    const std::vector<Float3> origins{{0.3f, -0.2f, 0}};
    const std::vector<Float3> normals{up};
    std::vector<float> t(1);
    std::vector<std::uint8_t> flags(1);
    std::vector<SculptPrimId> prim(1);
    (*tracer)->TraceNormals(origins, normals, NormalQuery{0.5f}, NormalHits{t, prim, flags},
                            counters);
    EXPECT_EQ(t[0], 0.0f) << name;
    EXPECT_EQ(prim[0].value, 0) << name;
    // Its direction leaves through the sheet's front (+z): a back-face hit by definition.
    EXPECT_EQ(flags[0], HitFlags::kHit | HitFlags::kBackFace) << name;
  }
}

TEST(IntersectTest, MatchesBruteForceOnARealMesh) {
  const Mesh blub =
      trace_test::LoadObj(DISPEX_TEST_DATA_DIR "/meshes/keenan_blub/blub_control_mesh.obj");
  const auto oracle = trace_test::OracleTriangles(blub);
  auto tracer = MakeEmbreeTracer(blub);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  std::mt19937 rng(21);
  std::normal_distribution<double> g;
  std::vector<Ray> rays;
  for (int k = 0; k < 1000; ++k) {
    const Vec3 o{0.8 * g(rng), 0.8 * g(rng), 0.8 * g(rng)};
    const Vec3 d{g(rng), g(rng), g(rng)};
    rays.push_back(Ray{trace_test::ToFloat3(o), 0.01f, trace_test::ToFloat3(d), 50});
  }
  std::vector<RayHit> hits(rays.size());
  TraceCounters counters;
  (*tracer)->Intersect(rays, hits, counters);
  int hit_count = 0;
  for (std::size_t k = 0; k < rays.size(); ++k) {
    const auto ref = trace_test::OracleRay(oracle, trace_test::ToVec3(rays[k].origin),
                                           trace_test::ToVec3(rays[k].direction), 0.01, 50);
    ASSERT_EQ(ref.has_value(), hits[k].hit()) << k;
    if (!ref) continue;
    ++hit_count;
    const double scale = std::max(ref->t, 1.0);
    EXPECT_NEAR(hits[k].t, ref->t, 1e-6 * scale) << k;
    if (ref->min_barycentric > 1e-4) {
      EXPECT_EQ(hits[k].prim.value, ref->face) << k;
      EXPECT_NEAR(hits[k].normal.x, ref->normal.x, 1e-5) << k;
      EXPECT_NEAR(hits[k].normal.y, ref->normal.y, 1e-5) << k;
      EXPECT_NEAR(hits[k].normal.z, ref->normal.z, 1e-5) << k;
    }
  }
  EXPECT_GT(hit_count, 200);
}

}  // namespace
}  // namespace dispex
