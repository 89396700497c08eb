// LimitSurface: building from a cage (errors named), Ptex numbering and adjacency against
// Far::PtexIndices on an independently built refiner, holes, infinitely sharp edges.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <cmath>
#include <limits>

#include "dispex/subdiv.h"
#include "subdiv_test_util.h"

namespace dispex {
namespace {

using subdiv_test::MakeCube;
using subdiv_test::MakeGrid;
using subdiv_test::MakeMesh;
using subdiv_test::MakePentagonFan;
using ::testing::HasSubstr;

std::string BuildError(const Mesh& mesh, const SubdivOptions& options = {}) {
  StatusOr<LimitSurface> s = LimitSurface::Build(mesh, options);
  return s.ok() ? std::string("(built)") : s.status().message();
}

TEST(LimitSurfaceTest, CubeCounts) {
  StatusOr<LimitSurface> s = LimitSurface::Build(MakeCube());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->num_vertices(), 8);
  EXPECT_EQ(s->num_base_faces(), 6);
  EXPECT_EQ(s->num_ptex_faces(), 6);
  for (int f = 0; f < 6; ++f) {
    EXPECT_EQ(s->first_ptex_face(BaseFaceId(f)), PtexFaceId(f));
    EXPECT_EQ(s->base_face(PtexFaceId(f)), BaseFaceId(f));
    EXPECT_EQ(s->sub_face(PtexFaceId(f)), 0);
    EXPECT_FALSE(s->is_hole(PtexFaceId(f)));
  }
  EXPECT_TRUE(s->inf_sharp_edges().empty());
  EXPECT_EQ(s->stats().approx_level_smooth, 10);
  EXPECT_EQ(s->stats().approx_level_sharp, 10);
}

// Ptex ids and adjacency equal Far::PtexIndices on a refiner built from a TopologyDescriptor.
void ExpectPtexMatchesFar(const Mesh& mesh) {
  namespace Far = OpenSubdiv::Far;
  StatusOr<LimitSurface> s = LimitSurface::Build(mesh);
  ASSERT_TRUE(s.ok()) << s.status().message();
  std::vector<int> sizes;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) sizes.push_back(mesh.face_size(f));
  Far::TopologyDescriptor desc;
  desc.numVertices = static_cast<int>(mesh.num_vertices());
  desc.numFaces = static_cast<int>(mesh.num_faces());
  desc.numVertsPerFace = sizes.data();
  desc.vertIndicesPerFace = mesh.face_indices.data();
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Create(desc));
  ASSERT_NE(refiner, nullptr);
  Far::PtexIndices ptex(*refiner);
  ASSERT_EQ(s->num_ptex_faces(), ptex.GetNumFaces());
  for (int f = 0; f < desc.numFaces; ++f) {
    const int n = sizes[f];
    EXPECT_EQ(s->first_ptex_face(BaseFaceId(f)).value, ptex.GetFaceId(f));
    ASSERT_EQ(s->num_ptex_faces(BaseFaceId(f)), n == 4 ? 1 : n);
    EXPECT_EQ(s->base_face_size(BaseFaceId(f)), n);
    for (int k = 0; k < s->num_ptex_faces(BaseFaceId(f)); ++k) {
      const PtexFaceId p(ptex.GetFaceId(f) + k);
      EXPECT_EQ(s->base_face(p), BaseFaceId(f));
      EXPECT_EQ(s->sub_face(p), k);
      int adj_faces[4], adj_edges[4];
      ptex.GetAdjacency(*refiner, f, k, adj_faces, adj_edges);
      for (int e = 0; e < 4; ++e) {
        EXPECT_EQ(s->adjacency(p).faces[e].value, adj_faces[e]) << "ptex " << p.value << " e" << e;
        EXPECT_EQ(s->adjacency(p).edges[e], adj_edges[e]) << "ptex " << p.value << " e" << e;
      }
    }
  }
}

TEST(LimitSurfaceTest, PtexNumberingMatchesFarOnPentagonFan) {
  const Mesh fan = MakePentagonFan();
  ExpectPtexMatchesFar(fan);
  StatusOr<LimitSurface> s = LimitSurface::Build(fan);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->num_ptex_faces(), 10);  // 5 sub-faces + 5 quads
  EXPECT_EQ(s->base_face(PtexFaceId(3)), BaseFaceId(0));
  EXPECT_EQ(s->sub_face(PtexFaceId(3)), 3);
  EXPECT_EQ(s->first_ptex_face(BaseFaceId(2)), PtexFaceId(6));
  // Sub-face 1 of the pentagon: edge 1 meets sub-face 2's edge 2, edge 2 meets sub-face 0's
  // edge 1, edge 0 meets the quad across pentagon edge 1 (base face 2 = Ptex 6).
  const PtexAdjacency& a = s->adjacency(PtexFaceId(1));
  EXPECT_EQ(a.faces[1], PtexFaceId(2));
  EXPECT_EQ(a.edges[1], 2);
  EXPECT_EQ(a.faces[2], PtexFaceId(0));
  EXPECT_EQ(a.edges[2], 1);
  EXPECT_EQ(a.faces[0], PtexFaceId(6));
  EXPECT_EQ(s->stats().irregular_base_faces, 1);
}

