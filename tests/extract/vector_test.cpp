// Vector displacement maps: D = sculpt - limit surface, read through the correspondence.
// The expected D at a sample comes from OpenSubdiv's own uniform refinement (RefineUniform
// with face charts: every sculpt quad's Ptex face and corner (u, v)), not from the
// correspondence: the displacements of the sculpt quad's corners from their limit points,
// corrected for the blend of the samples around each vertex (D - (m / 4n) L D, L D the sum of
// the vertex's four neighbours in the sculpt's own edges - 4 D; none at a grid corner or on an
// open border: src/extract/mapping/vertex_displacements.h), bilinear over the quad.
//  - At full resolution every texel equals it to float rounding, in every space (rejects a
//    wrong cell, a rotated or mirrored grid, a wrong frame, derivatives on the wrong scale).
//  - Under the bound rule every sample's per-face read-back is within the tolerance of it
//    (rejects dropped detail, a wrong resolution rule, channels analysed apart).
//  - With --watertight all the outermost texels hold D on the face's edges: the per-face
//    reader then meets the exact D on every truth record, borders included (rejects the
//    default's texels half a texel inside, which miss it at face borders).
//  - By default faces are raised until D's step in object space where faces meet, read
//    through the cross-face filter, is within the tolerance (rejects the map without rounds).
//  - The map records its space; a sculpt that is not the base refined fails with the reason
//    and writes nothing; the file does not depend on the thread count.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"
#include "e2e_support.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::SculptOptions;
using testing::TempDir;

// Sculpt vertex ids by (Ptex face, i, j) on the face's grid of n x n cells, from OpenSubdiv's
// refinement of the cage (make-sculpt writes its faces in that order).
struct ReferenceGrid {
  std::map<std::tuple<int, int, int>, int> vertex;
  std::vector<int> cells;  // per Ptex face: n
  // Per sculpt vertex: L D from the sculpt's edges, each vertex's D at its limit point.
  std::vector<std::array<double, 3>> bend;
};

// L D per sculpt vertex: its four edge neighbours' D - 4 D, D = the vertex minus its limit
// point (at one of its grid places); 0 at a corner of any face's grid and where the vertex has
// another number of neighbours (an open border).
std::vector<std::array<double, 3>> Bends(const ReferenceGrid& ref, const LimitSurface& surface,
                                         const Mesh& sculpt) {
  const std::size_t count = sculpt.positions.size();
  std::vector<std::array<double, 3>> d(count), bend(count, {0, 0, 0});
  std::vector<std::uint8_t> corner(count, 0);
  LimitEvaluator eval(surface);
  for (const auto& [place, id] : ref.vertex) {
    const auto [f, i, j] = place;
    const int n = ref.cells[static_cast<std::size_t>(f)];
    if ((i == 0 || i == n) && (j == 0 || j == n)) corner[static_cast<std::size_t>(id)] = 1;
    const float uv[2] = {static_cast<float>(i) / n, static_cast<float>(j) / n};
    float p[3];
    EXPECT_TRUE(eval.EvaluatePoints(PtexFaceId(f), uv, p, {}).ok());
    const Float3 q = sculpt.positions[static_cast<std::size_t>(id)];
    d[static_cast<std::size_t>(id)] = {double(q.x) - p[0], double(q.y) - p[1], double(q.z) - p[2]};
  }
  std::vector<std::set<int>> neighbours(count);
  for (std::size_t q = 0; q < sculpt.num_faces(); ++q) {
    for (std::size_t c = 0; c < 4; ++c) {
      const int a = sculpt.face_indices[4 * q + c], b = sculpt.face_indices[4 * q + (c + 1) % 4];
      neighbours[static_cast<std::size_t>(a)].insert(b);
      neighbours[static_cast<std::size_t>(b)].insert(a);
    }
  }
  for (std::size_t v = 0; v < count; ++v) {
    if (corner[v] || neighbours[v].size() != 4) continue;
    for (int k = 0; k < 3; ++k) {
      bend[v][k] = -4 * d[v][k];
      for (const int w : neighbours[v]) bend[v][k] += d[static_cast<std::size_t>(w)][k];
    }
  }
  return bend;
}

