// Results do not depend on the number of threads that build the BVH or trace, nor on how
// queries are split into batches.
#include <gtest/gtest.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cstring>
#include <mutex>
#include <random>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

struct Results {
  std::vector<float> t;
  std::vector<SculptPrimId> prim;
  std::vector<std::uint8_t> flags;
  std::vector<ClosestPoint> closest;
  TraceCounters counters;
};

Results TraceIn(int threads, std::size_t batch, const Mesh& mesh,
                const std::vector<Float3>& origins, const std::vector<Float3>& normals,
                BuildQuality quality) {
  Results run;
  const std::size_t n = origins.size();
  run.t.assign(n, 0.0f);
  run.prim.assign(n, SculptPrimId());
  run.flags.assign(n, 0);
  run.closest.assign(n, ClosestPoint{});
  tbb::task_arena arena(threads);
  arena.execute([&] {
    TracerOptions options;
    options.quality = quality;
    auto tracer = MakeEmbreeTracer(mesh, options);
    ASSERT_TRUE(tracer.ok());
    std::mutex mutex;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, batch),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        const std::size_t b = r.begin(), m = r.size();
                        TraceCounters counters;
                        (*tracer)->TraceNormals(std::span(origins).subspan(b, m),
                                                std::span(normals).subspan(b, m), NormalQuery{0.2f},
                                                NormalHits{std::span(run.t).subspan(b, m),
                                                           std::span(run.prim).subspan(b, m),
                                                           std::span(run.flags).subspan(b, m)},
                                                counters);
                        (*tracer)->ClosestPoints(std::span(origins).subspan(b, m), 1.0f,
                                                 std::span(run.closest).subspan(b, m), counters);
                        std::lock_guard lock(mutex);
                        run.counters += counters;
                      });
  });
  return run;
}

TEST(ThreadsTest, SameAnswersForAnyThreadCountAndBatching) {
  // A bumpy sphere: vertices pushed in and out so hits are on both sides.
  Mesh mesh = trace_test::CubeSphere(48, 1.0, false);
  for (Float3& p : mesh.positions) {
    const float s = 1 + 0.05f * std::sin(9 * p.x) * std::cos(7 * p.y) * std::sin(5 * p.z);
    p = {p.x * s, p.y * s, p.z * s};
  }
  std::mt19937 rng(13);
  std::normal_distribution<double> g;
  std::vector<Float3> origins, normals;
  for (int k = 0; k < 40000; ++k) {
    trace_test::Vec3 d{g(rng), g(rng), g(rng)};
    d = (1 / trace_test::Length(d)) * d;
    origins.push_back(trace_test::ToFloat3(d));
    normals.push_back(trace_test::ToFloat3(d));
  }
  for (const BuildQuality quality : {BuildQuality::kLow, BuildQuality::kMedium}) {
    SCOPED_TRACE(std::string(BuildQualityName(quality)));
    const Results one = TraceIn(1, 40000, mesh, origins, normals, quality);
    const Results two = TraceIn(2, 333, mesh, origins, normals, quality);
    const Results two_big = TraceIn(2, 4096, mesh, origins, normals, quality);
    for (const Results* other : {&two, &two_big}) {
      EXPECT_EQ(std::memcmp(one.t.data(), other->t.data(), one.t.size() * sizeof(float)), 0);
      EXPECT_EQ(one.prim, other->prim);
      EXPECT_EQ(one.flags, other->flags);
      EXPECT_EQ(std::memcmp(one.closest.data(), other->closest.data(),
                            one.closest.size() * sizeof(ClosestPoint)),
                0);
      EXPECT_EQ(one.counters.rays_cast, other->counters.rays_cast);
      EXPECT_EQ(one.counters.hits, other->counters.hits);
    }
    EXPECT_GT(one.counters.hits, 70000u);  // 40000 normal queries + 40000 closest points
  }
}

}  // namespace
}  // namespace dispex
