// Hit policies, misses beyond the search distance, the front/back and direction flags,
// Embree's geometric-normal convention, primitive-to-face mapping, and the ray counters.
#include <gtest/gtest.h>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::AddFace;
using trace_test::NewMesh;

// Two horizontal squares of side 2 centred on the z axis, at z = upper (a quad, face 0) and
// z = -lower (two triangles, faces 1 and 2). Both face +z (counter-clockwise from above).
Mesh TwoSheets(float upper, float lower) {
  Mesh mesh = NewMesh({{-1, -1, upper},
                       {1, -1, upper},
                       {1, 1, upper},
                       {-1, 1, upper},
                       {-1, -1, -lower},
                       {1, -1, -lower},
                       {1, 1, -lower},
                       {-1, 1, -lower}});
  AddFace(mesh, {0, 1, 2, 3});
  AddFace(mesh, {4, 5, 6});
  AddFace(mesh, {4, 6, 7});
  return mesh;
}

struct Result {
  float t;
  SculptPrimId prim;
  std::uint8_t flags;
  TraceCounters counters;
};

// One normal query from (x, y, z0) along +z.
Result Query(const Tracer& tracer, float distance, HitPolicy policy, float z0 = 0, float x = 0.3f,
             float y = -0.2f) {
  const Float3 origin{x, y, z0}, normal{0, 0, 1};
  Result r{};
  tracer.TraceNormals(std::span(&origin, 1), std::span(&normal, 1), NormalQuery{distance, policy},
                      NormalHits{std::span(&r.t, 1), std::span(&r.prim, 1), std::span(&r.flags, 1)},
                      r.counters);
  return r;
}

std::unique_ptr<Tracer> Make(const Mesh& mesh, const TracerOptions& options = {}) {
  auto tracer = MakeEmbreeTracer(mesh, options);
  EXPECT_TRUE(tracer.ok()) << tracer.status().message();
  return std::move(tracer).value();
}

constexpr std::uint8_t kHit = HitFlags::kHit, kNeg = HitFlags::kNegative,
                       kBack = HitFlags::kBackFace;

TEST(PolicyTest, UpperSheetNearer) {
  const Mesh mesh = TwoSheets(0.3f, 0.5f);
  const auto tracer = Make(mesh);
  // +n meets the upper sheet from below (its back), -n the lower sheet from above (front).
  Result r = Query(*tracer, 1, HitPolicy::kNearest);
  EXPECT_FLOAT_EQ(r.t, 0.3f);
  EXPECT_EQ(r.flags, kHit | kBack);
  EXPECT_EQ(r.prim.value, 0);
  r = Query(*tracer, 1, HitPolicy::kOutsideFirst);
  EXPECT_FLOAT_EQ(r.t, 0.3f);
  EXPECT_EQ(r.flags, kHit | kBack);
  r = Query(*tracer, 1, HitPolicy::kInsideFirst);
  EXPECT_FLOAT_EQ(r.t, -0.5f);
  EXPECT_EQ(r.flags, kHit | kNeg);
  EXPECT_EQ(r.prim.value, 1);  // (0.3, -0.2) lies in triangle (4, 5, 6), face 1: x > y
  EXPECT_EQ(Query(*tracer, 1, HitPolicy::kInsideFirst, 0, -0.3f, 0.2f).prim.value, 2);
}

TEST(PolicyTest, LowerSheetNearer) {
  const Mesh mesh = TwoSheets(0.5f, 0.3f);
  const auto tracer = Make(mesh);
  Result r = Query(*tracer, 1, HitPolicy::kNearest);
  EXPECT_FLOAT_EQ(r.t, -0.3f);
  EXPECT_EQ(r.flags, kHit | kNeg);
  EXPECT_EQ(r.prim.value, 1);
  r = Query(*tracer, 1, HitPolicy::kOutsideFirst);
  EXPECT_FLOAT_EQ(r.t, 0.5f);
  EXPECT_EQ(r.flags, kHit | kBack);
  EXPECT_EQ(r.prim.value, 0);
  r = Query(*tracer, 1, HitPolicy::kInsideFirst);
  EXPECT_FLOAT_EQ(r.t, -0.3f);
  EXPECT_EQ(r.flags, kHit | kNeg);
}

TEST(PolicyTest, TieKeepsThePlusHit) {
  const Mesh mesh = TwoSheets(0.4f, 0.4f);
  const auto tracer = Make(mesh);
  const Result r = Query(*tracer, 1, HitPolicy::kNearest);
  EXPECT_FLOAT_EQ(r.t, 0.4f);
  EXPECT_EQ(r.flags, kHit | kBack);
  EXPECT_EQ(r.prim.value, 0);
}

TEST(PolicyTest, OnlyOneSideWithinTheSearchDistance) {
  const Mesh mesh = TwoSheets(0.5f, 0.3f);
  const auto tracer = Make(mesh);
  for (const HitPolicy policy :
       {HitPolicy::kNearest, HitPolicy::kOutsideFirst, HitPolicy::kInsideFirst}) {
    const Result r = Query(*tracer, 0.4f, policy);
    EXPECT_FLOAT_EQ(r.t, -0.3f) << HitPolicyName(policy);
    EXPECT_EQ(r.flags, kHit | kNeg) << HitPolicyName(policy);
  }
}

