// Directions whose small components are rounding noise, e.g. (-1.7e-20, 4.9e-4, 1) from the
// limit normals of a flat creased side: Embree 3.13.5's coherent 8-wide packets lost a third
// of such rays (src/trace/batch_kernels.h, FlushTiny). Every RayMode must hit them all, with
// the t of single rays.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

constexpr RayMode kModes[] = {RayMode::kSingle, RayMode::kPacket4, RayMode::kPacket8,
                              RayMode::kPacket16, RayMode::kStream};

// A flat quad grid z = 1e-4 over [-1, 1]^2, and rays from z = 0 just below it with noisy
// directions of every sign mixed in each batch.
struct TinyCase {
  Mesh grid;
  std::vector<Float3> origins, directions;
};

TinyCase MakeCase() {
  TinyCase c;
  const int n = 64;
  std::vector<Float3> positions;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      positions.push_back({-1.0f + 2.0f * static_cast<float>(i) / n,
                           -1.0f + 2.0f * static_cast<float>(j) / n, 1e-4f});
    }
  }
  c.grid = trace_test::NewMesh(positions);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::int32_t a = j * (n + 1) + i;
      trace_test::AddFace(c.grid, {a, a + 1, a + n + 2, a + n + 1});
    }
  }
  const Float3 noisy[] = {{1e-20f, 1e-17f, 1},     {-1e-20f, 1e-17f, 1},    {1e-20f, -1e-17f, 1},
                          {-1e-20f, -1e-17f, 1},   {0, -3e-35f, 1},         {-1.7e-20f, 4.9e-4f, 1},
                          {1.7e-20f, -4.9e-4f, 1}, {4.9e-4f, -1.7e-20f, 1}, {0, 0, 1},
                          {1e-7f, -1e-6f, 1},      {-3e-7f, 1e-5f, 1},      {2e-6f, -1e-9f, 1},
                          {-1e-8f, 1e-8f, 1}};
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.9f, 0.9f);
  for (int k = 0; k < 4096; ++k) {
    // Neighbouring samples share packets, as in extraction: strips of 8 along x.
    const float x = u(rng), y = u(rng);
    for (int s = 0; s < 8; ++s) {
      c.origins.push_back({x + 1e-3f * static_cast<float>(s), y, 0});
      c.directions.push_back(noisy[(k + s) % std::size(noisy)]);
    }
  }
  return c;
}

TEST(TinyDirectionTest, NormalQueriesHitInEveryRayMode) {
  const TinyCase c = MakeCase();
  const std::size_t n = c.origins.size();
  std::vector<float> single_t;
  for (const RayMode mode : kModes) {
    TracerOptions options;
    options.ray_mode = mode;
    options.retry_misses = false;  // the first pass alone must hit
    auto tracer = MakeEmbreeTracer(c.grid, options);
    ASSERT_TRUE(tracer.ok()) << tracer.status().message();
    std::vector<float> t(n);
    std::vector<std::uint8_t> flags(n);
    TraceCounters counters;
    (*tracer)->TraceNormals(c.origins, c.directions, NormalQuery{1e-3f}, NormalHits{t, {}, flags},
                            counters);
    EXPECT_EQ(counters.hits, n) << RayModeName(mode);
    if (mode == RayMode::kSingle) single_t = t;
    int differ = 0;
    for (std::size_t i = 0; i < n; ++i) differ += t[i] == single_t[i] ? 0 : 1;
    EXPECT_EQ(differ, 0) << RayModeName(mode);
  }
}

TEST(TinyDirectionTest, RaysHitInEveryRayMode) {
  const TinyCase c = MakeCase();
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < c.origins.size(); ++i) {
    rays.push_back(Ray{c.origins[i], 0, c.directions[i], 1e-3f});
  }
  std::vector<RayHit> single;
  for (const RayMode mode : kModes) {
    TracerOptions options;
    options.ray_mode = mode;
    options.retry_misses = false;
    auto tracer = MakeEmbreeTracer(c.grid, options);
    ASSERT_TRUE(tracer.ok()) << tracer.status().message();
    std::vector<RayHit> hits(rays.size());
    TraceCounters counters;
    (*tracer)->Intersect(rays, hits, counters);
    EXPECT_EQ(counters.hits, rays.size()) << RayModeName(mode);
    if (mode == RayMode::kSingle) single = hits;
    int differ = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) differ += hits[i].t == single[i].t ? 0 : 1;
    EXPECT_EQ(differ, 0) << RayModeName(mode);
  }
}

}  // namespace
}  // namespace dispex