ReferenceGrid BuildReference(const LimitSurface& surface, int levels, const Mesh& sculpt) {
  ReferenceGrid ref;
  RefineOptions refine;
  refine.face_charts = true;
  auto refined = RefineUniform(surface, levels, refine);
  EXPECT_TRUE(refined.ok()) << refined.status().message();
  EXPECT_EQ(refined->mesh.num_faces(), sculpt.num_faces());
  ref.cells.resize(static_cast<std::size_t>(surface.num_ptex_faces()));
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    ref.cells[static_cast<std::size_t>(f)] =
        surface.num_ptex_faces(surface.base_face(PtexFaceId(f))) == 1 ? 1 << levels
                                                                      : 1 << (levels - 1);
  }
  for (std::size_t q = 0; q < refined->mesh.num_faces(); ++q) {
    const int f = refined->face_ptex[q].value;
    const int n = ref.cells[static_cast<std::size_t>(f)];
    for (int c = 0; c < 4; ++c) {
      const int i = static_cast<int>(std::lround(refined->face_uvs[8 * q + 2 * c] * n));
      const int j = static_cast<int>(std::lround(refined->face_uvs[8 * q + 2 * c + 1] * n));
      ref.vertex[{f, i, j}] = sculpt.face_indices[4 * q + static_cast<std::size_t>(c)];
    }
  }
  ref.bend = Bends(ref, surface, sculpt);
  return ref;
}

// D at (u, v) of `face` sampled `samples` a side (ExtractMethod::kInterpolate): the
// displacements of the sculpt quad's corners from the limit points at their grid places,
// corrected for the blend, bilinear over the quad.
Float3 ExpectedD(const ReferenceGrid& ref, const Mesh& sculpt, LimitEvaluator& eval, int face,
                 float u, float v, int samples) {
  const int n = ref.cells[static_cast<std::size_t>(face)];
  const double sharpen = double(n) / (4.0 * samples);
  const int i = std::min(static_cast<int>(u * n), n - 1),
            j = std::min(static_cast<int>(v * n), n - 1);
  const double s = u * n - i, t = v * n - j;
  auto at = [&](int di, int dj) {
    const int id = ref.vertex.at({face, i + di, j + dj});
    const Float3 q = sculpt.positions[static_cast<std::size_t>(id)];
    const float uv[2] = {static_cast<float>(i + di) / n, static_cast<float>(j + dj) / n};
    float p[3];
    EXPECT_TRUE(eval.EvaluatePoints(PtexFaceId(face), uv, p, {}).ok());
    const std::array<double, 3>& bend = ref.bend[static_cast<std::size_t>(id)];
    return std::array<double, 3>{double(q.x) - p[0] - sharpen * bend[0],
                                 double(q.y) - p[1] - sharpen * bend[1],
                                 double(q.z) - p[2] - sharpen * bend[2]};
  };
  const auto a = at(0, 0), b = at(1, 0), c = at(1, 1), d = at(0, 1);
  double out[3];
  for (int k = 0; k < 3; ++k) {
    out[k] = (1 - s) * (1 - t) * a[k] + s * (1 - t) * b[k] + s * t * c[k] + (1 - s) * t * d[k];
  }
  return {static_cast<float>(out[0]), static_cast<float>(out[1]), static_cast<float>(out[2])};
}

// The object-space D a map holds at texel (i, j) of `face`'s samples: the channels read by
// the per-face reader, through the frame there.
Float3 MapD(const PtexFile& map, VectorSpace space, LimitEvaluator& eval, int face, float u,
            float v) {
  const float uv[2] = {u, v};
  float p[3], n[3], du[3], dv[3];
  EXPECT_TRUE(eval.EvaluatePointFrames(PtexFaceId(face), uv, {p, n, du, dv}).ok());
  const float c[3] = {map.Sample(PtexFaceId(face), u, v, 0), map.Sample(PtexFaceId(face), u, v, 1),
                      map.Sample(PtexFaceId(face), u, v, 2)};
  return VectorFromChannels(space,
                            {{du[0], du[1], du[2]}, {dv[0], dv[1], dv[2]}, {n[0], n[1], n[2]}}, c);
}

