// LimitEvaluator on cages built in code: against OpenSubdiv's PatchTable oracle, the regular
// fast path against Bfr, exact planar answers, continuity across sub-face edges, outward
// normals, the degenerate-normal fallback and argument errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "dispex/subdiv.h"
#include "subdiv_test_util.h"

namespace dispex {
namespace {

using subdiv_test::CompareWithOracle;
using subdiv_test::MakeCube;
using subdiv_test::MakeGrid;
using subdiv_test::MakeMesh;
using subdiv_test::MakePentagonFan;
using subdiv_test::MakePentagonPrism;
using subdiv_test::OracleComparison;
using ::testing::HasSubstr;

void ExpectMatchesOracle(const Mesh& cage, double max_pos = 1e-5, double max_angle = 1e-4) {
  SCOPED_TRACE(cage.source);
  const OracleComparison c = CompareWithOracle(cage, {}, 8);
  ASSERT_TRUE(c.built) << c.error;
  EXPECT_EQ(c.hole_mismatches, 0);
  EXPECT_GT(c.samples, 0);
  EXPECT_LT(c.max_position_error, max_pos);
  EXPECT_LT(c.max_normal_angle_regular, max_angle);
  std::printf("  %-20s samples %6lld  pos err %.2e  normal %.2e rad (%.2e incl. extraordinary)\n",
              cage.source.c_str(), static_cast<long long>(c.samples), c.max_position_error,
              c.max_normal_angle_regular, c.max_normal_angle);
}

Mesh BumpyGrid(int n) {
  Mesh g = MakeGrid(n);
  for (std::size_t v = 0; v < g.positions.size(); ++v) {
    Float3& p = g.positions[v];
    p.z = 0.3f * std::sin(1.3f * p.x) * std::cos(0.7f * p.y) + 0.05f * static_cast<float>(v % 3);
  }
  g.source = "bumpy_grid";
  return g;
}

TEST(LimitEvaluatorOracleTest, CodeBuiltCages) {
  ExpectMatchesOracle(MakeCube());
  ExpectMatchesOracle(MakePentagonFan());
  ExpectMatchesOracle(MakePentagonPrism());
  ExpectMatchesOracle(BumpyGrid(5));

  Mesh semi = MakeCube();
  semi.source = "cube_semisharp";
  semi.tags.creases.push_back({VertexId(0), VertexId(1), 2.5f});
  semi.tags.creases.push_back({VertexId(1), VertexId(3), 1.2f});
  semi.tags.corners.push_back({VertexId(6), 3.0f});
  ExpectMatchesOracle(semi);

  Mesh inf = MakePentagonPrism();
  inf.source = "prism_infsharp";
  for (int k = 0; k < 5; ++k)
    inf.tags.creases.push_back({VertexId(5 + k), VertexId(5 + (k + 1) % 5), 10.0f});
  inf.tags.corners.push_back({VertexId(0), 10.0f});
  ExpectMatchesOracle(inf);

  Mesh edge_only = BumpyGrid(4);
  edge_only.source = "grid_edge_only";
  edge_only.tags.boundary = BoundaryInterpolation::kEdgeOnly;
  ExpectMatchesOracle(edge_only);

  Mesh none = BumpyGrid(5);
  none.source = "grid_boundary_none";
  none.tags.boundary = BoundaryInterpolation::kNone;
  ExpectMatchesOracle(none);

  Mesh holes = MakePentagonPrism();
  holes.source = "prism_hole";
  holes.tags.holes.push_back(BaseFaceId(1));
  ExpectMatchesOracle(holes);
}

// The pitfall of docs/ARCHITECTURE.md, "OpenSubdiv pitfalls": Bfr's default approximation
// (approx_level_smooth = 2) moves limit points near extraordinary vertices. dispex's defaults must
// match the patch table at OpenSubdiv's deepest isolation (10) there, and the comparison must be
// able to see the difference (it also sees level 6, which is why the default is 10).
TEST(LimitEvaluatorOracleTest, ApproximationLevelRegression) {
  for (const Mesh& cage : {MakeCube(), MakePentagonPrism(), MakePentagonFan()}) {
    SCOPED_TRACE(cage.source);
    const OracleComparison exact = CompareWithOracle(cage, {}, 4, 10);
    ASSERT_TRUE(exact.built) << exact.error;
    EXPECT_LT(exact.max_position_error, 1e-6);
    EXPECT_LT(exact.max_normal_angle, 1e-6);
    SubdivOptions coarse;
    coarse.approx_level_smooth = 2;
    const OracleComparison approx = CompareWithOracle(cage, coarse, 4, 10);
    ASSERT_TRUE(approx.built) << approx.error;
    EXPECT_GT(approx.max_position_error, 1e-5) << "the oracle no longer sees approx level 2";
    SubdivOptions six;
    six.approx_level_smooth = 6;
    const OracleComparison level6 = CompareWithOracle(cage, six, 4, 10);
    ASSERT_TRUE(level6.built) << level6.error;
    EXPECT_GT(level6.max_position_error, 1e-5);
    std::printf(
        "  %-16s vs patch table (isolation 10): level 10: %.2e  level 6: %.2e  "
        "level 2: %.2e (of the diagonal)\n",
        cage.source.c_str(), exact.max_position_error, level6.max_position_error,
        approx.max_position_error);
  }
}

// Grid outputs of one surface evaluated with the given options, face after face.
void EvaluateAll(const LimitSurface& s, int n, std::vector<float>& p, std::vector<float>& nrm,
                 LimitEvaluatorStats* stats = nullptr, bool reverse = false) {
  LimitEvaluator eval(s);
  const std::size_t per_face = 3 * static_cast<std::size_t>(n) * n;
  p.assign(per_face * s.num_ptex_faces(), 0.0f);
  nrm.assign(per_face * s.num_ptex_faces(), 0.0f);
  for (int k = 0; k < s.num_ptex_faces(); ++k) {
    const int f = reverse ? s.num_ptex_faces() - 1 - k : k;
    if (s.is_hole(PtexFaceId(f))) continue;
    ASSERT_TRUE(eval.EvaluateGrid(PtexFaceId(f), n, n,
                                  std::span<float>(p).subspan(per_face * f, per_face),
                                  std::span<float>(nrm).subspan(per_face * f, per_face))
                    .ok());
  }
  if (stats) *stats = eval.stats();
}

TEST(LimitEvaluatorTest, RegularFastPathAgreesWithBfr) {
  // Interior, boundary (edge-and-corner and edge-only), infinitely sharp and semi-sharp
  // regular faces all go through the fast path.
  std::vector<Mesh> cages;
  cages.push_back(BumpyGrid(6));
  Mesh edge_only = BumpyGrid(5);
  edge_only.tags.boundary = BoundaryInterpolation::kEdgeOnly;
  cages.push_back(edge_only);
  Mesh creased = BumpyGrid(6);
  creased.tags.creases.push_back({VertexId(8), VertexId(9), 10.0f});
  creased.tags.creases.push_back({VertexId(9), VertexId(10), 10.0f});
  creased.tags.creases.push_back({VertexId(15), VertexId(16), 1.5f});
  cages.push_back(creased);
  cages.push_back(MakePentagonFan());
  for (const Mesh& cage : cages) {
    SubdivOptions fast, slow;
    slow.regular_fast_path = false;
    StatusOr<LimitSurface> a = LimitSurface::Build(cage, fast);
    StatusOr<LimitSurface> b = LimitSurface::Build(cage, slow);
    ASSERT_TRUE(a.ok() && b.ok());
    for (int n : {1, 5, 16}) {
      std::vector<float> pa, na, pb, nb;
      LimitEvaluatorStats sa, sb;
      EvaluateAll(*a, n, pa, na, &sa);
      EvaluateAll(*b, n, pb, nb, &sb);
      if (cage.source != "pentagon_fan") {
        EXPECT_GT(sa.regular_faces, 0);
      }
      EXPECT_EQ(sb.regular_faces, 0);
      double max_p = 0, max_n = 0;
      for (std::size_t i = 0; i < pa.size(); ++i) {
        max_p = std::max(max_p, static_cast<double>(std::abs(pa[i] - pb[i])));
        max_n = std::max(max_n, static_cast<double>(std::abs(na[i] - nb[i])));
      }
      EXPECT_LT(max_p, 2e-6) << cage.source << " n=" << n;
      EXPECT_LT(max_n, 2e-6) << cage.source << " n=" << n;
    }
  }
}

TEST(LimitEvaluatorTest, FlatGridIsExactlyPlanar) {
  const int n = 6;
  StatusOr<LimitSurface> s = LimitSurface::Build(MakeGrid(n));
  ASSERT_TRUE(s.ok());
  LimitEvaluator eval(*s);
  const int r = 7;
  std::vector<float> p(3 * r * r), nrm(3 * r * r);
  for (int f = 0; f < n * n; ++f) {
    ASSERT_TRUE(eval.EvaluateGrid(PtexFaceId(f), r, r, p, nrm).ok());
    const int fi = f % n, fj = f / n;
    const bool interior = fi > 0 && fj > 0 && fi < n - 1 && fj < n - 1;
    for (int j = 0; j < r; ++j) {
      for (int i = 0; i < r; ++i) {
        const float* q = &p[3 * (j * r + i)];
        const float* m = &nrm[3 * (j * r + i)];
        EXPECT_EQ(q[2], 0.0f);
        EXPECT_EQ(m[0], 0.0f);
        EXPECT_EQ(m[1], 0.0f);
        EXPECT_EQ(m[2], 1.0f);
        if (interior) {
          // Uniform cubic B-splines reproduce linear functions: P = (fi + u, fj + v).
          EXPECT_NEAR(q[0], fi + (i + 0.5) / r, 1e-6);
          EXPECT_NEAR(q[1], fj + (j + 0.5) / r, 1e-6);
        }
      }
    }
  }
  EXPECT_EQ(eval.stats().regular_faces, n * n);
  EXPECT_EQ(eval.stats().samples, n * n * r * r);
  EXPECT_EQ(eval.stats().fallback_normals, 0);
}

// Point on Ptex edge e at parameter t (edges run counter-clockwise: 0 v=0, 1 u=1, 2 v=1,
// 3 u=0).
void EdgePoint(int e, float t, float uv[2]) {
  switch (e) {
    case 0:
      uv[0] = t;
      uv[1] = 0;
      break;
    case 1:
      uv[0] = 1;
      uv[1] = t;
      break;
    case 2:
      uv[0] = 1 - t;
      uv[1] = 1;
      break;
    default:
      uv[0] = 0;
      uv[1] = 1 - t;
      break;
  }
}

// Along every Ptex edge shared by two faces of the same kind (two quads or two sub-faces,
// so the edges have the same length), both sides give the same points.
int CheckEdgeContinuity(const Mesh& cage) {
  SCOPED_TRACE(cage.source);
  StatusOr<LimitSurface> s = LimitSurface::Build(cage);
  EXPECT_TRUE(s.ok());
  if (!s.ok()) return 0;
  const double diag = subdiv_test::BoundsDiagonal(cage);
  LimitEvaluator eval(*s);
  int checked = 0;
  const int steps = 9;
  for (int f = 0; f < s->num_ptex_faces(); ++f) {
    const PtexFaceId face(f);
    if (s->is_hole(face)) continue;
    const bool f_sub = s->num_ptex_faces(s->base_face(face)) != 1;
    for (int e = 0; e < 4; ++e) {
      const PtexFaceId g = s->adjacency(face).faces[e];
      if (!g.valid() || s->is_hole(g)) continue;
      const bool g_sub = s->num_ptex_faces(s->base_face(g)) != 1;
      if (f_sub != g_sub) continue;
      const int e2 = s->adjacency(face).edges[e];
      std::vector<float> uf, ug;
      for (int k = 0; k <= steps; ++k) {
        const float t = static_cast<float>(k) / steps;
        float a[2], b[2];
        EdgePoint(e, t, a);
        EdgePoint(e2, 1 - t, b);
        uf.insert(uf.end(), a, a + 2);
        ug.insert(ug.end(), b, b + 2);
      }
      std::vector<float> pf(3 * (steps + 1)), pg(3 * (steps + 1));
      EXPECT_TRUE(eval.EvaluatePoints(face, uf, pf, {}).ok());
      EXPECT_TRUE(eval.EvaluatePoints(g, ug, pg, {}).ok());
      for (std::size_t i = 0; i < pf.size(); ++i) {
        EXPECT_NEAR(pf[i], pg[i], 1e-6 * diag)
            << "Ptex " << f << " edge " << e << " vs " << g.value;
      }
      ++checked;
    }
  }
  return checked;
}

TEST(LimitEvaluatorTest, SubFaceEdgesAreContinuous) {
  EXPECT_GE(CheckEdgeContinuity(MakePentagonFan()), 10);
  EXPECT_GE(CheckEdgeContinuity(MakePentagonPrism()), 20);
  EXPECT_GT(CheckEdgeContinuity(MakeCube()), 0);
}

TEST(LimitEvaluatorTest, NormalsPointOutwardOnClosedCages) {
  for (const Mesh& cage : {MakeCube(), MakePentagonPrism()}) {
    SCOPED_TRACE(cage.source);
    StatusOr<LimitSurface> s = LimitSurface::Build(cage);
    ASSERT_TRUE(s.ok());
    std::vector<float> p, nrm;
    EvaluateAll(*s, 6, p, nrm);
    const auto c = subdiv_test::Centroid(cage);
    // Both shapes are convex: every normal points away from the centroid.
    for (std::size_t i = 0; i < p.size(); i += 3) {
      const double d =
          nrm[i] * (p[i] - c[0]) + nrm[i + 1] * (p[i + 1] - c[1]) + nrm[i + 2] * (p[i + 2] - c[2]);
      EXPECT_GT(d, 0.0) << "sample " << i / 3;
      EXPECT_NEAR(nrm[i] * nrm[i] + nrm[i + 1] * nrm[i + 1] + nrm[i + 2] * nrm[i + 2], 1.0, 1e-6);
    }
  }
  // Reversing the winding flips every normal.
  Mesh flipped = MakeCube();
  for (std::size_t f = 0; f < flipped.num_faces(); ++f) {
    std::reverse(flipped.face_indices.begin() + flipped.face_offsets[f],
                 flipped.face_indices.begin() + flipped.face_offsets[f + 1]);
  }
  const OracleComparison c = CompareWithOracle(flipped, {}, 4);
  ASSERT_TRUE(c.built);
  EXPECT_LT(c.mean_outward, 0.0);
}

TEST(LimitEvaluatorTest, ResultsDoNotDependOnEvaluationOrder) {
  StatusOr<LimitSurface> s = LimitSurface::Build(MakePentagonPrism());
  ASSERT_TRUE(s.ok());
  std::vector<float> p1, n1, p2, n2;
  EvaluateAll(*s, 9, p1, n1, nullptr, false);
  EvaluateAll(*s, 9, p2, n2, nullptr, true);
  EXPECT_EQ(p1, p2);
  EXPECT_EQ(n1, n2);
}

TEST(LimitEvaluatorTest, PositionsOnlySkipsNormals) {
  StatusOr<LimitSurface> s = LimitSurface::Build(MakePentagonFan());
  ASSERT_TRUE(s.ok());
  LimitEvaluator eval(*s);
  std::vector<float> p(3 * 16), q(3 * 16), n(3 * 16);
  for (int f = 0; f < s->num_ptex_faces(); ++f) {
    ASSERT_TRUE(eval.EvaluateGrid(PtexFaceId(f), 4, 4, p, {}).ok());
    ASSERT_TRUE(eval.EvaluateGrid(PtexFaceId(f), 4, 4, q, n).ok());
    for (int i = 0; i < 48; ++i) EXPECT_NEAR(p[i], q[i], 1e-6);
  }
}

TEST(LimitEvaluatorTest, DegenerateDerivativesFallBack) {
  // A grid whose rows 1..3 are collapsed to one point: on the line of row 2 both first
  // derivatives vanish (all control points they weigh coincide).
  Mesh g = MakeGrid(4);
  for (int j = 1; j <= 3; ++j) {
    for (int i = 0; i <= 4; ++i) g.positions[j * 5 + i] = {2.0f, 2.0f, 0.5f};
  }
  StatusOr<LimitSurface> s = LimitSurface::Build(g);
  ASSERT_TRUE(s.ok());
  LimitEvaluator eval(*s);
  // Ptex face 5 (i=1, j=1) has the collapsed row on its top edge, v = 1.
  const std::vector<float> uv = {0.5f, 1.0f, 0.25f, 1.0f, 0.5f, 0.5f};
  std::vector<float> p(9), n(9);
  ASSERT_TRUE(eval.EvaluatePoints(PtexFaceId(5), uv, p, n).ok());
  for (float x : n) EXPECT_TRUE(std::isfinite(x));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(n[3 * k] * n[3 * k] + n[3 * k + 1] * n[3 * k + 1] + n[3 * k + 2] * n[3 * k + 2],
                1.0, 1e-6);
  }
  EXPECT_GT(eval.stats().fallback_normals, 0);
  // The fallback normal is the limit of the normals approaching the edge.
  const std::vector<float> inside = {0.5f, 0.999f};
  std::vector<float> pi(3), ni(3);
  ASSERT_TRUE(eval.EvaluatePoints(PtexFaceId(5), inside, pi, ni).ok());
  const double dot = n[0] * ni[0] + n[1] * ni[1] + n[2] * ni[2];
  EXPECT_GT(dot, 0.99);

