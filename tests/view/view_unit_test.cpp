// The parts of a review page: its encodings (base64, fixed point, safe text), the surface grid
// (points shared where faces meet, the count of a closed mesh), the sculpt's decimation.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/view.h"
#include "view/decimate.h"
#include "view/embedded_assets.h"
#include "view/page_data.h"
#include "view/surface_grid.h"

namespace dispex::view {
namespace {

std::string DataPath(const std::string& relative) {
  return (std::filesystem::path(DISPEX_TEST_DATA_DIR) / relative).string();
}

TEST(ViewPageData, Base64OfKnownBytes) {
  auto of = [](std::string_view text) {
    return Base64({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  };
  EXPECT_EQ(of(""), "");
  EXPECT_EQ(of("f"), "Zg==");
  EXPECT_EQ(of("fo"), "Zm8=");
  EXPECT_EQ(of("foo"), "Zm9v");
  EXPECT_EQ(of("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64Of(std::vector<std::uint16_t>{0x0201, 0xFFFE}), "AQL+/w==");
}

// The page's unpackPoints (page/viewer.js), in C++.
std::vector<double> Unpack(const std::vector<std::uint32_t>& words, const double box[6]) {
  std::vector<double> out;
  for (std::size_t i = 0; i < words.size() / 2; ++i) {
    const std::uint32_t lo = words[2 * i], hi = words[2 * i + 1];
    const std::uint32_t q[3] = {lo & 0x1FFFFF, (lo >> 21) | ((hi & 0x3FF) << 11), hi >> 10};
    for (int c = 0; c < 3; ++c) out.push_back(box[c] + q[c] * (box[3 + c] - box[c]) / 2097151.0);
  }
  return out;
}

TEST(ViewPageData, PointsKeepTwentyOneBits) {
  std::vector<Float3> points = {{-1, 2, 3}, {4, -5, 6.5f}, {0.125f, 0, -7}, {1e-3f, 1, 2}};
  double box[6];
  const auto words = PackPoints(points, box);
  ASSERT_EQ(words.size(), 8u);
  EXPECT_EQ(box[0], -1);
  EXPECT_EQ(box[5], 6.5);
  const auto back = Unpack(words, box);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double xyz[3] = {points[i].x, points[i].y, points[i].z};
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(back[3 * i + c], xyz[c], (box[3 + c] - box[c]) / 2097151.0 * 0.51)
          << "point " << i << " coordinate " << c;
    }
  }
  // A box of no extent along an axis.
  const auto flat = PackPoints(std::vector<Float3>{{1, 1, 1}, {1, 2, 1}}, box);
  EXPECT_EQ(Unpack(flat, box)[3], 1);
}

TEST(ViewPageData, ValuesAsSixteenBits) {
  double scale = 0;
  const auto q = QuantizeValues(std::vector<float>{0.5f, -1.0f, 0.25f, 0}, scale);
  EXPECT_DOUBLE_EQ(scale, 1.0 / 32767);
  EXPECT_EQ(q, (std::vector<std::int16_t>{16384, -32767, 8192, 0}));
  EXPECT_EQ(QuantizeValues(std::vector<float>{0, 0}, scale), (std::vector<std::int16_t>{0, 0}));
  EXPECT_EQ(scale, 0);
}

TEST(ViewPageData, TextMadeSafe) {
  EXPECT_EQ(EscapeHtml("<a href=\"x\">&'</a>"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;&lt;/a&gt;");
  const std::string json = ScriptSafeJson(R"({"name":"</script><!--"})");
  EXPECT_EQ(json.find('<'), std::string::npos);
  EXPECT_NE(json.find("\\u003c/script>"), std::string::npos);
}

TEST(ViewEmbeddedAssets, PageAndThreeJsAreIn) {
  const std::string_view three = EmbeddedAsset(Asset::kThreeJs);
  EXPECT_GT(three.size(), 100'000u);
  EXPECT_NE(three.find("REVISION=\"111\""), std::string_view::npos) << "Debian's libjs-three r111";
  EXPECT_NE(EmbeddedAsset(Asset::kOrbitControlsJs).find("OrbitControls"), std::string_view::npos);
  const std::string_view page = EmbeddedAsset(Asset::kPageHtml);
  for (const char* marker : {"@TITLE@", "@CSS@", "@DATA@", "@THREE@", "@ORBIT_CONTROLS@",
                             "@VIEWER@", "Content-Security-Policy"}) {
    EXPECT_NE(page.find(marker), std::string_view::npos) << marker;
  }
  EXPECT_NE(EmbeddedAsset(Asset::kViewerJs).find("dispexReady"), std::string_view::npos);
  EXPECT_NE(EmbeddedAsset(Asset::kIndexHtml).find("@ROWS@"), std::string_view::npos);
  // Nothing embedded ends a script element early.
  for (Asset a : {Asset::kThreeJs, Asset::kOrbitControlsJs, Asset::kViewerJs}) {
    EXPECT_EQ(EmbeddedAsset(a).find("</script"), std::string_view::npos);
  }
}

// A displacement of `h` along the normal everywhere.
class Constant final : public MapDisplacement {
 public:
  explicit Constant(float h) : h_(h) {}
  void Displace(PtexFaceId, std::span<const float>, const LimitEvaluator::Frames& frames,
                std::span<float> d, std::span<float> value) const override {
    for (std::size_t j = 0; j < value.size(); ++j) {
      for (std::size_t c = 0; c < 3; ++c) d[3 * j + c] = h_ * frames.normals[3 * j + c];
      value[j] = h_;
    }
  }

 private:
  float h_;
};

struct Built {
  Mesh cage;
  LimitSurface surface;
  SurfaceGrid grid;
};
Built Build(const std::string& cage_path, int grid, float h = 0) {
  auto cage = ReadMesh(DataPath(cage_path));
  EXPECT_TRUE(cage.ok()) << cage.status().message();
  auto surface = LimitSurface::Build(*cage);
  EXPECT_TRUE(surface.ok()) << surface.status().message();
  auto faces = PtexFaceTable(*surface);
  auto built = BuildSurfaceGrid(*surface, faces, grid, Constant(h), "map.ptx");
  EXPECT_TRUE(built.ok()) << built.status().message();
  return {std::move(*cage), std::move(*surface), std::move(*built)};
}

std::int64_t Quads(const SurfaceGrid& g) {
  std::int64_t q = 0;
  for (std::uint16_t n : g.quads) q += std::int64_t(n) * n;
  return q;
}

TEST(ViewSurfaceGrid, ClosedMeshSharesEveryBorderPoint) {
  // A closed quad mesh of genus 0 has Q + 2 vertices (Euler): every point on a face border is
  // shared with the faces across, corners at extraordinary vertices too.
  for (int grid : {2, 4, 10}) {
    Built b = Build("meshes/opensubdiv/catmark_cube.obj", grid);
    EXPECT_EQ(std::int64_t(b.grid.limit.size()), Quads(b.grid) + 2) << "grid " << grid;
    EXPECT_EQ(b.grid.triangles, 2 * Quads(b.grid));
    EXPECT_EQ(Quads(b.grid), 6 * grid * grid);
  }
  // n-gons: a pyramid's triangles are three sub-faces of grid / 2 quads a side each.
  Built pyramid = Build("meshes/opensubdiv/catmark_pyramid.obj", 8);
  EXPECT_EQ(std::int64_t(pyramid.grid.limit.size()), Quads(pyramid.grid) + 2);
  int sub_faces = 0;
  for (std::size_t f = 0; f < pyramid.grid.quads.size(); ++f)
    sub_faces += pyramid.grid.quads[f] == 4;
  EXPECT_GT(sub_faces, 0);
  // A torus (genus 1): Q vertices.
  Built torus = Build("meshes/opensubdiv/catmark_torus.obj", 6);
  EXPECT_EQ(std::int64_t(torus.grid.limit.size()), Quads(torus.grid));
}

TEST(ViewSurfaceGrid, PointsLieOnTheLimitSurfaceDisplacedAlongTheNormal) {
  const float h = 0.05f;
  Built b = Build("meshes/opensubdiv/catmark_cube.obj", 4, h);
  // Each face's interior points come first, face by face, row by row: face 0's first is its
  // grid point (1, 1), at (u, v) = (1/4, 1/4).
  LimitEvaluator evaluator(b.surface);
  std::vector<float> uv = {0.25f, 0.25f}, p(3), n(3);
  ASSERT_TRUE(evaluator.EvaluatePoints(PtexFaceId(0), uv, p, n).ok());
  EXPECT_NEAR(b.grid.limit[0].x, p[0], 1e-6);
  EXPECT_NEAR(b.grid.limit[0].y, p[1], 1e-6);
  EXPECT_NEAR(b.grid.limit[0].z, p[2], 1e-6);
  EXPECT_NEAR(b.grid.displacement[0].x, h * n[0], 1e-6);
  EXPECT_NEAR(b.grid.displacement[0].z, h * n[2], 1e-6);
  for (float v : b.grid.value) EXPECT_FLOAT_EQ(v, h);
  // The border table: per face (n + 1)^2 - (n - 1)^2 = 4n entries.
  EXPECT_EQ(b.grid.border.size(), 6u * 16u);
  std::set<std::uint32_t> ids(b.grid.border.begin(), b.grid.border.end());
  EXPECT_EQ(ids.size(), b.grid.limit.size() - 6u * 9u);  // every border vertex used
}

TEST(ViewSurfaceGrid, FaceQuadsFollowTheBudget) {
  auto cage = ReadMesh(DataPath("meshes/opensubdiv/catmark_pyramid.obj"));
  ASSERT_TRUE(cage.ok());
  auto surface = LimitSurface::Build(*cage);
  ASSERT_TRUE(surface.ok());
  const auto quads = FaceQuads(*surface, 6);
  std::int64_t expected = 0;
  for (int f = 0; f < surface->num_ptex_faces(); ++f) {
    const bool sub = surface->num_ptex_faces(surface->base_face(PtexFaceId(f))) != 1;
    EXPECT_EQ(quads[static_cast<std::size_t>(f)], sub ? 3 : 6);
    expected += sub ? 16 : 49;
  }
  EXPECT_EQ(GridPoints(quads), expected);
}

Mesh GridMesh(int n) {
  Mesh m;
  m.source = "grid";
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      m.positions.push_back({float(i) / n, float(j) / n, 0.1f * std::sin(7.0f * i / n)});
    }
  }
  m.face_offsets.push_back(0);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int v = j * (n + 1) + i;
      for (int k : {v, v + 1, v + n + 2, v + n + 1}) m.face_indices.push_back(k);
      m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_indices.size()));
    }
  }
  m.positions.reserve(m.positions.size() + 1);
  return m;
}

TEST(ViewDecimate, SmallMeshWholeInTriangles) {
  Mesh m = GridMesh(4);
  DecimatedMesh d = DecimateByClustering(m, 1000);
  EXPECT_EQ(d.cell, 0);
  EXPECT_EQ(d.positions.size(), m.num_vertices());
  EXPECT_EQ(d.triangles.size(), 3u * 2u * 16u);
  EXPECT_EQ(d.triangles[0], 0u);
  EXPECT_EQ(d.triangles[1], 1u);
  EXPECT_EQ(d.triangles[2], 6u);
}

TEST(ViewDecimate, LargeMeshWithinBudget) {
  Mesh m = GridMesh(300);  // 90,601 vertices
  for (std::int64_t budget : {20000, 5000, 300}) {
    DecimatedMesh d = DecimateByClustering(m, budget);
    EXPECT_GT(d.cell, 0);
    EXPECT_LE(std::int64_t(d.positions.size()), budget);
    EXPECT_GT(std::int64_t(d.positions.size()), budget / 4) << "not far below the budget";
    std::set<std::array<std::uint32_t, 3>> seen;
    for (std::size_t t = 0; t < d.triangles.size(); t += 3) {
      std::array<std::uint32_t, 3> tri = {d.triangles[t], d.triangles[t + 1], d.triangles[t + 2]};
      EXPECT_TRUE(tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2]);
      for (std::uint32_t v : tri) ASSERT_LT(v, d.positions.size());
      std::sort(tri.begin(), tri.end());
      EXPECT_TRUE(seen.insert(tri).second) << "a triangle twice";
    }
    for (const Float3& p : d.positions) {
      EXPECT_TRUE(p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1);
    }
    // The same result again (deterministic).
    DecimatedMesh again = DecimateByClustering(m, budget);
    EXPECT_EQ(again.triangles, d.triangles);
  }
}