double Distance(const Float3& a, const Float3& b) {
  return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) +
                   (a.z - b.z) * (a.z - b.z));
}

struct Case {
  const char* cage;
  int levels;
  // The cage scaled by this: |dP/du| far from 1, where parametric channels (not lengths) would
  // hold the tolerance in channel units only.
  float scale = 1;
  Pattern pattern = Pattern::kDetail;
};

class VectorMapTest : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    cage_ = DataPath(std::string("meshes/opensubdiv/") + GetParam().cage);
    if (GetParam().scale != 1) {
      auto cage = ReadMesh(cage_);
      ASSERT_TRUE(cage.ok());
      for (Float3& p : cage->positions) {
        p = {p.x * GetParam().scale, p.y * GetParam().scale, p.z * GetParam().scale};
      }
      cage_ = dir_ / "cage.obj";
      ASSERT_TRUE(WriteObj(cage_, *cage).ok());
    }
    auto made = MakeSculpt(SculptOptions(cage_, dir_ / "sculpt.obj", GetParam().levels,
                                         GetParam().pattern, 0.02 * GetParam().scale));
    ASSERT_TRUE(made.ok()) << made.status().message();
    auto base = ReadMesh(cage_);
    ASSERT_TRUE(base.ok());
    auto sculpt = ReadMesh(dir_ / "sculpt.obj");
    ASSERT_TRUE(sculpt.ok());
    sculpt_ = std::move(sculpt).value();
    auto surface = LimitSurface::Build(*base);
    ASSERT_TRUE(surface.ok());
    surface_.emplace(std::move(surface).value());
    ref_ = BuildReference(*surface_, GetParam().levels, sculpt_);
  }

  ExtractOptions Options(VectorSpace space) const {
    ExtractOptions o;
    o.base_path = cage_;
    o.sculpt_path = dir_ / "sculpt.obj";
    o.output_path = dir_ / "map.ptx";
    o.vector = space;
    return o;
  }

  void ExpectWithinTolerance(VectorSpace space);

  TempDir dir_;
  std::string cage_;
  Mesh sculpt_;
  std::optional<LimitSurface> surface_;
  ReferenceGrid ref_;
};

TEST_P(VectorMapTest, FullResolutionHoldsTheSculptAtEverySample) {
  const int samples = 2 << GetParam().levels;
  for (VectorSpace space :
       {VectorSpace::kTangent, VectorSpace::kParametric, VectorSpace::kObject}) {
    ExtractOptions o = Options(space);
    o.oversample = samples;
    o.resolution_rule = ResolutionRule::kFixed;
    o.fixed_ulog2 = o.fixed_vlog2 = GetParam().levels + 1;
    auto report = Extract(o);
    ASSERT_TRUE(report.ok()) << report.status().message();
    EXPECT_EQ(report->method.levels, GetParam().levels);
    auto map = PtexFile::Open(o.output_path);
    ASSERT_TRUE(map.ok());
    LimitEvaluator eval(*surface_);
    double worst = 0, largest = 0;
    for (int f = 0; f < surface_->num_ptex_faces(); ++f) {
      if (surface_->is_hole(PtexFaceId(f))) continue;
      const int n = map->face_info(PtexFaceId(f)).ures();
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const float u = (i + 0.5f) / n, v = (j + 0.5f) / n;
          const Float3 want = ExpectedD(ref_, sculpt_, eval, f, u, v, n);
          worst = std::max(worst, Distance(MapD(*map, space, eval, f, u, v), want));
          largest = std::max(largest, Distance(want, {0, 0, 0}));
        }
      }
    }
    EXPECT_GT(largest, 1e-3) << "the sculpt is displaced";
    EXPECT_LT(worst, 1e-5 * (1 + largest)) << VectorSpaceName(space);
  }
}

TEST_P(VectorMapTest, BoundRuleKeepsEverySampleWithinTheTolerance) {
  for (VectorSpace space : {VectorSpace::kTangent, VectorSpace::kParametric}) {
    ExpectWithinTolerance(space);
  }
}