TEST(PolicyTest, MissesBeyondTheSearchDistance) {
  const Mesh mesh = TwoSheets(0.5f, 0.3f);
  const auto tracer = Make(mesh);
  for (const HitPolicy policy :
       {HitPolicy::kNearest, HitPolicy::kOutsideFirst, HitPolicy::kInsideFirst}) {
    const Result r = Query(*tracer, 0.299f, policy);
    EXPECT_TRUE(std::isnan(r.t)) << HitPolicyName(policy);
    EXPECT_EQ(r.flags, 0) << HitPolicyName(policy);
    EXPECT_FALSE(r.prim.valid()) << HitPolicyName(policy);
    EXPECT_EQ(r.counters.hits, 0u);
    // Both rays, then both again from sideways (TracerOptions::retry_misses).
    EXPECT_EQ(r.counters.rays_cast, 4u);
    EXPECT_EQ(r.counters.repair_rays, 2u);
  }
  // Just inside the distance, it hits.
  EXPECT_FLOAT_EQ(Query(*tracer, 0.301f, HitPolicy::kNearest).t, -0.3f);
}

TEST(PolicyTest, RaysCastFollowTheDocumentedRule) {
  const Mesh mesh = TwoSheets(0.3f, 0.5f);
  const auto tracer = Make(mesh);
  EXPECT_EQ(Query(*tracer, 1, HitPolicy::kNearest).counters.repair_rays, 0u);
  // nearest: +n hits at 0.3 > 0, so -n is cast too (tfar cut to 0.3: it then misses).
  EXPECT_EQ(Query(*tracer, 1, HitPolicy::kNearest).counters.rays_cast, 2u);
  // outside-first: the +n hit decides.
  EXPECT_EQ(Query(*tracer, 1, HitPolicy::kOutsideFirst).counters.rays_cast, 1u);
  // inside-first: -n hits first and decides.
  EXPECT_EQ(Query(*tracer, 1, HitPolicy::kInsideFirst).counters.rays_cast, 1u);
  // nearest with the origin on the upper sheet: +n hits at t = 0, nothing can be nearer.
  const Result on = Query(*tracer, 1, HitPolicy::kNearest, 0.3f);
  EXPECT_EQ(on.t, 0.0f);
  EXPECT_EQ(on.counters.rays_cast, 1u);
  EXPECT_EQ(on.counters.queries, 1u);
  EXPECT_EQ(on.counters.hits, 1u);

  // verify_hits adds one ray per hit: the sideways check of the stretch before it.
  TracerOptions options;
  options.verify_hits = true;
  const auto verifying = Make(mesh, options);
  const Result v = Query(*verifying, 1, HitPolicy::kNearest);
  EXPECT_FLOAT_EQ(v.t, 0.3f);
  EXPECT_EQ(v.counters.rays_cast, 3u);
  EXPECT_EQ(v.counters.repair_rays, 1u);
}

TEST(PolicyTest, InvalidQueriesAreMissesNotRays) {
  const Mesh mesh = TwoSheets(0.3f, 0.5f);
  const auto tracer = Make(mesh);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<Float3> origins{{0, 0, nan}, {0, 0, 0}, {inf, 0, 0}, {0, 0, 0}};
  const std::vector<Float3> normals{{0, 0, 1}, {0, 0, 0}, {0, 0, 1}, {0, 0, 1}};
  std::vector<float> t(4);
  std::vector<std::uint8_t> flags(4);
  TraceCounters counters;
  tracer->TraceNormals(origins, normals, NormalQuery{1}, NormalHits{t, {}, flags}, counters);
  EXPECT_EQ(counters.queries, 4u);
  EXPECT_EQ(counters.invalid, 3u);
  EXPECT_EQ(counters.hits, 1u);
  EXPECT_EQ(counters.rays_cast, 2u);
  for (int k : {0, 1, 2}) {
    EXPECT_TRUE(std::isnan(t[static_cast<std::size_t>(k)]));
    EXPECT_EQ(flags[static_cast<std::size_t>(k)], 0);
  }
  EXPECT_FLOAT_EQ(t[3], 0.3f);
}

