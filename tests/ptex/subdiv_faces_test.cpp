// ComputeSubdivPtexFaces against OpenSubdiv itself (Far::PtexIndices numbering and
// GetAdjacency) on every cage in tests/data/meshes, and against the worked example of
// docs/ptex.md, "Example: a quad, a pentagon, a quad and a triangle" (fixture
// cc_pentagon_triangle.ptx, written by the reference library).
#include <gtest/gtest.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "ptex_test_util.h"
#include "subdiv_ptex_faces.h"

namespace dispex {
namespace {

namespace fs = std::filesystem;
namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

Mesh PentagonTriangleMesh() {
  Mesh mesh;
  mesh.source = "pentagon_triangle";
  mesh.positions = {{0, 0, 0}, {1, 0, 0},    {2, 0, 0},    {0, 1, 0},      {1, 1, 0},
                    {2, 1, 0}, {0.5f, 2, 0}, {1.5f, 2, 0}, {2.5f, 1.5f, 0}};
  mesh.face_offsets = {0, 4, 9, 13, 16};
  mesh.face_indices = {0, 1, 4, 3, 1, 2, 5, 7, 4, 3, 4, 7, 6, 5, 8, 7};
  return mesh;
}

// The table of docs/ptex.md, "Example: a quad, a pentagon, a quad and a triangle", and of the
// fixture's README.
TEST(PtexSubdivFaces, GuideWorkedExample) {
  StatusOr<SubdivPtexFaces> layout = ComputeSubdivPtexFaces(PentagonTriangleMesh());
  ASSERT_TRUE(layout.ok()) << layout.status().message();
  ASSERT_EQ(layout->num_faces(), 10);
  EXPECT_EQ(layout->first_face,
            (std::vector<PtexFaceId>{PtexFaceId(0), PtexFaceId(1), PtexFaceId(6), PtexFaceId(7),
                                     PtexFaceId(10)}));
  const int table[10][8] = {{-1, 0, 1, 3, 6, 0, -1, 0}, {-1, 0, 2, 2, 5, 1, 0, 1},
                            {-1, 0, 3, 2, 1, 1, -1, 0}, {7, 3, 4, 2, 2, 1, -1, 0},
                            {6, 1, 5, 2, 3, 1, 9, 0},   {0, 1, 1, 2, 4, 1, 6, 1},
                            {0, 2, 5, 3, -1, 0, -1, 0}, {-1, 0, 8, 2, 9, 1, 3, 0},
                            {-1, 0, 9, 2, 7, 1, -1, 0}, {4, 3, 7, 2, 8, 1, -1, 0}};
  const int base[10] = {0, 1, 1, 1, 1, 1, 2, 3, 3, 3};
  const int q[10] = {0, 0, 1, 2, 3, 4, 0, 0, 1, 2};
  for (int f = 0; f < 10; ++f) {
    const PtexFaceInfo& info = layout->faces[std::size_t(f)];
    for (int e = 0; e < 4; ++e) {
      EXPECT_EQ(info.adjfaces[std::size_t(e)], table[f][2 * e]) << "face " << f << " edge " << e;
      EXPECT_EQ(info.adjedges[std::size_t(e)], table[f][2 * e + 1])
          << "face " << f << " edge " << e;
    }
    EXPECT_EQ(info.subface, f != 0 && f != 6) << f;
    EXPECT_EQ(layout->base_face[std::size_t(f)], BaseFaceId(base[f]));
    EXPECT_EQ(layout->subface_index[std::size_t(f)], q[f]);
  }
  // The reference library's file stores the same adjacency.
  StatusOr<PtexFile> file = PtexFile::Open(ptex_test::FixturePath("cc_pentagon_triangle.ptx"));
  ASSERT_TRUE(file.ok());
  for (int f = 0; f < 10; ++f) {
    const PtexFaceInfo& a = layout->faces[std::size_t(f)];
    const PtexFaceInfo& b = file->face_info(PtexFaceId(f));
    EXPECT_EQ(a.adjfaces, b.adjfaces) << f;
    EXPECT_EQ(a.adjedges, b.adjedges) << f;
    EXPECT_EQ(a.subface, b.subface) << f;
  }
}

// OpenSubdiv's answer for a mesh.
struct OsdPtex {
  int num_faces = 0;
  std::vector<int> first;
  std::vector<std::array<int, 8>> adjacency;  // per Ptex face: (face, edge) x 4
};

std::unique_ptr<Far::TopologyRefiner> MakeRefiner(const Mesh& mesh) {
  std::vector<int> counts(mesh.num_faces());
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) counts[f] = mesh.face_size(f);
  Far::TopologyDescriptor desc;
  desc.numVertices = static_cast<int>(mesh.num_vertices());
  desc.numFaces = static_cast<int>(mesh.num_faces());
  desc.numVertsPerFace = counts.data();
  desc.vertIndicesPerFace = mesh.face_indices.data();
  Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  return std::unique_ptr<Far::TopologyRefiner>(
      Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
}

OsdPtex OpenSubdivPtex(const Far::TopologyRefiner& refiner, const Mesh& mesh) {
  Far::PtexIndices indices(refiner);
  OsdPtex out;
  out.num_faces = indices.GetNumFaces();
  out.adjacency.resize(std::size_t(out.num_faces));
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const int first = indices.GetFaceId(static_cast<int>(f));
    out.first.push_back(first);
    const int n = mesh.face_size(f);
    for (int q = 0; q < (n == 4 ? 1 : n); ++q) {
      int faces[4], edges[4];
      indices.GetAdjacency(refiner, static_cast<int>(f), q, faces, edges);
      for (int e = 0; e < 4; ++e) {
        out.adjacency[std::size_t(first + q)][std::size_t(2 * e)] = faces[e];
        out.adjacency[std::size_t(first + q)][std::size_t(2 * e + 1)] = edges[e];
      }
    }
  }
  return out;
}

std::vector<fs::path> Cages() {
  std::vector<fs::path> paths;
  for (const auto& entry :
       fs::recursive_directory_iterator(fs::path(DISPEX_TEST_DATA_DIR) / "meshes")) {
    if (entry.path().extension() == ".obj") paths.push_back(entry.path());
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

TEST(PtexSubdivFaces, MatchesOpenSubdivOnEveryCage) {
  const std::vector<fs::path> cages = Cages();
  ASSERT_GE(cages.size(), 30u);
  int checked = 0, with_ngons = 0, with_borders = 0, with_nonmanifold = 0;
  for (const fs::path& path : cages) {
    SCOPED_TRACE(path.filename().string());
    StatusOr<Mesh> mesh = ReadObj(path.string());
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    std::unique_ptr<Far::TopologyRefiner> refiner = MakeRefiner(*mesh);
    ASSERT_NE(refiner, nullptr) << "OpenSubdiv rejected the cage";
    const OsdPtex osd = OpenSubdivPtex(*refiner, *mesh);
    StatusOr<SubdivPtexFaces> mine = ComputeSubdivPtexFaces(*mesh);
    ASSERT_TRUE(mine.ok()) << mine.status().message();
    ASSERT_EQ(mine->num_faces(), osd.num_faces);
    for (std::size_t f = 0; f < mesh->num_faces(); ++f) {
      ASSERT_EQ(mine->first_face[f].value, osd.first[f]) << "base face " << f;
    }
    EXPECT_EQ(mine->first_face.back().value, osd.num_faces);
    bool ngon = false, border = false;
    for (int p = 0; p < osd.num_faces; ++p) {
      const PtexFaceInfo& info = mine->faces[std::size_t(p)];
      const BaseFaceId base = mine->base_face[std::size_t(p)];
      ASSERT_EQ(info.subface, mesh->face_size(std::size_t(base.value)) != 4) << "ptex face " << p;
      ngon |= info.subface;
      for (int e = 0; e < 4; ++e) {
        const int face = osd.adjacency[std::size_t(p)][std::size_t(2 * e)];
        const int edge = osd.adjacency[std::size_t(p)][std::size_t(2 * e + 1)];
        ASSERT_EQ(info.adjfaces[std::size_t(e)], face) << "ptex face " << p << " edge " << e;
        ASSERT_EQ(info.adjedges[std::size_t(e)], edge) << "ptex face " << p << " edge " << e;
        border |= face < 0;
      }
    }
    for (int e = 0; e < refiner->GetLevel(0).GetNumEdges(); ++e) {
      if (refiner->GetLevel(0).GetEdgeFaces(e).size() > 2) {
        ++with_nonmanifold;
        break;
      }
    }
    with_ngons += ngon;
    with_borders += border;
    ++checked;
  }
  // The set covers what the adjacency rules distinguish.
  EXPECT_EQ(checked, static_cast<int>(cages.size()));
  EXPECT_GE(with_ngons, 3);
  EXPECT_GE(with_borders, 3);
  EXPECT_GE(with_nonmanifold, 1);
}

TEST(PtexSubdivFaces, NonManifoldEdgesHaveNoNeighbour) {
  // Three quads around the edge (0, 1).
  Mesh mesh;
  mesh.positions.resize(8);
  mesh.face_offsets = {0, 4, 8, 12};
  mesh.face_indices = {0, 1, 2, 3, 1, 0, 4, 5, 0, 1, 6, 7};
  StatusOr<SubdivPtexFaces> layout = ComputeSubdivPtexFaces(mesh);
  ASSERT_TRUE(layout.ok());
  for (int f = 0; f < 3; ++f) EXPECT_EQ(layout->faces[std::size_t(f)].adjfaces[0], -1);
  std::unique_ptr<Far::TopologyRefiner> refiner = MakeRefiner(mesh);
  ASSERT_NE(refiner, nullptr);
  const OsdPtex osd = OpenSubdivPtex(*refiner, mesh);
  for (int f = 0; f < 3; ++f) {
    for (int e = 0; e < 4; ++e) {
      EXPECT_EQ(layout->faces[std::size_t(f)].adjfaces[std::size_t(e)],
                osd.adjacency[std::size_t(f)][std::size_t(2 * e)]);
    }
  }
}

TEST(PtexSubdivFaces, InvalidMeshes) {
  Mesh mesh;
  mesh.source = "cage.obj";
  mesh.positions.resize(4);
  mesh.face_offsets = {0, 2};
  mesh.face_indices = {0, 1};
  StatusOr<SubdivPtexFaces> r = ComputeSubdivPtexFaces(mesh);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(),
            "cage.obj: face 0 has 2 vertices; Catmull-Clark Ptex faces need at least 3");
  mesh.face_offsets = {0, 3};
  mesh.face_indices = {0, 1, 9};
  r = ComputeSubdivPtexFaces(mesh);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "cage.obj: face 0: vertex index 9 out of range (4 vertices)");
  mesh.face_offsets = {0, 5};
  r = ComputeSubdivPtexFaces(mesh);
  ASSERT_FALSE(r.ok());
}

}  // namespace
}  // namespace dispex