TEST(LimitSurfaceTest, PtexNumberingMatchesFarOnMixedFaces) {
  // Two quads, a triangle, a pentagon and a hexagon sharing edges (an open sheet).
  const Mesh mesh = MakeMesh(
      {{0, 0, 0},
       {1, 0, 0},
       {2, 0, 0},
       {0, 1, 0},
       {1, 1, 0.2f},
       {2, 1, 0},
       {3, 0.5f, 0},
       {0, 2, 0.1f},
       {2, 2, 0},
       {4, 1, 0},
       {4, 2.5f, 0.3f},
       {3, 3, 0}},
      {{0, 1, 4, 3}, {1, 2, 5, 4}, {2, 6, 5}, {3, 4, 5, 8, 7}, {5, 6, 9, 10, 11, 8}}, "mixed");
  ExpectPtexMatchesFar(mesh);
  StatusOr<LimitSurface> s = LimitSurface::Build(mesh);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->num_ptex_faces(), 1 + 1 + 3 + 5 + 6);
  EXPECT_EQ(s->first_ptex_face(BaseFaceId(4)), PtexFaceId(10));
  EXPECT_EQ(s->stats().irregular_base_faces, 3);
}

TEST(LimitSurfaceTest, HolesHaveNoSurface) {
  Mesh cube = MakeCube();
  cube.tags.holes.push_back(BaseFaceId(2));
  StatusOr<LimitSurface> s = LimitSurface::Build(cube);
  ASSERT_TRUE(s.ok()) << s.status().message();
  for (int f = 0; f < 6; ++f) EXPECT_EQ(s->is_hole(PtexFaceId(f)), f == 2) << f;
  EXPECT_EQ(s->stats().hole_ptex_faces, 1);
  LimitEvaluator eval(*s);
  std::vector<float> p(12), n(12);
  Status st = eval.EvaluateGrid(PtexFaceId(2), 2, 2, p, n);
  EXPECT_FALSE(st.ok());
  EXPECT_THAT(st.message(), HasSubstr("Ptex face 2"));
  EXPECT_THAT(st.message(), HasSubstr("no limit surface"));
  EXPECT_TRUE(eval.EvaluateGrid(PtexFaceId(3), 2, 2, p, n).ok());
}

TEST(LimitSurfaceTest, BoundaryNoneLeavesBoundaryFacesWithoutSurface) {
  Mesh grid = MakeGrid(4);
  grid.tags.boundary = BoundaryInterpolation::kNone;
  StatusOr<LimitSurface> s = LimitSurface::Build(grid);
  ASSERT_TRUE(s.ok()) << s.status().message();
  int with_surface = 0;
  for (int f = 0; f < s->num_ptex_faces(); ++f) with_surface += !s->is_hole(PtexFaceId(f));
  EXPECT_EQ(with_surface, 4);  // the 2x2 interior faces
}

TEST(LimitSurfaceTest, InfinitelySharpEdgesAreReported) {
  Mesh cube = MakeCube();
  cube.tags.creases.push_back({VertexId(0), VertexId(1), 10.0f});
  cube.tags.creases.push_back({VertexId(2), VertexId(3), 9.5f});   // semi-sharp: not listed
  cube.tags.creases.push_back({VertexId(3), VertexId(5), 25.0f});  // >= 10: infinite
  StatusOr<LimitSurface> s = LimitSurface::Build(cube);
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->inf_sharp_edges().size(), 2u);
  EXPECT_EQ(s->stats().inf_sharp_edges, 2);
  EXPECT_EQ(s->stats().approx_level_sharp, 10);
  // Boundary edges are infinitely sharp in OpenSubdiv but have one normal: not listed.
  StatusOr<LimitSurface> g = LimitSurface::Build(MakeGrid(3));
  ASSERT_TRUE(g.ok());
  EXPECT_TRUE(g->inf_sharp_edges().empty());
}

TEST(LimitSurfaceTest, SemiSharpCreasesRaiseTheSharpLevel) {
  Mesh cube = MakeCube();
  cube.tags.creases.push_back({VertexId(0), VertexId(1), 7.2f});
  SubdivOptions six;
  six.approx_level_smooth = 6;
  StatusOr<LimitSurface> s = LimitSurface::Build(cube, six);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->options().approx_level_smooth, 6);
  EXPECT_EQ(s->options().approx_level_sharp, 8);  // ceil(7.2)
  SubdivOptions fixed = six;
  fixed.approx_level_sharp = 7;
  StatusOr<LimitSurface> t = LimitSurface::Build(cube, fixed);
  ASSERT_TRUE(t.ok());
  EXPECT_EQ(t->options().approx_level_sharp, 7);
  StatusOr<LimitSurface> d = LimitSurface::Build(cube);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->options().approx_level_sharp, 10);
}