// Embree's Ng for a counter-clockwise triangle or quad is the right-hand-rule normal
// (v1 - v0) x (v2 - v0); the back-face flag and RayHit::normal rely on it.
TEST(PolicyTest, GeometricNormalConvention) {
  for (const bool quad : {false, true}) {
    for (const bool flipped : {false, true}) {
      Mesh mesh = NewMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
      if (quad) {
        flipped ? AddFace(mesh, {0, 3, 2, 1}) : AddFace(mesh, {0, 1, 2, 3});
      } else {
        flipped ? AddFace(mesh, {0, 2, 1}) : AddFace(mesh, {0, 1, 2});
      }
      const auto a = trace_test::ToVec3(mesh.positions[static_cast<std::size_t>(mesh.face(0)[0])]);
      const auto b = trace_test::ToVec3(mesh.positions[static_cast<std::size_t>(mesh.face(0)[1])]);
      const auto c = trace_test::ToVec3(mesh.positions[static_cast<std::size_t>(mesh.face(0)[2])]);
      const double right_hand_z = trace_test::Cross(b - a, c - a).z;  // +1 or -1 here
      const auto tracer = Make(mesh);

      const Ray down{{0.7f, 0.2f, 1}, 0, {0, 0, -1}, 5};
      RayHit hit;
      TraceCounters counters;
      tracer->Intersect(std::span(&down, 1), std::span(&hit, 1), counters);
      ASSERT_TRUE(hit.hit());
      EXPECT_FLOAT_EQ(hit.t, 1);
      EXPECT_EQ(hit.normal.x, 0);
      EXPECT_EQ(hit.normal.y, 0);
      EXPECT_EQ(hit.normal.z, static_cast<float>(right_hand_z));

      // A query from above along +z: only -n (going down) hits. Going down meets the front
      // when the right-hand normal points up.
      const Result r = Query(*tracer, 2, HitPolicy::kNearest, 1.0f, 0.7f, 0.2f);
      ASSERT_EQ(r.flags & kHit, kHit);
      EXPECT_EQ((r.flags & kBack) != 0, right_hand_z < 0) << quad << flipped;
    }
  }
}

TEST(PolicyTest, PrimitiveIdsMapBackToFacesInMixedMeshes) {
  // Five unit squares side by side along x, each a different kind of face: a triangle
  // (covering the lower-right half), a quad, a pentagon, a quad, a hexagon.
  std::vector<Float3> positions;
  auto v = [&](float x, float y) {
    positions.push_back({x, y, 0});
    return static_cast<std::int32_t>(positions.size() - 1);
  };
  std::vector<std::vector<std::int32_t>> faces;
  faces.push_back({v(0, 0), v(1, 0), v(1, 1)});
  faces.push_back({v(1, 0), v(2, 0), v(2, 1), v(1, 1)});
  faces.push_back({v(2, 0), v(3, 0), v(3, 1), v(2.5f, 1.2f), v(2, 1)});
  faces.push_back({v(3, 0), v(4, 0), v(4, 1), v(3, 1)});
  faces.push_back({v(4, 0), v(4.5f, -0.1f), v(5, 0), v(5, 1), v(4.5f, 1.1f), v(4, 1)});
  Mesh mesh = NewMesh(positions);
  for (const auto& f : faces) {
    mesh.face_indices.insert(mesh.face_indices.end(), f.begin(), f.end());
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
  }
  const auto tracer = Make(mesh);
  EXPECT_EQ(tracer->stats().quads, 2u);
  EXPECT_EQ(tracer->stats().triangles, 1u + 3u + 4u);
  EXPECT_FALSE(tracer->stats().shared_indices);
  EXPECT_TRUE(tracer->stats().shared_vertices);
  const std::vector<float> xs{0.8f, 1.5f, 2.5f, 2.9f, 3.5f, 4.5f, 4.9f};
  const std::vector<int> expected{0, 1, 2, 2, 3, 4, 4};
  std::vector<Float3> origins, normals;
  for (const float x : xs) {
    origins.push_back({x, 0.3f, 1});
    normals.push_back({0, 0, 1});
  }
  std::vector<float> t(xs.size());
  std::vector<SculptPrimId> prim(xs.size());
  std::vector<std::uint8_t> flags(xs.size());
  TraceCounters counters;
  tracer->TraceNormals(origins, normals, NormalQuery{2}, NormalHits{t, prim, flags}, counters);
  for (std::size_t k = 0; k < xs.size(); ++k) {
    EXPECT_EQ(prim[k].value, expected[k]) << xs[k];
    EXPECT_FLOAT_EQ(t[k], -1) << xs[k];
  }
}

TEST(PolicyTest, Names) {
  for (const HitPolicy p :
       {HitPolicy::kNearest, HitPolicy::kOutsideFirst, HitPolicy::kInsideFirst}) {
    EXPECT_EQ(ParseHitPolicy(HitPolicyName(p)).value(), p);
  }
  for (const BuildQuality q : {BuildQuality::kLow, BuildQuality::kMedium, BuildQuality::kHigh}) {
    EXPECT_EQ(ParseBuildQuality(BuildQualityName(q)).value(), q);
  }
  for (const RayMode m : {RayMode::kSingle, RayMode::kPacket4, RayMode::kPacket8,
                          RayMode::kPacket16, RayMode::kStream}) {
    EXPECT_EQ(ParseRayMode(RayModeName(m)).value(), m);
  }
  EXPECT_EQ(HitPolicyName(HitPolicy::kOutsideFirst), "outside-first");
  const auto bad = ParseHitPolicy("closest");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(),
            "unknown hit policy 'closest' (expected nearest, outside-first or inside-first)");
}

}  // namespace
}  // namespace dispex