void VectorMapTest::ExpectWithinTolerance(VectorSpace space) {
  SCOPED_TRACE(VectorSpaceName(space));
  ExtractOptions o = Options(space);
  auto report = Extract(o);
  ASSERT_TRUE(report.ok()) << report.status().message();
  if (GetParam().pattern == Pattern::kDetail) {
    EXPECT_LT(report->spectral.texels_after, report->spectral.texels_before);
  }
  auto map = PtexFile::Open(o.output_path);
  ASSERT_TRUE(map.ok());
  EXPECT_EQ(map->header().num_channels, 3);
  EXPECT_EQ(map->header().edge_filter, PtexEdgeFilterMode::kTangentVector);
  ASSERT_NE(map->FindMetaData("dispex:vector_space"), nullptr);
  EXPECT_EQ(map->FindMetaData("dispex:vector_space")->AsString(), VectorSpaceName(space));
  EXPECT_EQ(map->FindMetaData("dispex:channels")->AsString(), VectorSpaceChannels(space));
  LimitEvaluator eval(*surface_);
  const int samples = 2 << GetParam().levels;
  double worst = 0;
  for (int f = 0; f < surface_->num_ptex_faces(); ++f) {
    if (surface_->is_hole(PtexFaceId(f))) continue;
    const int n = ref_.cells[static_cast<std::size_t>(f)] * 2;
    ASSERT_LE(n, samples);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const float u = (i + 0.5f) / n, v = (j + 0.5f) / n;
        worst = std::max(worst, Distance(MapD(*map, space, eval, f, u, v),
                                         ExpectedD(ref_, sculpt_, eval, f, u, v, n)));
      }
    }
  }
  EXPECT_LE(worst, report->settings.tolerance * (1 + 1e-3) + 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Cages, VectorMapTest,
                         ::testing::Values(Case{"catmark_cube.obj", 3},
                                           Case{"catmark_cube.obj", 3, 16, Pattern::kSideways},
                                           Case{"catmark_nonquads.obj", 3, 1, Pattern::kOverhang},
                                           Case{"catmark_nonquads.obj", 2},
                                           Case{"catmark_edgecorner.obj", 3},
                                           Case{"catmark_hole_test1.obj", 2}),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           std::string name = param.param.cage;
                           name = name.substr(0, name.find('.'));
                           if (param.param.scale != 1) name += "_scaled";
                           return name + "_" + std::string(PatternName(param.param.pattern));
                         });

TEST(VectorMapErrors, SculptThatIsNotARefinementFailsAndWritesNothing) {
  TempDir dir;
  const std::string cage = DataPath("meshes/opensubdiv/catmark_cube.obj");
  ASSERT_TRUE(MakeSculpt(testing::JitteredSculptOptions(cage, dir / "sculpt.obj", 8,
                                                        Pattern::kSmooth, 0.01))
                  .ok());
  ExtractOptions o;
  o.base_path = cage;
  o.sculpt_path = dir / "sculpt.obj";
  o.output_path = dir / "map.ptx";
  o.vector = VectorSpace::kObject;
  auto report = Extract(o);
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.status().message().find("correspondence"), std::string::npos)
      << report.status().message();
  EXPECT_FALSE(testing::fs::exists(o.output_path));
}

TEST(VectorMapDeterminism, SameBytesAtAnyThreadCount) {
  TempDir dir;
  const std::string cage = DataPath("meshes/opensubdiv/catmark_nonquads.obj");
  ASSERT_TRUE(MakeSculpt(SculptOptions(cage, dir / "sculpt.obj", 3, Pattern::kDetail, 0.02)).ok());
  std::string bytes[2];
  for (int k = 0; k < 2; ++k) {
    ExtractOptions o;
    o.base_path = cage;
    o.sculpt_path = dir / "sculpt.obj";
    o.output_path = dir / "map.ptx";
    o.vector = VectorSpace::kParametric;
    o.threads = k == 0 ? 1 : 3;
    ASSERT_TRUE(Extract(o).ok());
    bytes[k] = testing::Slurp(o.output_path);
  }
  EXPECT_EQ(bytes[0], bytes[1]);
}