TEST(LimitSurfaceErrorsTest, EmptyAndMalformedArrays) {
  Mesh empty;
  empty.source = "empty.obj";
  EXPECT_EQ(BuildError(empty), "empty.obj: the cage has no faces");

  Mesh bad = MakeCube();
  bad.face_offsets.back() = 23;
  EXPECT_THAT(BuildError(bad), HasSubstr("face offsets do not span the 24 face indices"));
}

TEST(LimitSurfaceErrorsTest, BadFaces) {
  Mesh two = MakeMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 1, 2}, {0, 1}}, "two.obj");
  EXPECT_EQ(BuildError(two), "two.obj: face 1 has 2 vertices; a face needs at least 3");

  Mesh range = MakeMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 1, 3}}, "range.obj");
  EXPECT_EQ(BuildError(range), "range.obj: face 0: vertex index 3 out of range (3 vertices)");

  Mesh negative = MakeMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, -1, 2}}, "neg.obj");
  EXPECT_THAT(BuildError(negative), HasSubstr("vertex index -1 out of range"));

  Mesh repeat = MakeMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2, 3}, {0, 2, 1, 2}},
                         "repeat.obj");
  EXPECT_EQ(BuildError(repeat), "repeat.obj: face 1 repeats vertex 2 (a degenerate face)");

  // A large face with a repeated vertex takes the sorting path.
  std::vector<Float3> ring;
  std::vector<int> big;
  for (int k = 0; k < 40; ++k) {
    ring.push_back({std::cos(k * 0.15f), std::sin(k * 0.15f), 0});
    big.push_back(k);
  }
  big[30] = 7;
  EXPECT_THAT(BuildError(MakeMesh(ring, {big}, "big.obj")), HasSubstr("face 0 repeats vertex 7"));

  Mesh nan = MakeCube();
  nan.positions[5].y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THAT(BuildError(nan), HasSubstr("cube: vertex 5 has a non-finite position"));
}

TEST(LimitSurfaceErrorsTest, BadTags) {
  Mesh cube = MakeCube();
  cube.tags.creases.push_back({VertexId(0), VertexId(3), 2.0f});  // a face diagonal
  EXPECT_EQ(BuildError(cube),
            "cube: OpenSubdiv rejected the topology: crease tag 0 (vertices 0-3) is not an edge "
            "of the mesh");

  cube = MakeCube();
  cube.tags.creases.push_back({VertexId(0), VertexId(1), 2.0f});
  cube.tags.creases.push_back({VertexId(0), VertexId(8), 2.0f});
  EXPECT_THAT(BuildError(cube), HasSubstr("crease tag 1: vertex 0-8 out of range (8 vertices)"));

  cube = MakeCube();
  cube.tags.creases.push_back({VertexId(1), VertexId(1), 2.0f});
  EXPECT_THAT(BuildError(cube), HasSubstr("crease tag 0: vertices 1-1 do not make an edge"));

  cube = MakeCube();
  cube.tags.creases.push_back({VertexId(0), VertexId(1), -1.0f});
  EXPECT_THAT(BuildError(cube), HasSubstr("crease tag 0 (vertices 0-1): sharpness -1"));

  cube = MakeCube();
  cube.tags.corners.push_back({VertexId(9), 1.0f});
  EXPECT_THAT(BuildError(cube), HasSubstr("corner tag 0: vertex 9 out of range"));

  cube = MakeCube();
  cube.tags.corners.push_back({VertexId(2), std::numeric_limits<float>::infinity()});
  EXPECT_THAT(BuildError(cube), HasSubstr("corner tag 0 (vertex 2): sharpness inf"));

  cube = MakeCube();
  cube.tags.holes.push_back(BaseFaceId(6));
  EXPECT_THAT(BuildError(cube), HasSubstr("hole tag 0: face 6 out of range (6 faces)"));
}

TEST(LimitSurfaceErrorsTest, BadOptions) {
  SubdivOptions options;
  options.approx_level_smooth = 11;
  EXPECT_THAT(BuildError(MakeCube(), options), HasSubstr("approx_level_smooth 11 outside 1..10"));
  options = {};
  options.approx_level_sharp = -1;
  EXPECT_THAT(BuildError(MakeCube(), options), HasSubstr("approx_level_sharp -1 outside"));
}

TEST(LimitSurfaceErrorsTest, ValenceOverflowIsRejectedByOpenSubdiv) {
  // A vertex with more incident edges than OpenSubdiv's valence limit (65535).
  const int n = 70000;
  std::vector<Float3> p = {{0, 0, 0}};
  std::vector<std::vector<int>> faces;
  for (int k = 0; k < n; ++k) {
    const float a = 6.2831853f * k / n;
    p.push_back({std::cos(a), std::sin(a), 0});
  }
  for (int k = 0; k < n; ++k) faces.push_back({0, 1 + k, 1 + (k + 1) % n});
  const std::string error = BuildError(MakeMesh(p, faces, "pole.obj"));
  EXPECT_THAT(error, HasSubstr("pole.obj: OpenSubdiv rejected the topology"));
  EXPECT_THAT(error, HasSubstr("valence"));
}

}  // namespace
}  // namespace dispex
