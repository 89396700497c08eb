// Bad sculpts and Embree failures become Status messages that name the element; buffers are
// shared with the mesh where Embree allows and copied (with the same results) where not.
#include <gtest/gtest.h>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::AddFace;
using trace_test::NewMesh;

Mesh Square() {
  Mesh mesh = NewMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  mesh.source = "sculpt.obj";
  AddFace(mesh, {0, 1, 2, 3});
  return mesh;
}

std::string Error(const Mesh& mesh, const TracerOptions& options = {}) {
  auto tracer = MakeEmbreeTracer(mesh, options);
  return tracer.ok() ? "(no error)" : tracer.status().message();
}

TEST(SceneErrorsTest, EmptySculpt) {
  Mesh mesh = Square();
  mesh.face_indices.clear();
  mesh.face_offsets = {0};
  EXPECT_EQ(Error(mesh), "sculpt.obj: the sculpt has no faces");
  mesh.face_offsets.clear();
  EXPECT_EQ(Error(mesh), "sculpt.obj: the sculpt has no faces");
  Mesh unnamed;
  EXPECT_EQ(Error(unnamed), "sculpt: the sculpt has no faces");
}

TEST(SceneErrorsTest, FaceWithTooFewVertices) {
  Mesh mesh = Square();
  AddFace(mesh, {0, 2});
  EXPECT_EQ(Error(mesh), "sculpt.obj: sculpt face 1 has 2 vertices; a face needs at least 3");
}

TEST(SceneErrorsTest, IndexOutOfRange) {
  Mesh mesh = Square();
  AddFace(mesh, {0, 2, 7});
  EXPECT_EQ(Error(mesh),
            "sculpt.obj: sculpt face 1 corner 2 uses vertex 7, but the sculpt has 4 vertices");
  mesh = Square();
  mesh.face_indices[1] = -3;
  EXPECT_EQ(Error(mesh),
            "sculpt.obj: sculpt face 0 corner 1 uses vertex -3, but the sculpt has 4 vertices");
}

TEST(SceneErrorsTest, MalformedOffsets) {
  Mesh mesh = Square();
  mesh.face_offsets.back() = 3;
  EXPECT_EQ(Error(mesh), "sculpt.obj: sculpt face offsets end at 3 but there are 4 face indices");
  mesh = Square();
  AddFace(mesh, {0, 1, 2});
  mesh.face_offsets = {0, 5, 4, 7};  // three faces, the second running backwards
  mesh.face_indices = {0, 1, 2, 3, 0, 1, 2};
  EXPECT_EQ(Error(mesh),
            "sculpt.obj: sculpt face 1 has malformed offsets (5 to 4, 7 face indices)");
  mesh.face_offsets = {2, 4, 7};
  EXPECT_EQ(Error(mesh), "sculpt.obj: sculpt face offsets start at 2, not 0");
}

TEST(SceneErrorsTest, NonFinitePositions) {
  Mesh mesh = Square();
  mesh.positions[2].y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(Error(mesh),
            "sculpt.obj: sculpt vertex 2 (used by face 0) has a non-finite position (1, nan, 0)");
  mesh = Square();
  mesh.positions[3].z = -std::numeric_limits<float>::infinity();
  EXPECT_EQ(Error(mesh),
            "sculpt.obj: sculpt vertex 3 (used by face 0) has a non-finite position (0, 1, -inf)");
  // A non-finite vertex that no face uses is harmless.
  mesh = Square();
  mesh.positions.push_back({std::numeric_limits<float>::quiet_NaN(), 0, 0});
  EXPECT_EQ(Error(mesh), "(no error)");
}

