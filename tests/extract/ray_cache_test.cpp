// The automatic search distance's rays kept between incremental runs (ray_cache.h): after an
// edit of the sculpt, every ray's nearest |t| updated from the run before must be the bits a
// BVH of the whole edited sculpt gives (LowerNearestHits), while casting only the rays near the
// edit again; the cache file reads back what was written and refuses other rays or damage.
#include "extract/incremental/ray_cache.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/trace.h"
#include "e2e_support.h"

namespace dispex::extract {
namespace {

using testing::DataPath;
using testing::TempDir;

struct Rays {
  std::vector<Float3> origins, normals;
  float length = 0;
  LongRays View() const { return {origins, normals, length}; }
};

// 4 x 4 points on each quad of the cage, along its normal (the rays of the estimate leave the
// limit surface; any rays near the sculpt test the update as well).
Rays CageRays(const Mesh& cage) {
  Rays rays;
  const BoundingBox box = ComputeBounds(cage);
  const Float3 d{box.max.x - box.min.x, box.max.y - box.min.y, box.max.z - box.min.z};
  rays.length = 0.15f * std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  for (std::size_t f = 0; f < cage.num_faces(); ++f) {
    const std::span<const std::int32_t> face = cage.face(f);
    if (face.size() != 4) continue;
    Float3 p[4];
    for (int c = 0; c < 4; ++c) p[c] = cage.positions[static_cast<std::size_t>(face[c])];
    const Float3 a{p[2].x - p[0].x, p[2].y - p[0].y, p[2].z - p[0].z};
    const Float3 b{p[3].x - p[1].x, p[3].y - p[1].y, p[3].z - p[1].z};
    Float3 n{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    if (!(len > 0)) continue;
    n = {n.x / len, n.y / len, n.z / len};
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i) {
        const float u = (i + 0.5f) / 4, v = (j + 0.5f) / 4;
        const float w[4] = {(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v};
        Float3 o{};
        for (int c = 0; c < 4; ++c) {
          o = {o.x + w[c] * p[c].x, o.y + w[c] * p[c].y, o.z + w[c] * p[c].z};
        }
        rays.origins.push_back(o);
        rays.normals.push_back(n);
      }
    }
  }
  return rays;
}

// Each ray's nearest |t| (and its side) through a BVH of the whole sculpt.
std::vector<float> WholeNearest(const Mesh& sculpt, const Rays& rays,
                                std::vector<std::int8_t>* side = nullptr) {
  std::vector<float> nearest(rays.origins.size(), std::numeric_limits<float>::infinity());
  std::vector<std::int8_t> sides(rays.origins.size(), 0);
  auto tracer = MakeEmbreeTracer(sculpt, TracerOptions{});
  EXPECT_TRUE(tracer.ok()) << tracer.status().message();
  if (!tracer.ok()) return nearest;
  LowerNearestHits(**tracer, rays.origins, rays.normals, rays.length, nearest, sides);
  if (side != nullptr) *side = std::move(sides);
  return nearest;
}

// Moves the sculpt's vertices within `radius` of `centre` by up to `amount` along +y, smoothly.
Mesh Bumped(Mesh sculpt, const Float3& centre, float radius, float amount) {
  for (Float3& p : sculpt.positions) {
    const float dx = p.x - centre.x, dy = p.y - centre.y, dz = p.z - centre.z;
    const float r = std::sqrt(dx * dx + dy * dy + dz * dz) / radius;
    if (r < 1) p.y += amount * (1 - r * r) * (1 - r * r);
  }
  return sculpt;
}

class RayCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string cage_path = DataPath("meshes/keenan_spot/spot_quadrangulated.obj");
    auto cage = ReadMesh(cage_path);
    ASSERT_TRUE(cage.ok()) << cage.status().message();
    cage_ = std::move(*cage);
    const std::string sculpt_path = dir_ / "sculpt.ply";
    ASSERT_TRUE(
        MakeSculpt(testing::SculptOptions(cage_path, sculpt_path, 2, Pattern::kDetail, 0.005))
            .ok());
    auto sculpt = ReadMesh(sculpt_path);
    ASSERT_TRUE(sculpt.ok()) << sculpt.status().message();
    sculpt_ = std::move(*sculpt);
    rays_ = CageRays(cage_);
    ASSERT_GT(rays_.origins.size(), 1000u);
  }

  // The cache of `sculpt`'s rays as a run through a BVH of the whole sculpt writes it.
  RayCache Cached(const Mesh& sculpt, const RayGrid& grid) const {
    RayCache cache;
    cache.rays_key = RaysKey(rays_.View(), grid);
    KeySculptCells(sculpt, grid, cache);
    cache.nearest = WholeNearest(sculpt, rays_, &cache.side);
    return cache;
  }

