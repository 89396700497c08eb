// verify's edge steps on maps whose steps are known by construction: a flat map has none; one
// face raised by 3 tau steps by exactly 3 tau per face and not at all through the cross-face
// filter (equal resolutions blend); fine detail beside coarse neighbours steps through the
// filter; edges on infinitely sharp creases are counted and left out.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "../extract/e2e_support.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/verify.h"

namespace dispex {
namespace {

using testing::DataPath;

constexpr double kTau = 1e-3;

// Writes a map of the cage with every face from `fill(face, info)`: info's resolution is set by
// fill, adjacency comes from the limit surface (PtexFaceTable).
template <class Fill>
void WriteMap(const std::string& cage, const std::string& out, Fill fill) {
  auto mesh = ReadMesh(cage);
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  auto surface = LimitSurface::Build(*mesh);
  ASSERT_TRUE(surface.ok()) << surface.status().message();
  auto writer = PtexWriter::Create(out, PtexWriterOptions{}, surface->num_ptex_faces());
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  const std::vector<PtexFaceInfo> table = PtexFaceTable(*surface);
  for (int f = 0; f < surface->num_ptex_faces(); ++f) {
    PtexFaceInfo info = table[std::size_t(f)];
    std::vector<float> texels = fill(f, info);
    ASSERT_TRUE(writer->SetFace(PtexFaceId(f), info, texels).ok());
  }
  ASSERT_TRUE(writer->Finish().ok());
}

VerifyReport VerifyEdges(const std::string& cage, const std::string& map, double max_step) {
  VerifyOptions options;
  options.base_path = cage;
  options.map_path = map;
  options.tolerance = kTau;
  options.max_edge_step = max_step;
  auto report = Verify(options);
  EXPECT_TRUE(report.ok()) << report.status().message();
  return report.ok() ? *report : VerifyReport{};
}

class EdgeCheckTest : public ::testing::Test {
 protected:
  testing::TempDir dir_;
};

TEST_F(EdgeCheckTest, FlatMapHasNoSteps) {
  const std::string cage = DataPath("meshes/opensubdiv/catmark_cube.obj");
  const std::string map = dir_ / "flat.ptx";
  WriteMap(cage, map, [](int, PtexFaceInfo& info) {
    info.ulog2 = info.vlog2 = 2;
    return std::vector<float>(16, 0.5f);
  });
  const VerifyReport r = VerifyEdges(cage, map, 0.1);
  EXPECT_TRUE(r.measured_edges);
  EXPECT_EQ(r.edges, 12u);
  EXPECT_EQ(r.edge_per_face.max, 0.0);
  EXPECT_EQ(r.edge_across_faces.max, 0.0);
  EXPECT_TRUE(r.passed) << r.failure;
}

TEST_F(EdgeCheckTest, RaisedFaceStepsPerFaceOnly) {
  const std::string cage = DataPath("meshes/opensubdiv/catmark_cube.obj");
  const std::string map = dir_ / "raised.ptx";
  WriteMap(cage, map, [](int f, PtexFaceInfo& info) {
    info.ulog2 = info.vlog2 = 2;
    return std::vector<float>(16, f == 2 ? float(3 * kTau) : 0.0f);
  });
  const VerifyReport r = VerifyEdges(cage, map, 2);
  EXPECT_NEAR(r.edge_per_face.max, 3 * kTau, 1e-9);
  EXPECT_NEAR(r.edge_across_faces.max, 0.0, 1e-9);
  EXPECT_FALSE(r.passed);
  EXPECT_NE(r.failure.find("per-face reader"), std::string::npos) << r.failure;
  ASSERT_FALSE(r.worst_edges.empty());
  const auto& w = r.worst_edges.front();
  EXPECT_TRUE(w.face == 2 || w.neighbour == 2) << w.face << " " << w.neighbour;
  EXPECT_TRUE(VerifyEdges(cage, map, 3.5).passed);
}

// Face 0 holds columns alternating +-2 tau at 8 x 8; its neighbours, 1 x 1 zeros, read it
// box-reduced to one texel (0) while face 0 reads its own outer column: a step of tau at
// face 0's edges across its columns (half the kernel on +-2 tau, half on 0).
TEST_F(EdgeCheckTest, DetailBesideCoarseNeighboursStepsThroughTheFilter) {
  const std::string cage = DataPath("meshes/opensubdiv/catmark_cube.obj");
  const std::string map = dir_ / "detail.ptx";
  WriteMap(cage, map, [](int f, PtexFaceInfo& info) {
    if (f != 0) return std::vector<float>(1, 0.0f);
    info.ulog2 = info.vlog2 = 3;
    std::vector<float> t(64);
    for (int j = 0; j < 8; ++j) {
      for (int i = 0; i < 8; ++i) t[std::size_t(j * 8 + i)] = float((i % 2 ? 2 : -2) * kTau);
    }
    return t;
  });
  const VerifyReport r = VerifyEdges(cage, map, 0.5);
  EXPECT_NEAR(r.edge_across_faces.max, kTau, 1e-9);
  EXPECT_FALSE(r.passed);
  EXPECT_TRUE(VerifyEdges(cage, map, 2.5).passed);
}

TEST_F(EdgeCheckTest, SharpCreasesAreCountedNotMeasured) {
  const std::string cage = DataPath("meshes/opensubdiv/catmark_cubes_infsharp.obj");
  const std::string map = dir_ / "creased.ptx";
  WriteMap(cage, map, [](int f, PtexFaceInfo&) { return std::vector<float>(1, float(f) * 1e-3f); });
  const VerifyReport r = VerifyEdges(cage, map, 0);
  EXPECT_EQ(r.crease_edges, 17u);
  EXPECT_GT(r.edges, r.crease_edges);
  EXPECT_EQ(r.edge_per_face.count, r.edge_across_faces.count);
}

}  // namespace
}  // namespace dispex