TEST(SceneErrorsTest, MemoryLimitGivesOutOfMemory) {
  Mesh mesh = trace_test::CubeSphere(40, 1.0, false);
  mesh.source = "big.obj";
  TracerOptions options;
  options.memory_limit_bytes = 64 * 1024;
  const std::string error = Error(mesh, options);
  EXPECT_EQ(error.rfind("big.obj: embree: out of memory", 0), 0u) << error;
  EXPECT_NE(error.find("RTC_ERROR_OUT_OF_MEMORY"), std::string::npos) << error;
  // With room to spare it builds, and reports what Embree holds.
  options.memory_limit_bytes = std::int64_t{1} << 30;
  auto tracer = MakeEmbreeTracer(mesh, options);
  ASSERT_TRUE(tracer.ok()) << tracer.status().message();
  EXPECT_GT((*tracer)->stats().backend_bytes, 64 * 1024);
  EXPECT_GE((*tracer)->stats().backend_peak_bytes, (*tracer)->stats().backend_bytes);
  EXPECT_TRUE((*tracer)->status().ok());
}

TEST(SceneErrorsTest, SharedOrCopiedBuffersGiveTheSameHits) {
  Mesh shared = trace_test::CubeSphere(8, 1.0, false);
  Mesh copied = shared;
  copied.positions.shrink_to_fit();  // no room for Embree's padding: must be copied
  ASSERT_EQ(copied.positions.capacity(), copied.positions.size());
  auto a = MakeEmbreeTracer(shared);
  auto b = MakeEmbreeTracer(copied);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE((*a)->stats().shared_vertices);
  EXPECT_TRUE((*a)->stats().shared_indices);
  EXPECT_EQ((*a)->stats().copied_bytes, 0u);
  EXPECT_FALSE((*b)->stats().shared_vertices);
  EXPECT_GE((*b)->stats().copied_bytes, copied.positions.size() * sizeof(Float3));

  std::vector<Float3> origins, normals;
  for (std::size_t v = 0; v < shared.num_vertices(); ++v) {
    const Float3& p = shared.positions[v];
    origins.push_back({0.9f * p.x + 0.01f, 0.9f * p.y - 0.02f, 0.9f * p.z + 0.005f});
    normals.push_back(p);
  }
  std::vector<float> ta(origins.size()), tb(origins.size());
  std::vector<std::uint8_t> fa(origins.size()), fb(origins.size());
  TraceCounters counters;
  (*a)->TraceNormals(origins, normals, NormalQuery{1}, NormalHits{ta, {}, fa}, counters);
  (*b)->TraceNormals(origins, normals, NormalQuery{1}, NormalHits{tb, {}, fb}, counters);
  EXPECT_EQ(ta, tb);
  EXPECT_EQ(fa, fb);
  EXPECT_EQ(counters.hits, 2 * origins.size());
}

TEST(SceneErrorsTest, AllTriangleMeshesShareTheirIndices) {
  const Mesh mesh = trace_test::CubeSphere(4, 1.0, true);
  auto tracer = MakeEmbreeTracer(mesh);
  ASSERT_TRUE(tracer.ok());
  EXPECT_TRUE((*tracer)->stats().shared_indices);
  EXPECT_EQ((*tracer)->stats().triangles, mesh.num_faces());
  EXPECT_EQ((*tracer)->stats().quads, 0u);
}

TEST(SceneErrorsTest, StatsDescribeTheBuild) {
  const Mesh mesh = trace_test::CubeSphere(4, 1.0, false);
  TracerOptions options;
  options.quality = BuildQuality::kMedium;
  options.ray_mode = RayMode::kPacket16;
  auto tracer = MakeEmbreeTracer(mesh, options);
  ASSERT_TRUE(tracer.ok());
  const TracerStats& stats = (*tracer)->stats();
  EXPECT_EQ(stats.faces, 96u);
  EXPECT_EQ(stats.quads, 96u);
  EXPECT_NE(stats.backend.find("embree 3."), std::string::npos) << stats.backend;
  EXPECT_NE(stats.backend.find("medium build, robust, retry misses, packet16"), std::string::npos)
      << stats.backend;
  EXPECT_GE(stats.build_seconds, 0);
}

}  // namespace
}  // namespace dispex