  // Updates `before` to `after` and compares every ray's bits with the whole BVH's.
  std::int64_t ExpectUpdateIsWhole(const Mesh& before_sculpt, const Mesh& after) const {
    const RayGrid grid(rays_.View());
    const RayCache before = Cached(before_sculpt, grid);
    RayCache now;
    now.rays_key = before.rays_key;
    KeySculptCells(after, grid, now);
    std::int64_t recast = -1;
    EXPECT_TRUE(
        UpdateNearestHits(after, TracerOptions{}, rays_.View(), grid, before, now, recast).ok());
    std::vector<std::int8_t> sides;
    const std::vector<float> expected = WholeNearest(after, rays_, &sides);
    EXPECT_TRUE(now.side == sides) << "the hits' sides differ from the whole BVH's";
    EXPECT_EQ(now.nearest.size(), expected.size());
    std::size_t differ = 0, hits = 0;
    for (std::size_t i = 0; i < expected.size() && i < now.nearest.size(); ++i) {
      differ +=
          std::bit_cast<std::uint32_t>(now.nearest[i]) != std::bit_cast<std::uint32_t>(expected[i]);
      hits += std::isfinite(expected[i]);
    }
    EXPECT_EQ(differ, 0u) << "of " << expected.size() << " rays, " << recast << " cast again";
    EXPECT_GT(hits, expected.size() / 2);
    return recast;
  }

  TempDir dir_;
  Mesh cage_, sculpt_;
  Rays rays_;
};

TEST_F(RayCacheTest, AnEditRecastsTheRaysNearItAndGivesTheWholeSculptsHits) {
  const BoundingBox box = ComputeBounds(sculpt_);
  const float diagonal =
      std::sqrt(std::pow(box.max.x - box.min.x, 2.0f) + std::pow(box.max.y - box.min.y, 2.0f) +
                std::pow(box.max.z - box.min.z, 2.0f));
  // A bump at a vertex of the sculpt's surface, then a deeper one (the rays that hit the old
  // surface there must be cast again in full), then nothing changed.
  const Float3 at = sculpt_.positions[sculpt_.positions.size() / 3];
  const Mesh bumped = Bumped(sculpt_, at, 0.03f * diagonal, 0.005f * diagonal);
  const std::int64_t recast = ExpectUpdateIsWhole(sculpt_, bumped);
  EXPECT_GT(recast, 0);
  EXPECT_LT(recast, static_cast<std::int64_t>(rays_.origins.size() / 4))
      << "a local edit casts only the rays near it again";
  const Mesh deeper = Bumped(bumped, at, 0.03f * diagonal, 0.02f * diagonal);
  EXPECT_GT(ExpectUpdateIsWhole(bumped, deeper), 0);
  EXPECT_EQ(ExpectUpdateIsWhole(deeper, deeper), 0);
  // A sculpt moved as a whole: every ray is cast again.
  Mesh moved = sculpt_;
  for (Float3& p : moved.positions) p.x += 0.02f * diagonal;
  EXPECT_EQ(ExpectUpdateIsWhole(sculpt_, moved), static_cast<std::int64_t>(rays_.origins.size()));
}

TEST_F(RayCacheTest, TheFileReadsBackAndRefusesOtherRaysAndDamage) {
  const RayGrid grid(rays_.View());
  const RayCache written = Cached(sculpt_, grid);
  const std::string path = RayCachePath(dir_ / "cache", dir_ / "sculpt.ply", "fingerprint");
  EXPECT_EQ(path, RayCachePath(dir_ / "cache", dir_ / "./sculpt.ply", "fingerprint"));
  EXPECT_NE(path, RayCachePath(dir_ / "cache", dir_ / "other.ply", "fingerprint"));
  EXPECT_NE(path, RayCachePath(dir_ / "cache", dir_ / "sculpt.ply", "another base"));
  EXPECT_EQ(RayCachePath("", dir_ / "sculpt.ply", "fingerprint"), "");
  ASSERT_TRUE(WriteRayCache(path, written));
  const std::optional<RayCache> read = ReadRayCache(path, written.rays_key);
  ASSERT_TRUE(read.has_value());
  EXPECT_TRUE(read->cells == written.cells);
  EXPECT_EQ(std::memcmp(read->nearest.data(), written.nearest.data(),
                        written.nearest.size() * sizeof(float)),
            0);
  EXPECT_EQ(read->half_extent, written.half_extent);
  EXPECT_TRUE(read->side == written.side);
  // Other rays (a longer length): not this file's.
  Rays longer = rays_;
  longer.length *= 2;
  EXPECT_FALSE(ReadRayCache(path, RaysKey(longer.View(), RayGrid(longer.View()))).has_value());
  // A byte changed, and a file cut short.
  std::string bytes = testing::Slurp(path);
  bytes[bytes.size() / 2] ^= 1;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_FALSE(ReadRayCache(path, written.rays_key).has_value());
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes.substr(0, 100);
  EXPECT_FALSE(ReadRayCache(path, written.rays_key).has_value());
  EXPECT_FALSE(ReadRayCache(dir_ / "missing.bin", written.rays_key).has_value());
}

}  // namespace
}  // namespace dispex::extract
