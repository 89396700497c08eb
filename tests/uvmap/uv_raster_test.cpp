// PtexUvCharts' inverse: every texel centre placed on a Ptex face maps back to itself, the
// texels inside UV faces are counted exactly, overlaps and UVs outside the UDIM range are
// reported, and a cage without UVs on every face is refused naming the face.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/uv_charts.h"

namespace dispex {
namespace {

std::string DataPath(const std::string& relative) {
  return (std::filesystem::path(DISPEX_TEST_DATA_DIR) / relative).string();
}

// A mesh from OBJ text, through a temporary file.
Mesh ObjMesh(const std::string& text) {
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("dispex_uv_raster_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
        "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".obj"))
          .string();
  std::ofstream(path) << text;
  auto mesh = ReadMesh(path);
  std::filesystem::remove(path);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return mesh.ok() ? std::move(*mesh) : Mesh{};
}

struct Charted {
  Mesh mesh;
  LimitSurface surface;
  PtexUvCharts charts;
};

Charted Chart(Mesh mesh) {
  auto surface = LimitSurface::Build(mesh);
  EXPECT_TRUE(surface.ok()) << surface.status().message();
  auto charts = PtexUvCharts::Build(mesh, *surface);
  EXPECT_TRUE(charts.ok()) << charts.status().message();
  return {std::move(mesh), std::move(*surface), std::move(*charts)};
}

// Each placed texel's (face, u, v) goes back to its centre through the forward rule.
void ExpectPlacesMapBack(const PtexUvCharts& charts, const UvRaster& raster) {
  const int n = raster.resolution;
  for (const UvTile& tile : raster.tiles) {
    const int tu = (tile.udim - 1001) % 10, tv = (tile.udim - 1001) / 10;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const UvTexelPlace& p = tile.places[static_cast<std::size_t>(j) * n + i];
        if (p.face < 0) continue;
        double uv[2];
        charts.Evaluate(PtexFaceId(p.face), p.u, p.v, uv);
        ASSERT_NEAR(uv[0], tu + (i + 0.5) / n, 1e-6) << tile.udim << " " << i << " " << j;
        ASSERT_NEAR(uv[1], tv + (j + 0.5) / n, 1e-6) << tile.udim << " " << i << " " << j;
      }
    }
  }
}

TEST(UvRaster, SpotTexelsMapBackToTheirCentres) {
  Charted c = Chart(*ReadMesh(DataPath("meshes/keenan_spot/spot_control_mesh.obj")));
  auto raster = RasterizeUvCharts(c.charts, c.surface, 128);
  ASSERT_TRUE(raster.ok()) << raster.status().message();
  ExpectPlacesMapBack(c.charts, *raster);
  // Spot's UVs reach u < 0 on two faces and v just above 1 on one.
  EXPECT_EQ(raster->tiles.size(), 2u);
  EXPECT_EQ(raster->tiles[0].udim, 1001);
  EXPECT_EQ(raster->tiles[1].udim, 1011);
  EXPECT_FALSE(raster->faces_outside_udim.empty());
  // Five of its faces are flipped in UV space, so their neighbours overlap.
  EXPECT_GT(raster->overlap_texels, 0);
}

TEST(UvRaster, BoxInSixTilesCountsEveryTexelOnce) {
  Charted c = Chart(*ReadMesh(DataPath("uv_maps/udim_box.obj")));
  // Each side covers [0.1, 0.9]^2 of its tile: at N = 40, texel centres 4..35 in each axis.
  auto raster = RasterizeUvCharts(c.charts, c.surface, 40);
  ASSERT_TRUE(raster.ok()) << raster.status().message();
  ASSERT_EQ(raster->tiles.size(), 6u);
  const int udims[] = {1001, 1002, 1003, 1011, 1012, 1013};
  for (int t = 0; t < 6; ++t) {
    EXPECT_EQ(raster->tiles[t].udim, udims[t]);
    int inside = 0;
    for (int j = 0; j < 40; ++j) {
      for (int i = 0; i < 40; ++i) {
        const bool in = raster->tiles[t].places[j * 40 + i].face >= 0;
        inside += in;
        EXPECT_EQ(in, i >= 4 && i <= 35 && j >= 4 && j <= 35) << udims[t] << " " << i << " " << j;
      }
    }
    EXPECT_EQ(inside, 32 * 32);
  }
  EXPECT_EQ(raster->inside, 6 * 32 * 32);
  EXPECT_EQ(raster->overlap_texels, 0);  // faces share UV edges, never area
  EXPECT_TRUE(raster->faces_outside_udim.empty());
  ExpectPlacesMapBack(c.charts, *raster);
}

TEST(UvRaster, NgonSubFacesMapBack) {
  // A triangle beside two quads: its Ptex sub-faces. UVs are the corner, edge
  // midpoints and centroid rule.
  Charted c = Chart(
      ObjMesh("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1.5 0\nv 0 1 0\nv 3 0.5 0\n"
              "vt 0.05 0.05\nvt 0.4 0.05\nvt 0.8 0.05\nvt 0.8 0.45\nvt 0.4 0.7\nvt 0.05 0.45\n"
              "vt 0.95 0.25\n"
              "f 1/1 2/2 5/5 6/6\nf 2/2 3/3 4/4 5/5\nf 3/3 7/7 4/4\n"));
  auto raster = RasterizeUvCharts(c.charts, c.surface, 64);
  ASSERT_TRUE(raster.ok());
  ExpectPlacesMapBack(c.charts, *raster);
  EXPECT_EQ(raster->overlap_texels, 0);
  // The triangle's sub-faces tile it: every texel inside the faces is placed.
  std::int64_t expected = 0;
  for (int j = 0; j < 64; ++j) {
    for (int i = 0; i < 64; ++i) {
      const double x = (i + 0.5) / 64, y = (j + 0.5) / 64;
      // Inside the union of the three faces (convex pieces), away from its border.
      auto inside = [&](std::initializer_list<std::array<double, 2>> poly, double margin) {
        const auto* p = poly.begin();
        const std::size_t m = poly.size();
        for (std::size_t k = 0; k < m; ++k) {
          const auto& a = p[k];
          const auto& b = p[(k + 1) % m];
          const double cross = (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
          const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
          if (cross < margin * len) return false;
        }
        return true;
      };
      const bool in = inside({{0.05, 0.05}, {0.4, 0.05}, {0.4, 0.7}, {0.05, 0.45}}, 1e-3) ||
                      inside({{0.4, 0.05}, {0.8, 0.05}, {0.8, 0.45}, {0.4, 0.7}}, 1e-3) ||
                      inside({{0.8, 0.05}, {0.95, 0.25}, {0.8, 0.45}}, 1e-3);
      if (in) {
        ++expected;
        EXPECT_GE(raster->tiles[0].places[j * 64 + i].face, 0) << i << " " << j;
      }
    }
  }
  EXPECT_GE(raster->inside, expected);
  EXPECT_LE(raster->inside, expected + 64);  // texels within 1e-3 of a border
}

TEST(UvRaster, OverlapsAreReportedAndResolvedByDepth) {
  // Two quads, the second's UVs over the right half of the first's.
  Charted c =
      Chart(ObjMesh("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0\nvt 0.5 1\n"
                    "f 1/1 2/2 3/3 4/4\nf 2/5 5/2 6/3 3/6\n"));
  auto raster = RasterizeUvCharts(c.charts, c.surface, 32);
  ASSERT_TRUE(raster.ok());
  EXPECT_GT(raster->overlap_texels, 0);
  EXPECT_EQ(raster->overlap_faces, (std::vector<std::int32_t>{0, 1}));
  // Near u = 0.75 (the second face's centre, the first face's 0.75) the second face is deeper.
  EXPECT_EQ(raster->tiles[0].places[16 * 32 + 24].face, 1);
  EXPECT_EQ(raster->tiles[0].places[16 * 32 + 4].face, 0);
  ExpectPlacesMapBack(c.charts, *raster);
}

TEST(UvRaster, FacesLeavingTheUdimRangeAreListed) {
  Charted c =
      Chart(ObjMesh("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                    "vt -0.5 0.2\nvt 0.5 0.2\nvt 0.5 0.8\nvt -0.5 0.8\n"
                    "f 1/1 2/2 3/3 4/4\n"));
  auto raster = RasterizeUvCharts(c.charts, c.surface, 16);
  ASSERT_TRUE(raster.ok());
  EXPECT_EQ(raster->faces_outside_udim, (std::vector<std::int32_t>{0}));
  ASSERT_EQ(raster->tiles.size(), 1u);  // its part in tile 1001 only
  EXPECT_EQ(raster->tiles[0].udim, 1001);
  EXPECT_EQ(raster->inside, 8 * 10);
}

TEST(UvRaster, BadResolutionIsAnError) {
  Charted c = Chart(*ReadMesh(DataPath("uv_maps/udim_box.obj")));
  auto raster = RasterizeUvCharts(c.charts, c.surface, 0);
  ASSERT_FALSE(raster.ok());
  EXPECT_EQ(raster.status().message(), "resolution = 0: must be 1..16384");
}

TEST(UvCharts, CageWithoutUvsOnEveryFaceNamesTheFirstFace) {
  Mesh mesh = ObjMesh(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 3 0 0\nv 3 1 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
      "f 1/1 2/2 3/3 4/4\nf 2 5 6 3\nf 5 7 8 6\n");
  auto surface = LimitSurface::Build(mesh);
  ASSERT_TRUE(surface.ok());
  auto charts = PtexUvCharts::Build(mesh, *surface);
  ASSERT_FALSE(charts.ok());
  EXPECT_NE(charts.status().message().find(": face 1 has no texture coordinates"),
            std::string::npos)
      << charts.status().message();
  EXPECT_EQ(charts.status().message().find('\n'), std::string::npos);
}

TEST(UvCharts, CageWithoutAnyUvsIsAnError) {
  Mesh mesh = ObjMesh("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  auto surface = LimitSurface::Build(mesh);
  ASSERT_TRUE(surface.ok());
  auto charts = PtexUvCharts::Build(mesh, *surface);
  ASSERT_FALSE(charts.ok());
  EXPECT_NE(charts.status().message().find("has no texture coordinates"), std::string::npos);
}

TEST(DilateTile, FillsPaddingRingsAndNoFurther) {
  const int n = 9;
  std::vector<float> values(n * n, 0.0f);
  std::vector<std::uint8_t> filled(n * n, 0);
  values[4 * n + 4] = 2.5f;
  filled[4 * n + 4] = 1;
  DilateTile(n, 1, 2, values, filled);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const bool ring = std::abs(i - 4) <= 2 && std::abs(j - 4) <= 2;
      EXPECT_EQ(filled[j * n + i], ring ? 1 : 0) << i << " " << j;
      EXPECT_EQ(values[j * n + i], ring ? 2.5f : 0.0f) << i << " " << j;
    }
  }
}

TEST(DilateTile, TakesTheMeanOfFilledNeighbours) {
  const int n = 3;
  std::vector<float> values = {1, 0, 3, 0, 0, 0, 0, 0, 0};
  std::vector<std::uint8_t> filled = {1, 0, 1, 0, 0, 0, 0, 0, 0};
  DilateTile(n, 1, 1, values, filled);
  EXPECT_FLOAT_EQ(values[1], 2.0f);  // between 1 and 3
  EXPECT_FLOAT_EQ(values[4], 2.0f);  // the centre sees both
  EXPECT_FLOAT_EQ(values[3], 1.0f);
  EXPECT_EQ(filled[7], 0);  // two rings away
}

}  // namespace
}  // namespace dispex
