// The limit surface of every real cage in tests/data/meshes against OpenSubdiv's own
// Far::PatchTable + Far::PatchMap evaluation (built independently, see subdiv_test_util.h):
// positions to 1e-5 of the bounding-box diagonal, normals to 1e-4 rad away from
// extraordinary points, same holes; outward normals on closed cages; a clear error for what
// dispex rejects; and Spot's level-2 cage, whose limit surface is the cage's.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "subdiv_test_util.h"

namespace dispex {
namespace {

using subdiv_test::CompareWithOracle;
using subdiv_test::OracleComparison;
using ::testing::HasSubstr;

std::string DataPath(const std::string& relative) {
  return (std::filesystem::path(DISPEX_TEST_DATA_DIR) / "meshes" / relative).string();
}

Mesh ReadOrDie(const std::string& relative) {
  StatusOr<Mesh> mesh = ReadMesh(DataPath(relative));
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return mesh.ok() ? std::move(mesh).value() : Mesh{};
}

struct Cage {
  const char* path;
  bool closed;  // closed surface: mean dot(normal, P - centroid) > 0
};

class RealCageTest : public ::testing::TestWithParam<Cage> {};

TEST_P(RealCageTest, MatchesPatchTable) {
  const Mesh mesh = ReadOrDie(GetParam().path);
  ASSERT_GT(mesh.num_faces(), 0u);
  const OracleComparison c = CompareWithOracle(mesh, {}, 6);
  ASSERT_TRUE(c.built) << c.error;
  EXPECT_EQ(c.hole_mismatches, 0);
  EXPECT_GT(c.samples, 0);
  EXPECT_LT(c.max_position_error, 1e-5);
  EXPECT_LT(c.max_normal_angle_regular, 1e-4);
  if (GetParam().closed) {
    EXPECT_GT(c.mean_outward, 0.0);
  }
  std::printf("  %-40s samples %7lld  pos %.2e  normal %.2e rad (%.2e all)  outward %+.3f\n",
              GetParam().path, static_cast<long long>(c.samples), c.max_position_error,
              c.max_normal_angle_regular, c.max_normal_angle, c.mean_outward);
}

// EvaluatePointFrames' derivatives are dP/du and dP/dv in the Ptex face's own (u,v): central
// differences of the positions agree to 3% (float positions, step 1/512) on every path (regular
// fast path, Bfr, Far patch table) and every kind of face -- the check that rejects OpenSubdiv's
// sub-face derivatives, twice the Ptex sub-face's on n-gons. The grid path gives the same frames as
// the point path.
TEST_P(RealCageTest, DerivativesAreThePtexFacesOwn) {
  const Mesh mesh = ReadOrDie(GetParam().path);
  StatusOr<LimitSurface> s = LimitSurface::Build(mesh);
  ASSERT_TRUE(s.ok()) << s.status().message();
  LimitEvaluator eval(*s);
  constexpr double kStep = 1.0 / 512;
  constexpr int kGrid = 4;
  std::vector<float> uv, p(3 * kGrid * kGrid), n(p.size()), du(p.size()), dv(p.size());
  std::vector<float> gp(p.size()), gn(p.size()), gdu(p.size()), gdv(p.size());
  for (int j = 0; j < kGrid; ++j) {
    for (int i = 0; i < kGrid; ++i) {
      uv.push_back((i + 0.5f) / kGrid);
      uv.push_back((j + 0.5f) / kGrid);
    }
  }
  double worst = 0;
  int checked = 0;
  for (int f = 0; f < s->num_ptex_faces(); ++f) {
    const PtexFaceId face(f);
    if (s->is_hole(face)) continue;
    ASSERT_TRUE(eval.EvaluatePointFrames(face, uv, {p, n, du, dv}).ok());
    ASSERT_TRUE(eval.EvaluateGridFrames(face, kGrid, kGrid, {gp, gn, gdu, gdv}).ok());
    for (std::size_t k = 0; k < p.size(); ++k) {
      ASSERT_NEAR(gdu[k], du[k], 1e-4 * (1 + std::fabs(du[k])));
      ASSERT_NEAR(gdv[k], dv[k], 1e-4 * (1 + std::fabs(dv[k])));
    }
    for (int q = 0; q < kGrid * kGrid; ++q) {
      for (int axis = 0; axis < 2; ++axis) {
        float a[2] = {uv[2 * q], uv[2 * q + 1]}, b[2] = {a[0], a[1]};
        a[axis] -= static_cast<float>(kStep);
        b[axis] += static_cast<float>(kStep);
        float pa[3], pb[3];
        ASSERT_TRUE(eval.EvaluatePoints(face, a, pa, {}).ok());
        ASSERT_TRUE(eval.EvaluatePoints(face, b, pb, {}).ok());
        const float* d = axis == 0 ? &du[3 * q] : &dv[3 * q];
        double err2 = 0, len2 = 0;
        for (int k = 0; k < 3; ++k) {
          const double fd = (static_cast<double>(pb[k]) - pa[k]) / (2 * kStep);
          err2 += (fd - d[k]) * (fd - d[k]);
          len2 += static_cast<double>(d[k]) * d[k];
        }
        if (len2 < 1e-12) continue;  // a degenerate corner: no direction to compare
        worst = std::max(worst, std::sqrt(err2 / len2));
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 0);
  EXPECT_LT(worst, 0.03) << GetParam().path;
  std::printf("  %-40s derivatives within %.2e of central differences\n", GetParam().path, worst);
}

INSTANTIATE_TEST_SUITE_P(
    Cages, RealCageTest,
    ::testing::Values(
        Cage{"opensubdiv/catmark_cube.obj", true},
        Cage{"opensubdiv/catmark_cube_creases0.obj", true},
        Cage{"opensubdiv/catmark_cube_creases1.obj", true},
        Cage{"opensubdiv/catmark_cubes_semisharp.obj", false},
        Cage{"opensubdiv/catmark_cubes_infsharp.obj", false},
        Cage{"opensubdiv/catmark_cube_corner0.obj", true},
        Cage{"opensubdiv/catmark_hole_test1.obj", false},
        Cage{"opensubdiv/catmark_hole_test2.obj", false},
        Cage{"opensubdiv/catmark_edgecorner.obj", false},
        Cage{"opensubdiv/catmark_tent.obj", false}, Cage{"opensubdiv/catmark_fan.obj", false},
        Cage{"opensubdiv/catmark_flap.obj", false}, Cage{"opensubdiv/catmark_helmet.obj", false},
        Cage{"opensubdiv/catmark_xord_boundary.obj", false},
        Cage{"opensubdiv/catmark_xord_interior.obj", false},
        Cage{"opensubdiv/catmark_nonman_verts.obj", false},
        Cage{"opensubdiv/catmark_nonquads.obj", false}, Cage{"opensubdiv/catmark_pole8.obj", false},
        Cage{"opensubdiv/catmark_pole64.obj", false},
        Cage{"opensubdiv/catmark_val2_interior.obj", false},
        Cage{"opensubdiv/catmark_pyramid.obj", true},
        Cage{"opensubdiv/catmark_smoothtris0.obj", true}, Cage{"dispex/chaikin_box.obj", true},
        Cage{"opensubdiv/catmark_gregory_test8.obj", true},
        Cage{"opensubdiv/catmark_torus.obj", false},
        Cage{"opensubdiv/catmark_torus_creases0.obj", false},
        Cage{"opensubdiv/catmark_single_crease.obj", false},
        Cage{"opensubdiv/catmark_lefthanded.obj", false},
        Cage{"opensubdiv/catmark_pawn.obj", false}, Cage{"opensubdiv/catmark_car.obj", false},
        Cage{"keenan_spot/spot_control_mesh.obj", true},
        Cage{"keenan_spot/spot_quadrangulated.obj", true},
        Cage{"keenan_blub/blub_control_mesh.obj", true},
        Cage{"jerry_the_ogre/controlmesh.obj", true},
        Cage{"stanford_bunny/bun_zipper_quadriflow_1000.obj", true},
        Cage{"nefertiti/nefertiti_quadriflow_1000.obj", true}),
    [](const ::testing::TestParamInfo<Cage>& param) {
      std::string name = param.param.path;
      name = name.substr(name.find('/') + 1);
      name = name.substr(0, name.find('.'));
      for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
      return name;
    });

// RefineUniform on real cages against OpenSubdiv's own uniform refinement: same counts and
// face-vertex lists, and limit positions/normals equal to Far::PrimvarRefiner::Limit at every
// refined vertex that is not a base vertex itself (Limit is inexact at darts and interior
// valence-2 vertices; those points are covered by the patch-table comparison above). The
// level is at least every semi-sharp crease's sharpness, where Limit becomes exact.
struct RefineCase {
  const char* path;
  int levels;
};

// Counts and face-vertex lists of RefineUniform equal Far's, positions and normals its
// Limit's away from base vertices.
void ExpectRefinementMatchesFar(const Mesh& mesh, int levels, const std::string& name) {
  StatusOr<LimitSurface> s = LimitSurface::Build(mesh);
  ASSERT_TRUE(s.ok()) << s.status().message();
  StatusOr<RefinedMesh> r = RefineUniform(*s, levels);
  ASSERT_TRUE(r.ok()) << r.status().message();
  const subdiv_test::FarLimit far = subdiv_test::FarUniformLimit(mesh, levels);
  ASSERT_EQ(r->mesh.num_vertices(), static_cast<std::size_t>(far.num_vertices));
  ASSERT_EQ(r->mesh.num_faces(), static_cast<std::size_t>(far.num_faces));
  std::size_t i = 0;
  for (const auto& face : far.faces) {
    for (int v : face) ASSERT_EQ(r->mesh.face_indices[i++], v);
  }
  const double diag = subdiv_test::BoundsDiagonal(mesh);
  double max_err = 0, max_angle = 0;
  int compared = 0;
  for (int v = 0; v < far.num_vertices; ++v) {
    if (far.from_base_vertex[v]) continue;
    const Float3& p = r->mesh.positions[v];
    const auto& q = far.positions[v];
    const double d[3] = {p.x - q[0], p.y - q[1], p.z - q[2]};
    max_err = std::max(max_err, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / diag);
    max_angle =
        std::max(max_angle, subdiv_test::AngleBetween(&r->normals[3 * v], far.normals[v].data()));
    ++compared;
  }
  EXPECT_LT(max_err, 1e-6);
  // Limit's normals are exact; Bfr's at n-gon centres and other extraordinary points carry
  // the Gregory end caps' error at level 10 (measured <= 5.4e-6 rad on the ogre).
  EXPECT_LT(max_angle, 5e-5);
  std::printf("  %-40s level %d: %d vertices compared, position %.2e, normal %.2e rad\n",
              name.c_str(), levels, compared, max_err, max_angle);
}

class RealCageRefineTest : public ::testing::TestWithParam<RefineCase> {};

TEST_P(RealCageRefineTest, MatchesPrimvarRefiner) {
  ExpectRefinementMatchesFar(ReadOrDie(GetParam().path), GetParam().levels, GetParam().path);
}

INSTANTIATE_TEST_SUITE_P(Cages, RealCageRefineTest,
                         ::testing::Values(RefineCase{"opensubdiv/catmark_val2_interior.obj", 5},
                                           RefineCase{"opensubdiv/catmark_nonquads.obj", 3},
                                           RefineCase{"opensubdiv/catmark_cubes_infsharp.obj", 3},
                                           RefineCase{"opensubdiv/catmark_pole64.obj", 2},
                                           RefineCase{"dispex/chaikin_box.obj", 4},
                                           RefineCase{"keenan_spot/spot_control_mesh.obj", 3},
                                           RefineCase{"jerry_the_ogre/controlmesh.obj", 2}),
                         [](const ::testing::TestParamInfo<RefineCase>& param) {
                           std::string name = param.param.path;
                           name = name.substr(name.find('/') + 1);
                           name = name.substr(0, name.find('.'));
                           for (char& c : name)
                             c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

TEST(RealCageErrorsTest, DegenerateFacesAreRejected) {
  // catmark_nonman_edges has faces that repeat a vertex (zero-length sides).
  const Mesh mesh = ReadOrDie("opensubdiv/catmark_nonman_edges.obj");
  StatusOr<LimitSurface> s = LimitSurface::Build(mesh);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.status().message(),
              HasSubstr("catmark_nonman_edges.obj: face 24 repeats vertex 51"));
}

TEST(RealCageTest, TagsReachOpenSubdiv) {
  StatusOr<LimitSurface> holes =
      LimitSurface::Build(ReadOrDie("opensubdiv/catmark_hole_test2.obj"));
  ASSERT_TRUE(holes.ok());
  EXPECT_EQ(holes->stats().hole_ptex_faces, 4);  // t hole 4/0/0 5 6 9 10
  StatusOr<LimitSurface> inf =
      LimitSurface::Build(ReadOrDie("opensubdiv/catmark_cubes_infsharp.obj"));
  ASSERT_TRUE(inf.ok());
  EXPECT_GT(inf->stats().inf_sharp_edges, 0);
  StatusOr<LimitSurface> ogre = LimitSurface::Build(ReadOrDie("jerry_the_ogre/controlmesh.obj"));
  ASSERT_TRUE(ogre.ok());
  EXPECT_EQ(ogre->num_ptex_faces(), 1928);  // data README: 1308 faces -> 1928 Ptex faces
  // Non-manifold edges are sharpened by OpenSubdiv: two normals there, so they are listed.
  StatusOr<LimitSurface> fan = LimitSurface::Build(ReadOrDie("opensubdiv/catmark_fan.obj"));
  ASSERT_TRUE(fan.ok());
  EXPECT_EQ(fan->stats().non_manifold_edges, 4);  // data README: 4 non-manifold edges
  EXPECT_GE(fan->stats().inf_sharp_edges, 4);
  // OpenSubdiv 3.5's Bfr mishandles neighbourhoods of interior valence-2 vertices: those
  // faces go through a patch table (and still match the oracle above).
  StatusOr<LimitSurface> val2 =
      LimitSurface::Build(ReadOrDie("opensubdiv/catmark_val2_interior.obj"));
  ASSERT_TRUE(val2.ok());
  EXPECT_GT(val2->stats().patch_table_faces, 0);
  EXPECT_EQ(ogre->stats().patch_table_faces, 0);
  StatusOr<LimitSurface> spot = LimitSurface::Build(ReadOrDie("keenan_spot/spot_control_mesh.obj"));
  ASSERT_TRUE(spot.ok());
  EXPECT_EQ(spot->num_ptex_faces(), 252);
  StatusOr<LimitSurface> blub = LimitSurface::Build(ReadOrDie("keenan_blub/blub_control_mesh.obj"));
  ASSERT_TRUE(blub.ok());
  EXPECT_EQ(blub->num_ptex_faces(), 144);
}

// ---- Tags that change the surface: t creasemethod, t smoothtriangles ----------------------

// catmark_smoothtris0 (all triangles) with its `t smoothtriangles 0/0/1 catmark` made
// `smooth`: OpenSubdiv's smooth-triangle rule.
Mesh SmoothTriangles() {
  const std::string path = DataPath("opensubdiv/catmark_smoothtris0.obj");
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string tag = "t smoothtriangles 0/0/1 catmark";
  const std::size_t at = text.find(tag);
  EXPECT_NE(at, std::string::npos);
  if (at != std::string::npos) text.replace(at, tag.size(), "t smoothtriangles 0/0/1 smooth");
  StatusOr<Mesh> mesh = ParseObj(text, path);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return mesh.ok() ? std::move(mesh).value() : Mesh{};
}

TEST(TagOptionsTest, SmoothTrianglesMatchPatchTable) {
  const Mesh mesh = SmoothTriangles();
  ASSERT_EQ(mesh.tags.triangles, TriangleSubdivision::kSmooth);
  const OracleComparison c = CompareWithOracle(mesh, {}, 6);
  ASSERT_TRUE(c.built) << c.error;
  EXPECT_GT(c.samples, 0);
  EXPECT_LT(c.max_position_error, 1e-5);
  EXPECT_LT(c.max_normal_angle_regular, 1e-4);
  EXPECT_GT(c.mean_outward, 0.0);
}

TEST(TagOptionsTest, SmoothTrianglesRefineLikeFar) {
  ExpectRefinementMatchesFar(SmoothTriangles(), 3, "catmark_smoothtris0 (smooth)");
}

// Largest distance between the limit surfaces of two cages of the same topology (texel
// centres of a 9 x 9 grid on every Ptex face), / bounding-box diagonal. `fast_path_equal`:
// whether every face `a` evaluates on the regular fast path is the same on both.
struct SurfaceDifference {
  double max = 0;
  int fast_path_faces = 0;
  bool fast_path_equal = true;
};

SurfaceDifference Difference(const Mesh& a, const Mesh& b) {
  SurfaceDifference out;
  StatusOr<LimitSurface> sa = LimitSurface::Build(a);
  StatusOr<LimitSurface> sb = LimitSurface::Build(b);
  EXPECT_TRUE(sa.ok() && sb.ok());
  if (!sa.ok() || !sb.ok()) return out;
  LimitEvaluator ea(*sa), eb(*sb);
  constexpr int kN = 9;
  std::vector<float> pa(3 * kN * kN), pb(3 * kN * kN);
  const double diag = subdiv_test::BoundsDiagonal(a);
  for (int f = 0; f < sa->num_ptex_faces(); ++f) {
    const std::int64_t regular_before = ea.stats().regular_faces;
    EXPECT_TRUE(ea.EvaluateGrid(PtexFaceId(f), kN, kN, pa, {}).ok());
    EXPECT_TRUE(eb.EvaluateGrid(PtexFaceId(f), kN, kN, pb, {}).ok());
    double face_max = 0;
    for (int i = 0; i < kN * kN; ++i) {
      const double d[3] = {pa[3 * i] - pb[3 * i], pa[3 * i + 1] - pb[3 * i + 1],
                           pa[3 * i + 2] - pb[3 * i + 2]};
      face_max = std::max(face_max, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / diag);
    }
    out.max = std::max(out.max, face_max);
    if (ea.stats().regular_faces > regular_before) {
      ++out.fast_path_faces;
      out.fast_path_equal = out.fast_path_equal && face_max == 0;
    }
  }
  return out;
}

// Each option moves the surface far beyond the oracle tolerances above (1e-5 of the
// diagonal), so the oracle tests would fail if the option were dropped. Faces on the regular
// fast path are the same under both options: it is never used where an option matters.
TEST(TagOptionsTest, OptionsChangeTheSurface) {
  const Mesh chaikin = ReadOrDie("dispex/chaikin_box.obj");
  ASSERT_EQ(chaikin.tags.crease_method, CreaseMethod::kChaikin);
  Mesh uniform = chaikin;
  uniform.tags.crease_method = CreaseMethod::kUniform;
  const SurfaceDifference creases = Difference(chaikin, uniform);
  EXPECT_GT(creases.max, 1e-3);
  EXPECT_GT(creases.fast_path_faces, 0);
  EXPECT_TRUE(creases.fast_path_equal);

  const Mesh smooth = SmoothTriangles();
  Mesh catmark = smooth;
  catmark.tags.triangles = TriangleSubdivision::kCatmark;
  const SurfaceDifference triangles = Difference(smooth, catmark);
  EXPECT_GT(triangles.max, 1e-3);
  std::printf("  chaikin vs uniform %.3e (%d fast-path faces), smooth vs catmark %.3e\n",
              creases.max, creases.fast_path_faces, triangles.max);

  // Uniform refinement too (the refined cage of each option against the other's).
  for (const auto& [x, y] : {std::pair(&chaikin, &uniform), std::pair(&smooth, &catmark)}) {
    StatusOr<LimitSurface> sx = LimitSurface::Build(*x);
    StatusOr<LimitSurface> sy = LimitSurface::Build(*y);
    ASSERT_TRUE(sx.ok() && sy.ok());
    StatusOr<RefinedMesh> rx = RefineUniform(*sx, 2);
    StatusOr<RefinedMesh> ry = RefineUniform(*sy, 2);
    ASSERT_TRUE(rx.ok() && ry.ok());
    ASSERT_EQ(rx->mesh.num_vertices(), ry->mesh.num_vertices());
    double max = 0;
    for (std::size_t v = 0; v < rx->mesh.num_vertices(); ++v) {
      const Float3 &p = rx->mesh.positions[v], &q = ry->mesh.positions[v];
      max = std::max({max, std::abs(double(p.x) - q.x), std::abs(double(p.y) - q.y),
                      std::abs(double(p.z) - q.z)});
    }
    EXPECT_GT(max / subdiv_test::BoundsDiagonal(*x), 1e-3) << x->source;
  }
}

}  // namespace
}  // namespace dispex