  // Everything collapsed: no usable derivative, no usable polygon: +z, never NaN.
  Mesh point = MakeGrid(3);
  for (Float3& q : point.positions) q = {1, 1, 1};
  StatusOr<LimitSurface> t = LimitSurface::Build(point);
  ASSERT_TRUE(t.ok());
  LimitEvaluator e2(*t);
  std::vector<float> p2(12), n2(12);
  ASSERT_TRUE(e2.EvaluateGrid(PtexFaceId(4), 2, 2, p2, n2).ok());
  EXPECT_EQ(n2[2], 1.0f);
  EXPECT_EQ(p2[0], 1.0f);
  EXPECT_EQ(e2.stats().fallback_normals, 4);
}

TEST(LimitEvaluatorTest, ArgumentErrors) {
  StatusOr<LimitSurface> s = LimitSurface::Build(MakeCube());
  ASSERT_TRUE(s.ok());
  LimitEvaluator eval(*s);
  std::vector<float> p(12), n(12);
  EXPECT_THAT(eval.EvaluateGrid(PtexFaceId(6), 2, 2, p, n).message(),
              HasSubstr("cube: Ptex face 6 out of range (6 Ptex faces)"));
  EXPECT_THAT(eval.EvaluateGrid(PtexFaceId(-1), 2, 2, p, n).message(), HasSubstr("out of range"));
  EXPECT_THAT(eval.EvaluateGrid(PtexFaceId(0), 0, 2, p, n).message(), HasSubstr("grid 0x2"));
  EXPECT_THAT(eval.EvaluateGrid(PtexFaceId(0), 3, 2, p, n).message(),
              HasSubstr("a 3x2 grid needs 18 floats"));
  EXPECT_THAT(eval.EvaluatePoints(PtexFaceId(0), std::vector<float>{0.5f}, p, n).message(),
              HasSubstr("not a list of pairs"));
  EXPECT_THAT(eval.EvaluatePoints(PtexFaceId(0), std::vector<float>{0.5f, 1.5f}, p, n).message(),
              HasSubstr("point 0 (u,v) = (0.5, 1.5) is outside"));
  EXPECT_THAT(
      eval.EvaluatePoints(PtexFaceId(0), std::vector<float>{0.5f, std::nanf("")}, p, n).message(),
      HasSubstr("outside"));
  EXPECT_THAT(eval.EvaluatePoints(PtexFaceId(0), std::vector<float>(10, 0.5f), p, n).message(),
              HasSubstr("5 points need 15 floats"));
  EXPECT_TRUE(eval.EvaluatePoints(PtexFaceId(0), {}, {}, {}).ok());
}

}  // namespace
}  // namespace dispex
