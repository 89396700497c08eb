// Normal queries between two real meshes: points on Spot's control cage with its face
// normals, against the cage refined twice (the quadrangulated Spot), every policy, compared
// with the brute-force double-precision oracle.
#include <gtest/gtest.h>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::Vec3;

TEST(RealMeshTest, CageToRefinedSpot) {
  const Mesh cage =
      trace_test::LoadObj(DISPEX_TEST_DATA_DIR "/meshes/keenan_spot/spot_control_mesh.obj");
  const Mesh sculpt =
      trace_test::LoadObj(DISPEX_TEST_DATA_DIR "/meshes/keenan_spot/spot_quadrangulated.obj");
  const auto oracle = trace_test::OracleTriangles(sculpt);
  auto tracer = MakeEmbreeTracer(sculpt);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();

  // Four points per fan triangle of each cage face (triangles, quads and pentagons), with
  // the face's Newell normal.
  std::vector<Float3> origins, normals;
  for (std::size_t f = 0; f < cage.num_faces(); ++f) {
    const auto v = cage.face(f);
    std::vector<Vec3> p;
    for (const std::int32_t index : v) {
      p.push_back(trace_test::ToVec3(cage.positions[static_cast<std::size_t>(index)]));
    }
    Vec3 n;
    for (std::size_t k = 0; k < p.size(); ++k)
      n = n + trace_test::Cross(p[k], p[(k + 1) % p.size()]);
    n = (1 / trace_test::Length(n)) * n;
    for (std::size_t k = 1; k + 1 < p.size(); ++k) {
      for (const auto& [a, b, c] :
           {std::array{1.0 / 3, 1.0 / 3, 1.0 / 3}, std::array{4.0 / 6, 1.0 / 6, 1.0 / 6},
            std::array{1.0 / 6, 4.0 / 6, 1.0 / 6}, std::array{1.0 / 6, 1.0 / 6, 4.0 / 6}}) {
        origins.push_back(trace_test::ToFloat3(a * p[0] + b * p[k] + c * p[k + 1]));
        normals.push_back(trace_test::ToFloat3(n));
      }
    }
  }
  constexpr float kDistance = 0.15f;
  const std::size_t n = origins.size();
  std::vector<std::optional<trace_test::OracleHit>> plus_hits, minus_hits;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 o = trace_test::ToVec3(origins[k]);
    const Vec3 d = trace_test::ToVec3(normals[k]);
    plus_hits.push_back(trace_test::OracleRay(oracle, o, d, 0, kDistance));
    minus_hits.push_back(trace_test::OracleRay(oracle, o, -1.0 * d, 0, kDistance));
  }
  for (const HitPolicy policy :
       {HitPolicy::kNearest, HitPolicy::kOutsideFirst, HitPolicy::kInsideFirst}) {
    SCOPED_TRACE(std::string(HitPolicyName(policy)));
    std::vector<float> t(n);
    std::vector<SculptPrimId> prim(n);
    std::vector<std::uint8_t> flags(n);
    TraceCounters counters;
    (*tracer)->TraceNormals(origins, normals, NormalQuery{kDistance, policy},
                            NormalHits{t, prim, flags}, counters);
    int hits = 0, faces_checked = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3 d = trace_test::ToVec3(normals[k]);
      const auto& plus = plus_hits[k];
      const auto& minus = minus_hits[k];
      if ((plus && plus->t > kDistance - 1e-5) || (minus && minus->t > kDistance - 1e-5)) continue;
      bool take_minus = false;
      switch (policy) {
        case HitPolicy::kNearest:
          take_minus = minus && (!plus || minus->t < plus->t);
          break;
        case HitPolicy::kOutsideFirst:
          take_minus = !plus && minus;
          break;
        case HitPolicy::kInsideFirst:
          take_minus = minus.has_value();
          break;
      }
      const auto& ref = take_minus ? minus : plus;
      ASSERT_EQ(ref.has_value(), (flags[k] & HitFlags::kHit) != 0) << k;
      if (!ref) continue;
      ++hits;
      EXPECT_NEAR(t[k], take_minus ? -ref->t : ref->t, 1e-6 * std::max(ref->t, 1.0)) << k;
      EXPECT_EQ((flags[k] & HitFlags::kNegative) != 0, take_minus) << k;
      const Vec3 dir = take_minus ? -1.0 * d : d;
      EXPECT_EQ((flags[k] & HitFlags::kBackFace) != 0, trace_test::Dot(dir, ref->normal) > 0) << k;
      if (ref->min_barycentric > 1e-4) {
        EXPECT_EQ(prim[k].value, ref->face) << k;
        ++faces_checked;
      }
    }
    EXPECT_GT(hits, static_cast<int>(n) * 9 / 10);
    EXPECT_GT(faces_checked, static_cast<int>(n) * 3 / 4);
  }
}

}  // namespace
}  // namespace dispex
