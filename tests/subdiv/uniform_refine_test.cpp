// RefineUniform: counts against OpenSubdiv's own uniform refinement, limit positions against
// Far::PrimvarRefiner::Limit where that is exact (smooth cages), per-vertex and per-face
// charts against the evaluator, determinism across thread counts, errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "dispex/subdiv.h"
#include "subdiv_test_util.h"

namespace dispex {
namespace {

using subdiv_test::MakeCube;
using subdiv_test::MakeGrid;
using subdiv_test::MakePentagonFan;
using subdiv_test::MakePentagonPrism;
using ::testing::HasSubstr;

TEST(RefineUniformTest, CountsMatchOpenSubdiv) {
  for (const Mesh& cage : {MakeCube(), MakePentagonFan(), MakePentagonPrism(), MakeGrid(3)}) {
    for (int levels = 0; levels <= 3; ++levels) {
      SCOPED_TRACE(cage.source + " level " + std::to_string(levels));
      StatusOr<LimitSurface> s = LimitSurface::Build(cage);
      ASSERT_TRUE(s.ok());
      StatusOr<RefinedMesh> r = RefineUniform(*s, levels);
      ASSERT_TRUE(r.ok()) << r.status().message();
      const subdiv_test::FarLimit far = subdiv_test::FarUniformLimit(cage, levels);
      EXPECT_EQ(r->mesh.num_vertices(), static_cast<std::size_t>(far.num_vertices));
      EXPECT_EQ(r->mesh.num_faces(), static_cast<std::size_t>(far.num_faces));
      EXPECT_EQ(r->refined_vertices, static_cast<std::size_t>(far.num_vertices));
      EXPECT_EQ(r->refined_faces, static_cast<std::size_t>(far.num_faces));
      // Same topology, same order: the face-vertex lists are OpenSubdiv's.
      std::size_t i = 0;
      for (const auto& face : far.faces) {
        ASSERT_EQ(r->mesh.face_size(&face - far.faces.data()), static_cast<int>(face.size()));
        for (int v : face) EXPECT_EQ(r->mesh.face_indices[i++], v);
      }
      EXPECT_EQ(i, r->mesh.face_indices.size());
      EXPECT_EQ(r->normals.size(), 3 * r->mesh.num_vertices());
      EXPECT_EQ(r->ptex_faces.size(), r->mesh.num_vertices());
      EXPECT_EQ(r->uvs.size(), 2 * r->mesh.num_vertices());
      EXPECT_TRUE(r->mesh.tags.empty());
    }
  }
}

TEST(RefineUniformTest, HoleFacesAndTheirVerticesAreDropped) {
  Mesh prism = MakePentagonPrism();
  prism.tags.holes = {BaseFaceId(0), BaseFaceId(3)};
  StatusOr<LimitSurface> s = LimitSurface::Build(prism);
  ASSERT_TRUE(s.ok());
  const int levels = 2;
  StatusOr<RefinedMesh> r = RefineUniform(*s, levels);
  ASSERT_TRUE(r.ok()) << r.status().message();
  const subdiv_test::FarLimit far = subdiv_test::FarUniformLimit(prism, levels);
  std::vector<std::vector<int>> kept;
  std::set<int> used;
  for (int f = 0; f < far.num_faces; ++f) {
    if (far.face_base[f] == 0 || far.face_base[f] == 3) continue;
    kept.push_back(far.faces[f]);
    used.insert(far.faces[f].begin(), far.faces[f].end());
  }
  ASSERT_EQ(r->mesh.num_faces(), kept.size());
  ASSERT_EQ(r->mesh.num_vertices(), used.size());
  EXPECT_EQ(r->refined_faces, static_cast<std::size_t>(far.num_faces));
  // Vertices keep OpenSubdiv's relative order.
  std::vector<int> rank(far.num_vertices, -1);
  int next = 0;
  for (int v : used) rank[v] = next++;
  for (std::size_t f = 0; f < kept.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(r->mesh.face_indices[4 * f + k], rank[kept[f][k]]);
    }
  }
  for (PtexFaceId p : r->ptex_faces) EXPECT_FALSE(s->is_hole(p));
}

// Far::PrimvarRefiner::Limit at the refined level: exact for smooth cages without darts,
// semi-sharp creases or interior valence-2 vertices.
void ExpectLimitMatchesPrimvarRefiner(const Mesh& cage, int levels) {
  SCOPED_TRACE(cage.source + " level " + std::to_string(levels));
  StatusOr<LimitSurface> s = LimitSurface::Build(cage);
  ASSERT_TRUE(s.ok());
  StatusOr<RefinedMesh> r = RefineUniform(*s, levels);
  ASSERT_TRUE(r.ok());
  const subdiv_test::FarLimit far = subdiv_test::FarUniformLimit(cage, levels);
  ASSERT_EQ(r->mesh.num_vertices(), static_cast<std::size_t>(far.num_vertices));
  const double diag = subdiv_test::BoundsDiagonal(cage);
  double max_err = 0, max_angle = 0;
  for (int v = 0; v < far.num_vertices; ++v) {
    const Float3& p = r->mesh.positions[v];
    const auto& q = far.positions[v];
    const double d[3] = {p.x - q[0], p.y - q[1], p.z - q[2]};
    max_err = std::max(max_err, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / diag);
    max_angle =
        std::max(max_angle, subdiv_test::AngleBetween(&r->normals[3 * v], far.normals[v].data()));
  }
  EXPECT_LT(max_err, 1e-6);
  EXPECT_LT(max_angle, 1e-5);
  std::printf("  %-16s level %d: %d vertices, position %.2e, normal %.2e rad\n",
              cage.source.c_str(), levels, far.num_vertices, max_err, max_angle);
}

TEST(RefineUniformTest, LimitPositionsMatchPrimvarRefinerOnSmoothCages) {
  ExpectLimitMatchesPrimvarRefiner(MakeCube(), 1);
  ExpectLimitMatchesPrimvarRefiner(MakeCube(), 3);
  ExpectLimitMatchesPrimvarRefiner(MakePentagonPrism(), 2);
  // Level 0 only on quads: Limit's masks assume quads around the vertex.
  ExpectLimitMatchesPrimvarRefiner(MakeCube(), 0);
}

// Each vertex's (ptex, u, v), and each face's corner chart, evaluate to the vertex's limit
// position: the charts are right, including n-gon sub-faces.
TEST(RefineUniformTest, ChartsEvaluateToTheVertices) {
  for (const Mesh& cage : {MakePentagonFan(), MakePentagonPrism(), MakeCube()}) {
    SCOPED_TRACE(cage.source);
    StatusOr<LimitSurface> s = LimitSurface::Build(cage);
    ASSERT_TRUE(s.ok());
    RefineOptions options;
    options.face_charts = true;
    StatusOr<RefinedMesh> r = RefineUniform(*s, 3, options);
    ASSERT_TRUE(r.ok());
    const double diag = subdiv_test::BoundsDiagonal(cage);
    LimitEvaluator eval(*s);
    ASSERT_EQ(r->face_ptex.size(), r->mesh.num_faces());
    ASSERT_EQ(r->face_uvs.size(), 8 * r->mesh.num_faces());
    for (std::size_t f = 0; f < r->mesh.num_faces(); ++f) {
      std::vector<float> uv(r->face_uvs.begin() + 8 * f, r->face_uvs.begin() + 8 * f + 8);
      // A level-3 face is an axis-aligned square of side 1/8 (quads) or 1/4 (sub-faces).
      const float side = std::max(std::abs(uv[2] - uv[0]), std::abs(uv[3] - uv[1]));
      EXPECT_TRUE(side == 0.125f || side == 0.25f) << side;
      std::vector<float> p(12);
      ASSERT_TRUE(eval.EvaluatePoints(r->face_ptex[f], uv, p, {}).ok());
      for (int k = 0; k < 4; ++k) {
        const Float3& q = r->mesh.positions[r->mesh.face_indices[4 * f + k]];
        EXPECT_NEAR(p[3 * k], q.x, 1e-6 * diag);
        EXPECT_NEAR(p[3 * k + 1], q.y, 1e-6 * diag);
        EXPECT_NEAR(p[3 * k + 2], q.z, 1e-6 * diag);
      }
    }
    for (std::size_t v = 0; v < r->mesh.num_vertices(); ++v) {
      const float u = r->uvs[2 * v], w = r->uvs[2 * v + 1];
      EXPECT_TRUE(u >= 0 && u <= 1 && w >= 0 && w <= 1);
      std::vector<float> p(3), n(3);
      ASSERT_TRUE(eval.EvaluatePoints(r->ptex_faces[v], std::vector<float>{u, w}, p, n).ok());
      EXPECT_EQ(p[0], r->mesh.positions[v].x);
      EXPECT_EQ(p[1], r->mesh.positions[v].y);
      EXPECT_EQ(p[2], r->mesh.positions[v].z);
      EXPECT_EQ(n[0], r->normals[3 * v]);
    }
  }
}

TEST(RefineUniformTest, WindingIsPreserved) {
  StatusOr<LimitSurface> s = LimitSurface::Build(MakePentagonPrism());
  ASSERT_TRUE(s.ok());
  StatusOr<RefinedMesh> r = RefineUniform(*s, 2);
  ASSERT_TRUE(r.ok());
  const Mesh& m = r->mesh;
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    const Float3& a = m.positions[m.face_indices[4 * f]];
    const Float3& b = m.positions[m.face_indices[4 * f + 1]];
    const Float3& c = m.positions[m.face_indices[4 * f + 2]];
    const Float3& d = m.positions[m.face_indices[4 * f + 3]];
    const double e1[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
    const double e2[3] = {d.x - b.x, d.y - b.y, d.z - b.z};
    double geo[3];
    subdiv_test::UnitCross(e1, e2, geo);
    const float* n = &r->normals[3 * m.face_indices[4 * f]];
    EXPECT_GT(geo[0] * n[0] + geo[1] * n[1] + geo[2] * n[2], 0.5) << "face " << f;
  }
}

TEST(RefineUniformTest, SameResultWithOneOrTwoThreads) {
  StatusOr<LimitSurface> s = LimitSurface::Build(MakePentagonFan());
  ASSERT_TRUE(s.ok());
  RefineOptions one, two;
  one.threads = 1;
  two.threads = 2;
  one.face_charts = two.face_charts = true;
  StatusOr<RefinedMesh> a = RefineUniform(*s, 4, one);
  StatusOr<RefinedMesh> b = RefineUniform(*s, 4, two);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->mesh.face_indices, b->mesh.face_indices);
  ASSERT_EQ(a->mesh.positions.size(), b->mesh.positions.size());
  for (std::size_t v = 0; v < a->mesh.positions.size(); ++v) {
    EXPECT_EQ(a->mesh.positions[v].x, b->mesh.positions[v].x);
    EXPECT_EQ(a->mesh.positions[v].y, b->mesh.positions[v].y);
    EXPECT_EQ(a->mesh.positions[v].z, b->mesh.positions[v].z);
  }
  EXPECT_EQ(a->normals, b->normals);
  EXPECT_EQ(a->ptex_faces, b->ptex_faces);
  EXPECT_EQ(a->uvs, b->uvs);
  EXPECT_EQ(a->face_uvs, b->face_uvs);
}

TEST(RefineUniformTest, Errors) {
  StatusOr<LimitSurface> s = LimitSurface::Build(MakeCube());
  ASSERT_TRUE(s.ok());
  EXPECT_THAT(RefineUniform(*s, 9).status().message(),
              HasSubstr("cube: refinement level 9 outside 0..8"));
  EXPECT_THAT(RefineUniform(*s, -1).status().message(), HasSubstr("level -1"));
  RefineOptions bad;
  bad.threads = -2;
  EXPECT_THAT(RefineUniform(*s, 1, bad).status().message(), HasSubstr("thread count -2"));
  RefineOptions charts;
  charts.face_charts = true;
  EXPECT_THAT(RefineUniform(*s, 0, charts).status().message(),
              HasSubstr("face charts need at least one refinement level"));
  // 91 x 91 quads at level 8: 8281 * 4^8 faces, over 2^31 face-vertex indices.
  StatusOr<LimitSurface> big = LimitSurface::Build(MakeGrid(91));
  ASSERT_TRUE(big.ok());
  EXPECT_THAT(RefineUniform(*big, 8).status().message(),
              HasSubstr("8 refinement levels make 542703616 faces"));
}

}  // namespace
}  // namespace dispex