TEST(ViewOptions, RangesNamed) {
  ViewPageOptions o;
  o.base_path = "base.obj";
  o.map_path = "map.ptx";
  EXPECT_TRUE(ValidateViewPageOptions(o).ok());
  auto message = [&](auto change) {
    ViewPageOptions c = o;
    change(c);
    const Status st = ValidateViewPageOptions(c);
    EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
    return st.message();
  };
  EXPECT_EQ(message([](ViewPageOptions& c) { c.max_vertices = 10; }),
            "max_vertices = 10: must be 1000..50000000");
  EXPECT_EQ(message([](ViewPageOptions& c) { c.grid = 300; }),
            "grid = 300: must be 0 (automatic) or 1..256");
  EXPECT_EQ(message([](ViewPageOptions& c) { c.max_grid = 0; }), "max_grid = 0: must be 1..256");
  EXPECT_EQ(message([](ViewPageOptions& c) { c.max_sculpt_vertices = -1; }),
            "max_sculpt_vertices = -1: must be 0..10000000");
  EXPECT_EQ(message([](ViewPageOptions& c) { c.map_path.clear(); }), "map_path: empty");
}

TEST(ViewIndex, ListsPagesEscaped) {
  const std::string html = MakeViewIndex(
      "batch <1>", {{"spot", "spot.html", "ok", "scalar map"}, {"a&b", "", "failed", "<boom>"}});
  EXPECT_NE(html.find("<a href=\"spot.html\">spot</a>"), std::string::npos);
  EXPECT_NE(html.find("batch &lt;1&gt;"), std::string::npos);
  EXPECT_NE(html.find("a&amp;b"), std::string::npos);
  EXPECT_NE(html.find("&lt;boom&gt;"), std::string::npos);
  EXPECT_EQ(html.find('@'), std::string::npos) << "every marker replaced";
}

}  // namespace
}  // namespace dispex::view