// The overhang changes fast across face borders: read per face, the default map misses the
// exact D there (31 of 1,164 records over their bound, measured); with pinned edges none is.
TEST(VectorMapEdges, AllPinsEdgesSoThePerFaceReaderMeetsTheTruthAtBorders) {
  TempDir dir;
  const std::string cage = DataPath("meshes/opensubdiv/catmark_nonquads.obj");
  ASSERT_TRUE(
      MakeSculpt(SculptOptions(cage, dir / "sculpt.obj", 3, Pattern::kOverhang, 0.02)).ok());
  std::size_t over[2] = {0, 0};
  for (WatertightEdges mode : {WatertightEdges::kFilter, WatertightEdges::kAll}) {
    SCOPED_TRACE(WatertightEdgesName(mode));
    ExtractOptions o;
    o.base_path = cage;
    o.sculpt_path = dir / "sculpt.obj";
    o.output_path = dir / "map.ptx";
    o.vector = VectorSpace::kObject;
    o.watertight = mode;
    auto report = Extract(o);
    ASSERT_TRUE(report.ok()) << report.status().message();
    const bool all = mode == WatertightEdges::kAll;
    EXPECT_EQ(report->edges.rule, mode);
    VerifyOptions v;
    v.base_path = cage;
    v.sculpt_path = dir / "sculpt.obj";
    v.map_path = o.output_path;
    v.truth_path = dir / "sculpt.obj.truth";
    auto verified = Verify(v);
    ASSERT_TRUE(verified.ok()) << verified.status().message();
    EXPECT_EQ(verified->truth_quantity, "|D_map - D|");
    over[all] = verified->truth_over_bound;
    if (all) {
      EXPECT_LE(verified->truth_worst_ratio, 0.5);
    }
  }
  EXPECT_GT(over[0], 10u) << "the case must show the border error";
  EXPECT_EQ(over[1], 0u);
}

// Under the cross-face filter a face coarser than its neighbour steps where they meet: Spot's
// overhang without the rounds steps by 1.85 (object) and 1.06 (tangent) tolerances, measured.
// The default (`filter`) raises faces until D's step in object space is within the tolerance
// on every edge, as verify measures it (rejects rounds that do not run; the step checked is
// verify's, of D, whatever the rounds measure).
TEST(VectorMapEdges, FilterHoldsTheCrossFaceStepsOfD) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  // Amplitude 0: 1% of the cage's bounding-box diagonal, as `make-sculpt` by default.
  ASSERT_TRUE(MakeSculpt(SculptOptions(cage, dir / "sculpt.obj", 3, Pattern::kOverhang, 0)).ok());
  for (VectorSpace space : {VectorSpace::kObject, VectorSpace::kTangent}) {
    for (WatertightEdges mode : {WatertightEdges::kOff, WatertightEdges::kFilter}) {
      SCOPED_TRACE(std::string(VectorSpaceName(space)) + " " +
                   std::string(WatertightEdgesName(mode)));
      ExtractOptions o;
      o.base_path = cage;
      o.sculpt_path = dir / "sculpt.obj";
      o.output_path = dir / "map.ptx";
      o.vector = space;
      o.watertight = mode;
      auto report = Extract(o);
      ASSERT_TRUE(report.ok()) << report.status().message();
      EXPECT_EQ(report->edges.rule, mode);
      VerifyOptions v;
      v.base_path = cage;
      v.sculpt_path = dir / "sculpt.obj";
      v.map_path = o.output_path;
      auto verified = Verify(v);
      ASSERT_TRUE(verified.ok()) << verified.status().message();
      ASSERT_TRUE(verified->measured_edges);
      const double tau = report->settings.tolerance;
      const double step = verified->edge_across_faces.max;
      if (mode == WatertightEdges::kOff) {
        std::printf("%s without the rounds: step %.3g tolerances\n",
                    std::string(VectorSpaceName(space)).c_str(), step / tau);
        EXPECT_GT(step, tau) << "the case must step";
        continue;
      }
      EXPECT_GT(report->edges.raised_faces, 0);
      EXPECT_EQ(report->edges.over, 0);
      EXPECT_LE(report->edges.step_across_faces, tau);
      EXPECT_NEAR(step, report->edges.step_across_faces, 1e-6 * tau);
      EXPECT_LE(step, tau);
    }
  }
}

}  // namespace
}  // namespace dispex
