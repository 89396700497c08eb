// Vector displacement: the vector patterns' sculpts and truth files, and verify on vector maps
// that the tests write themselves (a pattern's exact D at texel centres, in every space)
// against those sculpts and truths, with the wrong maps each check must reject.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>

#include "../extract/e2e_support.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/ptex_sampler.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"
#include "vector_map_support.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::PatternMapOptions;
using testing::RunDispex;
using testing::Slurp;
using testing::TempDir;
using testing::WritePatternMap;

const char* const kSpot = "meshes/keenan_spot/spot_control_mesh.obj";
constexpr VectorSpace kSpaces[] = {VectorSpace::kTangent, VectorSpace::kParametric,
                                   VectorSpace::kObject};

double Norm(const double d[3]) {
  return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

double Diagonal(const std::string& cage) {
  auto mesh = ReadMesh(cage);
  EXPECT_TRUE(mesh.ok());
  return mesh.ok() ? ComputeBounds(*mesh).diagonal() : 1;
}

// ---- The patterns --------------------------------------------------------------------------

// Rejects: wrong names, a scalar pattern whose D is not h N, an overhang off its formula, a
// sideways pattern with a normal part.
TEST(VectorPatterns, NamesAndDefinitions) {
  EXPECT_EQ(*ParsePattern("sideways"), Pattern::kSideways);
  EXPECT_EQ(*ParsePattern("overhang"), Pattern::kOverhang);
  EXPECT_EQ(PatternName(Pattern::kOverhang), "overhang");
  EXPECT_TRUE(IsVectorPattern(Pattern::kSideways));
  EXPECT_TRUE(IsVectorPattern(Pattern::kOverhang));
  EXPECT_FALSE(IsVectorPattern(Pattern::kDetail));
  auto bad = ParsePattern("sidewise");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("sideways, overhang"), std::string::npos);

  PatternFrame frame;
  frame.diagonal = 2;
  frame.edge = 0.01;
  frame.amplitude = 0.05;
  const float p[3] = {0.3f, -0.2f, 0.1f};
  const float up[3] = {0, 0, 1};
  double d[3];
  EvaluatePatternVector(Pattern::kSmooth, frame, p, up, d);
  EXPECT_EQ(d[0], 0);
  EXPECT_EQ(d[1], 0);
  EXPECT_EQ(d[2], EvaluatePattern(Pattern::kSmooth, frame, p));
  // Overhang: A sin(theta) N + (2 / k) sin(theta) (a - (a.N) N), theta = k a.p + 0.7,
  // lambda = max(4 A, 16 e) = 0.2 here.
  const double k = 2 * M_PI / 0.2, a[3] = {0.8, 0.48, 0.36};
  const double theta = k * (a[0] * 0.3f + a[1] * -0.2f + a[2] * 0.1f) + 0.7;
  EvaluatePatternVector(Pattern::kOverhang, frame, p, up, d);
  EXPECT_NEAR(d[0], 2 / k * std::sin(theta) * a[0], 1e-12);
  EXPECT_NEAR(d[1], 2 / k * std::sin(theta) * a[1], 1e-12);
  EXPECT_NEAR(d[2], 0.05 * std::sin(theta), 1e-12);
  EXPECT_NEAR(EvaluatePattern(Pattern::kOverhang, frame, p), d[2], 1e-12);
  // lambda = 16 e when that is longer.
  frame.edge = 0.02;
  const double k2 = 2 * M_PI / 0.32, theta2 = k2 * (theta - 0.7) / k + 0.7;
  EvaluatePatternVector(Pattern::kOverhang, frame, p, up, d);
  EXPECT_NEAR(d[2], 0.05 * std::sin(theta2), 1e-12);
  // Sideways: tangential only, whatever the normal, and not zero.
  const std::array<float, 3> normals[] = {{0, 0, 1}, {0.6f, 0.8f, 0}, {0.48f, 0.6f, 0.64f}};
  for (const auto& n : normals) {
    EvaluatePatternVector(Pattern::kSideways, frame, p, n.data(), d);
    // To the rounding of the float normal's length.
    EXPECT_NEAR(d[0] * n[0] + d[1] * n[1] + d[2] * n[2], 0, 1e-6 * Norm(d));
    EXPECT_GT(Norm(d), 0.01 * frame.amplitude);
    EXPECT_EQ(EvaluatePattern(Pattern::kSideways, frame, p), 0);
  }
}

// ---- Sculpts and truth files -----------------------------------------------------------------

struct SculptCase {
  Pattern pattern;
  int density;  // 0: refined 4 times
};

std::string SculptCaseName(const ::testing::TestParamInfo<SculptCase>& param) {
  return std::string(PatternName(param.param.pattern)) +
         (param.param.density ? "_jittered" : "_refined");
}

class VectorSculpt : public ::testing::TestWithParam<SculptCase> {};

// Every sculpt vertex is the limit point of its record plus the record's D, D is the pattern's
// at that point, and h = D.N. Rejects: vertices moved along the normal only, a truth whose D
// is not the sculpt's, h that is not the normal part; sideways with a normal part; overhang
// without its tangential shear.
TEST_P(VectorSculpt, TruthIsTheSculptsDisplacement) {
  const SculptCase& c = GetParam();
  TempDir dir;
  const std::string cage = DataPath(kSpot);
  const double diagonal = Diagonal(cage);
  MakeSculptOptions make =
      c.density ? testing::JitteredSculptOptions(cage, dir / "s.obj", c.density, c.pattern,
                                                 0.004 * diagonal)
                : testing::SculptOptions(cage, dir / "s.obj", 4, c.pattern, 0.004 * diagonal);
  auto made = MakeSculpt(make);
  ASSERT_TRUE(made.ok()) << made.status().message();
  auto sculpt = ReadMesh(make.output_path);
  ASSERT_TRUE(sculpt.ok());
  auto truth = ReadGroundTruth(make.output_path + ".truth");
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  EXPECT_EQ(truth->version(), 3);
  ASSERT_EQ(truth->size(), sculpt->num_vertices());
  ASSERT_EQ(truth->d.size(), 3 * truth->size());
  auto base = ReadMesh(cage);
  auto surface = LimitSurface::Build(*base);
  ASSERT_TRUE(surface.ok());
  LimitEvaluator evaluator(*surface);
  double worst_vertex = 0, worst_pattern = 0, worst_h = 0, max_normal = 0, max_tangential = 0;
  for (std::size_t i = 0; i < truth->size(); ++i) {
    float p[3], n[3];
    ASSERT_TRUE(evaluator.EvaluatePoints(truth->faces[i], {&truth->uvs[2 * i], 2}, p, n).ok());
    const float* d = &truth->d[3 * i];
    const Float3& q = sculpt->positions[i];
    const double err[3] = {q.x - (p[0] + double(d[0])), q.y - (p[1] + double(d[1])),
                           q.z - (p[2] + double(d[2]))};
    worst_vertex = std::max(worst_vertex, Norm(err));
    double want[3];
    EvaluatePatternVector(c.pattern, made->frame, p, n, want);
    const double diff[3] = {want[0] - d[0], want[1] - d[1], want[2] - d[2]};
    worst_pattern = std::max(worst_pattern, Norm(diff));
    const double dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
    worst_h = std::max(worst_h, std::abs(dn - truth->h[i]));
    max_normal = std::max(max_normal, std::abs(dn));
    const double t[3] = {d[0] - dn * n[0], d[1] - dn * n[1], d[2] - dn * n[2]};
    max_tangential = std::max(max_tangential, Norm(t));
  }
  const double A = made->amplitude;
  // Float positions of size ~1 and limit points that the refined layout takes from OpenSubdiv's
  // refinement, the check from Bfr: both within 1e-5 of the diagonal.
  EXPECT_LE(worst_vertex, 1e-5 * diagonal);
  EXPECT_LE(worst_pattern, 1e-5 * diagonal);
  EXPECT_LE(worst_h, 1e-5 * A);
  EXPECT_NEAR(made->max_tangential, max_tangential, 1e-3 * A);
  if (c.pattern == Pattern::kSideways) {
    EXPECT_LE(max_normal, 1e-5 * A);
    EXPECT_LE(std::max(std::abs(made->h_min), std::abs(made->h_max)), 1e-5 * A);
    EXPECT_GT(max_tangential, 0.5 * A);
  } else {
    // The shear: up to lambda / pi, lambda >= 16 e.
    EXPECT_GT(max_tangential, 0.9 * 16 * made->edge / M_PI);
    EXPECT_NEAR(max_normal, A, 0.05 * A);
    EXPECT_GT(made->folded_faces, made->faces / 20) << "the overhang's run-back sheets";
  }
  // Folded faces of a vector pattern keep a finite local error.
  for (float e : truth->local_error) ASSERT_TRUE(std::isfinite(e));
}

INSTANTIATE_TEST_SUITE_P(Patterns, VectorSculpt,
                         ::testing::Values(SculptCase{Pattern::kSideways, 0},
                                           SculptCase{Pattern::kOverhang, 0},
                                           SculptCase{Pattern::kSideways, 8},
                                           SculptCase{Pattern::kOverhang, 8}),
                         SculptCaseName);

// How many times the line P + t N, |t| <= reach, meets the sculpt, for limit points P on a
// grid of every Ptex face.
std::vector<int> NormalLineCrossings(const std::string& cage, const Mesh& sculpt, double reach,
                                     int grid) {
  auto base = ReadMesh(cage);
  auto surface = LimitSurface::Build(*base);
  auto tracer = MakeEmbreeTracer(sculpt);
  EXPECT_TRUE(tracer.ok());
  LimitEvaluator evaluator(*surface);
  std::vector<int> counts;
  std::vector<float> p(3 * grid * grid), n(3 * grid * grid);
  // Past the last hit by more than rounding, so that a line through an edge is not counted on
  // both faces; sheets closer than that (at the very rim of a fold) count as one.
  const float step = static_cast<float>(1e-3 * reach);
  for (int f = 0; f < surface->num_ptex_faces(); ++f) {
    if (!evaluator.EvaluateGrid(PtexFaceId(f), grid, grid, p, n).ok()) continue;
    for (int i = 0; i < grid * grid; ++i) {
      Ray ray;
      ray.direction = {n[3 * i], n[3 * i + 1], n[3 * i + 2]};
      ray.origin = {static_cast<float>(p[3 * i] - reach * n[3 * i]),
                    static_cast<float>(p[3 * i + 1] - reach * n[3 * i + 1]),
                    static_cast<float>(p[3 * i + 2] - reach * n[3 * i + 2])};
      ray.tfar = static_cast<float>(2 * reach);
      int count = 0;
      for (;;) {
        RayHit hit;
        TraceCounters counters;
        (*tracer)->Intersect({&ray, 1}, {&hit, 1}, counters);
        if (!hit.hit()) break;
        ++count;
        ray.tnear = hit.t + step;
        if (ray.tnear > ray.tfar) break;
      }
      counts.push_back(count);
    }
  }
  return counts;
}

// Rejects an overhang that a scalar map along N could hold: lines along N through the fold
// meet the sculpt three times. The control (smooth, same amplitude, which does not fold on
// spot at 0.002 of the diagonal) shows the counting finds one crossing where the surface does
// not fold.
TEST(VectorSculpt, OverhangFoldsAlongTheNormal) {
  TempDir dir;
  const std::string cage = DataPath(kSpot);
  const double diagonal = Diagonal(cage);
  for (Pattern pattern : {Pattern::kOverhang, Pattern::kSmooth}) {
    MakeSculptOptions make =
        testing::SculptOptions(cage, dir / "s.obj", 4, pattern, 0.002 * diagonal);
    auto made = MakeSculpt(make);
    ASSERT_TRUE(made.ok());
    auto sculpt = ReadMesh(make.output_path);
    ASSERT_TRUE(sculpt.ok());
    std::vector<int> counts = NormalLineCrossings(cage, *sculpt, 3 * made->amplitude, 8);
    std::size_t histogram[6] = {0, 0, 0, 0, 0, 0};
    for (int c : counts) ++histogram[std::min(c, 5)];
    // Measured: overhang 7.5% of the lines meet the sculpt 3 times (1.8% none: the sheet lies
    // beyond the reach where the shear carries it around spot's tighter curves; 1.5% twice:
    // grazing the rims of the folds); smooth 16126 of 16128 once, 2 twice.
    if (pattern == Pattern::kOverhang) {
      EXPECT_GT(histogram[3], counts.size() / 20) << "lines through the fold";
    } else {
      EXPECT_EQ(histogram[3], 0u);
      EXPECT_GT(histogram[1], counts.size() * 999 / 1000);
    }
  }
}

// Version 3 round-trips D; versions 1 and 2, written here byte by byte, are still read.
// Rejects: a writer that drops D or mislays its bytes, a reader that no longer reads the older
// versions, inconsistent sizes.
TEST(GroundTruthFile, Version3HoldsDAndOlderVersionsAreRead) {
  TempDir dir;
  dispex::GroundTruth truth;
  truth.faces = {PtexFaceId(3), PtexFaceId(0)};
  truth.uvs = {0.25f, 0.5f, 1.0f, 0.0f};
  truth.h = {0.125f, -2.0f};
  truth.local_error = {0.5f, 0.25f};
  truth.d = {1.0f, 2.0f, 0.125f, -0.5f, 0.0f, -2.0f};
  EXPECT_EQ(truth.version(), 3);
  ASSERT_TRUE(WriteGroundTruth(dir / "t3.truth", truth).ok());
  const std::string bytes = Slurp(dir / "t3.truth");
  ASSERT_EQ(bytes.size(), 24u + 2 * 32);
  std::uint32_t version = 0;
  std::memcpy(&version, bytes.data() + 8, 4);
  EXPECT_EQ(version, 3u);
  float dz = 0;  // the second record's dz: at 24 + 32 + 20 + 8
  std::memcpy(&dz, bytes.data() + 24 + 32 + 28, 4);
  EXPECT_EQ(dz, -2.0f);
  auto back = ReadGroundTruth(dir / "t3.truth");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->faces, truth.faces);
  EXPECT_EQ(back->uvs, truth.uvs);
  EXPECT_EQ(back->h, truth.h);
  EXPECT_EQ(back->local_error, truth.local_error);
  EXPECT_EQ(back->d, truth.d);
  std::ofstream(dir / "short.truth", std::ios::binary) << bytes.substr(0, bytes.size() - 12);
  EXPECT_FALSE(ReadGroundTruth(dir / "short.truth").ok());

  // Versions 1 and 2 by hand: the same records without D (and without e_v).
  for (std::uint32_t v : {1u, 2u}) {
    std::string file = "DISPEXGT";
    auto put = [&](const void* p, std::size_t n) { file.append(static_cast<const char*>(p), n); };
    const std::uint32_t zero = 0;
    const std::uint64_t count = 2;
    put(&v, 4);
    put(&zero, 4);
    put(&count, 8);
    for (std::size_t i = 0; i < 2; ++i) {
      put(&truth.faces[i].value, 4);
      put(&truth.uvs[2 * i], 8);
      put(&truth.h[i], 4);
      if (v == 2) put(&truth.local_error[i], 4);
    }
    const std::string path = dir / (v == 1 ? "v1.truth" : "v2.truth");
    std::ofstream(path, std::ios::binary) << file;
    auto old = ReadGroundTruth(path);
    ASSERT_TRUE(old.ok()) << old.status().message();
    EXPECT_EQ(old->version(), int(v));
    EXPECT_EQ(old->h, truth.h);
    EXPECT_EQ(old->uvs, truth.uvs);
    EXPECT_TRUE(old->d.empty());
    EXPECT_EQ(old->local_error.size(), v == 2 ? 2u : 0u);
  }
  // D without e_v, or of the wrong size, is not written.
  dispex::GroundTruth no_error = truth;
  no_error.local_error.clear();
  EXPECT_FALSE(WriteGroundTruth(dir / "bad.truth", no_error).ok());
  dispex::GroundTruth short_d = truth;
  short_d.d.pop_back();
  auto refused = WriteGroundTruth(dir / "bad.truth", short_d);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.message(),
            (dir / "bad.truth") + ": 5 displacement values for 2 records (3 each)");
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.truth"));
}

// ---- verify on vector maps -------------------------------------------------------------------

// Sculpts of spot (refined 4 times) with the vector patterns, and their truth files.
class VectorMaps : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::filesystem::path(std::filesystem::temp_directory_path() /
                                     ("dispex_VectorMaps_" + std::to_string(::getpid())));
    std::filesystem::create_directories(*dir_);
    cage_ = DataPath(kSpot);
    const double diagonal = Diagonal(cage_);
    for (Pattern pattern : {Pattern::kSideways, Pattern::kOverhang}) {
      const std::string sculpt = Sculpt(pattern);
      auto made = MakeSculpt(testing::SculptOptions(cage_, sculpt, 4, pattern, 0.004 * diagonal));
      ASSERT_TRUE(made.ok()) << made.status().message();
      made_[pattern == Pattern::kOverhang] = *made;
    }
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
    dir_ = nullptr;
  }

  static std::string Sculpt(Pattern pattern) {
    return (*dir_ / (std::string(PatternName(pattern)) + ".obj")).string();
  }
  static const MakeSculptReport& Made(Pattern pattern) {
    return made_[pattern == Pattern::kOverhang];
  }
  static std::string Map(Pattern pattern, const std::string& name, const PatternMapOptions& o) {
    const std::string path =
        (*dir_ / (std::string(PatternName(pattern)) + "_" + name + ".ptx")).string();
    WritePatternMap(cage_, pattern, Made(pattern).frame, path, o);
    return path;
  }
  // verify against the truth (version 3, or `truth`) with tolerance tau, and against the
  // sculpt both ways when `sculpt`.
  static VerifyReport Check(Pattern pattern, const std::string& map, double tau,
                            bool sculpt = false, const std::string& truth = "") {
    VerifyOptions verify;
    verify.base_path = cage_;
    if (sculpt) verify.sculpt_path = Sculpt(pattern);
    verify.map_path = map;
    verify.truth_path = truth.empty() ? Sculpt(pattern) + ".truth" : truth;
    verify.tolerance = tau;
    auto report = Verify(verify);
    EXPECT_TRUE(report.ok()) << report.status().message();
    return report.ok() ? *report : VerifyReport{};
  }
  // The test's tolerance: a tenth of the largest |D|; and the maps' resolution, fine enough for
  // the clamped per-face read within half a texel of an edge (the overhang's D turns fast).
  static double Tau(Pattern pattern) { return 0.1 * Made(pattern).max_displacement; }
  static int Log2(Pattern pattern) { return pattern == Pattern::kOverhang ? 6 : 4; }

  static std::filesystem::path* dir_;  // one folder for the suite
  static std::string cage_;
  static MakeSculptReport made_[2];
};
std::filesystem::path* VectorMaps::dir_ = nullptr;
std::string VectorMaps::cage_;
MakeSculptReport VectorMaps::made_[2];

std::string Describe(const VerifyReport& r) {
  return "truth rms " + std::to_string(r.truth.rms) + " p99 " + std::to_string(r.truth.p99) +
         " max " + std::to_string(r.truth.max) + " over " + std::to_string(r.truth_over_bound) +
         " (" + r.truth_quantity + "); map->sculpt max " + std::to_string(r.map_to_sculpt.max) +
         " sculpt->map max " + std::to_string(r.sculpt_to_map.max) + "; " + r.failure;
}

// Whether (u, v) of Ptex face f lies within `reach` (in u and in v) of a corner at an
// extraordinary point of the limit surface: a cage vertex whose valence is not 4, or the
// centre of an n-gon (n != 4).
bool NearExtraordinaryCorner(const Mesh& cage, const LimitSurface& surface,
                             const std::vector<int>& valence, PtexFaceId f, float u, float v,
                             float reach) {
  const BaseFaceId base = surface.base_face(f);
  const auto verts = cage.face(static_cast<std::size_t>(base.value));
  const int n = static_cast<int>(verts.size());
  const float corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int k = 0; k < 4; ++k) {
    if (std::abs(u - corners[k][0]) > reach || std::abs(v - corners[k][1]) > reach) continue;
    if (n == 4) {
      if (valence[static_cast<std::size_t>(verts[static_cast<std::size_t>(k)])] != 4) return true;
    } else if (k == 0) {  // the n-gon's vertex
      const int corner = surface.sub_face(f);
      if (valence[static_cast<std::size_t>(verts[static_cast<std::size_t>(corner)])] != 4) {
        return true;
      }
    } else if (k == 2) {  // its centre; corners 1 and 3 are edge midpoints
      return true;
    }
  }
  return false;
}

// verify's truth bound recomputed here, record by record, from the map read as a renderer reads
// it: the count of records over the bound, and how many of them lie within two texels of an
// extraordinary corner, and at one.
struct OverBound {
  std::size_t count = 0, near_extraordinary = 0, at_extraordinary = 0;
  double max_error = 0;
};
OverBound RecomputeTruthBound(const std::string& cage_path, const std::string& map_path,
                              const std::string& truth_path, double tau) {
  auto cage = ReadMesh(cage_path);
  auto surface = LimitSurface::Build(*cage);
  auto map = PtexFile::Open(map_path);
  auto truth = ReadGroundTruth(truth_path);
  EXPECT_TRUE(map.ok() && truth.ok() && surface.ok());
  const auto space = ParseVectorSpace(map->FindMetaData(kVectorSpaceMetaKey)->AsString());
  std::vector<int> valence(cage->num_vertices(), 0);
  for (std::int32_t v : cage->face_indices) ++valence[static_cast<std::size_t>(v)];
  LimitEvaluator evaluator(*surface);
  OverBound out;
  for (std::size_t i = 0; i < truth->size(); ++i) {
    float p[3], n[3], du[3], dv[3];
    const float u = truth->uvs[2 * i], v = truth->uvs[2 * i + 1];
    EXPECT_TRUE(
        evaluator.EvaluatePointFrames(truth->faces[i], {&truth->uvs[2 * i], 2}, {p, n, du, dv})
            .ok());
    const float c[3] = {map->Sample(truth->faces[i], u, v, 0),
                        map->Sample(truth->faces[i], u, v, 1),
                        map->Sample(truth->faces[i], u, v, 2)};
    const Float3 d = VectorFromChannels(
        *space, {{du[0], du[1], du[2]}, {dv[0], dv[1], dv[2]}, {n[0], n[1], n[2]}}, c);
    const double diff[3] = {d.x - double(truth->d[3 * i]), d.y - double(truth->d[3 * i + 1]),
                            d.z - double(truth->d[3 * i + 2])};
    const float error = static_cast<float>(Norm(diff));
    out.max_error = std::max(out.max_error, double(error));
    if (error > 1.5 * tau + 2.0 * truth->local_error[i]) {
      ++out.count;
      const float reach = 2.0f / map->face_info(truth->faces[i]).ures();  // two texels
      out.near_extraordinary +=
          NearExtraordinaryCorner(*cage, *surface, valence, truth->faces[i], u, v, reach);
      out.at_extraordinary +=
          NearExtraordinaryCorner(*cage, *surface, valence, truth->faces[i], u, v, 0);
    }
  }
  return out;
}

// Maps of the vector patterns as a perfect extraction at a fixed resolution would write them,
// in each space, pass verify against the sculpt and the version-3 truth: every record within
// 1.5 tau + 2 e_v, RMS and p99 within 0.5 and 1.5 tau, both distances within tau + the
// sculpt's linear error. Except, in the tangent and parametric spaces, at the records AT
// extraordinary corners and a few within two texels of one: there dP/du vanishes (valence 3)
// or grows without bound, Bfr's frame turns within 1e-3 of the corner, and the channels read
// there (clamped to the corner texel, converted with the corner's frame) miss D; a renderer's
// vertex there misses it the same way, so verify counts them (measured, tangent and
// parametric: sideways 3 and 49 records of 46850, overhang 16 and 68).
// The records over the bound are recomputed here independently of verify, so this also
// rejects a verify that reads the channels or the frames differently.
TEST_F(VectorMaps, MapsOfTheExactDPassInEverySpace) {
  for (Pattern pattern : {Pattern::kSideways, Pattern::kOverhang}) {
    const double tau = Tau(pattern);
    for (VectorSpace space : kSpaces) {
      SCOPED_TRACE(std::string(PatternName(pattern)) + " " + std::string(VectorSpaceName(space)));
      PatternMapOptions o;
      o.log2 = Log2(pattern);
      o.space = space;
      const std::string map = Map(pattern, "good", o);
      VerifyReport r = Check(pattern, map, tau, true);
      EXPECT_TRUE(r.map_vector);
      EXPECT_EQ(r.map_space, space);
      EXPECT_EQ(r.truth_version, 3);
      EXPECT_EQ(r.truth_quantity, "|D_map - D|");
      EXPECT_TRUE(r.edges_object_space);
      EXPECT_LE(r.truth.rms, 0.5 * tau) << Describe(r);
      EXPECT_LE(r.truth.p99, 1.5 * tau) << Describe(r);
      const double linear = Made(pattern).linear_error;
      EXPECT_LE(r.map_to_sculpt.max, tau + linear) << Describe(r);
      EXPECT_LE(r.sculpt_to_map.max, tau + linear) << Describe(r);
      const OverBound over = RecomputeTruthBound(cage_, map, Sculpt(pattern) + ".truth", tau);
      EXPECT_EQ(over.count, r.truth_over_bound);
      EXPECT_NEAR(over.max_error, r.truth.max, 1e-6 * r.truth.max);
      if (space == VectorSpace::kObject) {
        EXPECT_TRUE(r.passed) << Describe(r);
      } else {
        EXPECT_EQ(over.near_extraordinary, over.count) << "over the bound away from the corners";
        EXPECT_GE(over.at_extraordinary, over.count * 2 / 3);
        EXPECT_LE(over.count, 100u);
      }
      // Half floats: the same, to their rounding.
      if (space == VectorSpace::kObject) {
        o.data_type = PtexDataType::kHalf;
        VerifyReport half = Check(pattern, Map(pattern, "half", o), tau);
        EXPECT_TRUE(half.passed) << Describe(half);
      }
    }
  }
}

// Each wrong map fails the truth bounds (with the tolerance the good maps pass under):
//   zero             rejects a verify that does not read the map's vector at all;
//   channels 0 <-> 1 rejects one that reads the channels in the wrong order or treats the two
//                    tangential axes alike;
//   wrong space      (tangent written, named parametric; parametric named object; object
//                    named tangent) rejects one that ignores dispex:vector_space;
//   scalar h = D.N   rejects one that compares only the normal part with a version-3 truth:
//                    the scalar map of sideways holds nothing, of overhang no shear.
// Against the same truth without D (version 2) the scalar map passes, and so does a vector
// map compared by D.N: only the vector truth shows what a scalar map cannot hold.
TEST_F(VectorMaps, WrongMapsFailTheTruthBounds) {
  const std::pair<VectorSpace, VectorSpace> mislabelled[] = {
      {VectorSpace::kTangent, VectorSpace::kParametric},
      {VectorSpace::kParametric, VectorSpace::kObject},
      {VectorSpace::kObject, VectorSpace::kTangent}};
  for (Pattern pattern : {Pattern::kSideways, Pattern::kOverhang}) {
    const double tau = Tau(pattern);
    for (VectorSpace space : kSpaces) {
      SCOPED_TRACE(std::string(PatternName(pattern)) + " " + std::string(VectorSpaceName(space)));
      PatternMapOptions o;
      o.log2 = Log2(pattern);
      o.space = space;
      PatternMapOptions zero = o, swapped = o, wrong = o;
      zero.scale = 0;
      swapped.swap_tangential = true;
      for (const auto& [written, label] : mislabelled) {
        if (written == space) wrong.label = label;
      }
      for (const auto& [name, options] : {std::pair{"zero", zero}, std::pair{"swapped", swapped},
                                          std::pair{"mislabelled", wrong}}) {
        VerifyReport r = Check(pattern, Map(pattern, name, options), tau);
        EXPECT_FALSE(r.passed) << name << ": " << Describe(r);
        EXPECT_NE(r.failure.find("truth"), std::string::npos) << name << ": " << r.failure;
        EXPECT_GT(r.truth.rms, 0.5 * tau) << name << ": " << Describe(r);
      }
    }
    // The scalar map: fails against the vector truth, by its missing tangential part.
    PatternMapOptions scalar;
    scalar.log2 = Log2(pattern);
    scalar.space = std::nullopt;
    const std::string scalar_map = Map(pattern, "scalar", scalar);
    VerifyReport r = Check(pattern, scalar_map, tau, true);
    EXPECT_FALSE(r.map_vector);
    EXPECT_EQ(r.truth_quantity, "|map N - D|");
    EXPECT_FALSE(r.passed) << Describe(r);
    EXPECT_GT(r.truth.rms, 3 * tau) << Describe(r);
    // Against a truth without D it passes: h = D.N is all a version-2 truth knows.
    auto truth = ReadGroundTruth(Sculpt(pattern) + ".truth");
    ASSERT_TRUE(truth.ok());
    truth->d.clear();
    const std::string v2 = Sculpt(pattern) + ".v2.truth";
    ASSERT_TRUE(WriteGroundTruth(v2, *truth).ok());
    VerifyReport normal_only = Check(pattern, scalar_map, tau, false, v2);
    EXPECT_EQ(normal_only.truth_quantity, "|map - h|");
    EXPECT_TRUE(normal_only.passed) << Describe(normal_only);
    // A good vector map against the version-2 truth: compared by D.N, passes.
    PatternMapOptions object;
    object.log2 = Log2(pattern);
    object.space = VectorSpace::kObject;
    VerifyReport by_normal = Check(pattern, Map(pattern, "good", object), tau, false, v2);
    EXPECT_EQ(by_normal.truth_quantity, "|D_map.N - h|");
    EXPECT_TRUE(by_normal.passed) << Describe(by_normal);
    if (pattern == Pattern::kOverhang) {
      // The scalar map's surface lacks the overhang's sheets: far from the sculpt both ways
      // (measured: 0.033 and 0.040 against 0.005 and 0.005 for the vector map).
      VerifyReport vector = Check(pattern, Map(pattern, "good", object), tau, true);
      EXPECT_GT(r.sculpt_to_map.max, 4 * vector.sculpt_to_map.max);
      EXPECT_GT(r.map_to_sculpt.max, 4 * vector.map_to_sculpt.max);
    }
  }
}

// ---- Edge steps and errors ------------------------------------------------------------------

VerifyReport VerifyEdges(const std::string& cage, const std::string& map) {
  VerifyOptions verify;
  verify.base_path = cage;
  verify.map_path = map;
  auto report = Verify(verify);
  EXPECT_TRUE(report.ok()) << report.status().message();
  return report.ok() ? *report : VerifyReport{};
}

// A vector map's edge steps are steps of D in object space. A tangent map of one object-space
// vector D0 has none (to rounding), though its channel 0 steps by up to |D0| where the faces'
// u axes turn; an object map whose face 0 is off by (3k, 4k, 0) steps by 5k there, the length
// of the step. Rejects a verify that measures a tangent map's raw channels, or that takes the
// largest component's step for the vector's.
TEST(VectorEdges, StepsAreOfDInObjectSpace) {
  TempDir dir;
  const std::string cage = DataPath(kSpot);
  const double d0[3] = {0.02, -0.03, 0.015};
  PatternMapOptions o;
  o.log2 = 3;
  testing::WriteVectorFieldMap(
      cage, [&](const float*, const float*, double d[3]) { std::copy(d0, d0 + 3, d); },
      dir / "tangent.ptx", o);
  VerifyReport r = VerifyEdges(cage, dir / "tangent.ptx");
  EXPECT_TRUE(r.edges_object_space);
  EXPECT_GT(r.edge_per_face.count, 1000u);
  EXPECT_LT(r.edge_per_face.max, 1e-6);
  EXPECT_LT(r.edge_across_faces.max, 1e-6);
  // The same map's channel 0, measured as a scalar field, steps by a good part of |D0|.
  auto map = PtexFile::Open(dir / "tangent.ptx");
  auto base = ReadMesh(cage);
  auto surface = LimitSurface::Build(*base);
  ASSERT_TRUE(map.ok() && surface.ok());
  std::vector<PtexFaceInfo> faces(static_cast<std::size_t>(map->num_faces()));
  std::vector<std::vector<float>> channel0(faces.size());
  std::vector<float> texels;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    faces[f] = map->face_info(PtexFaceId(static_cast<int>(f)));
    ASSERT_TRUE(map->ReadFace(PtexFaceId(static_cast<int>(f)), 0, texels).ok());
    for (std::size_t i = 0; i < texels.size(); i += 3) channel0[f].push_back(texels[i]);
  }
  const std::vector<std::uint8_t> none(faces.size(), 0);
  PtexEdgeSteps raw = MeasurePtexEdgeSteps(faces, channel0, none, none);
  float raw_max = 0;
  for (float x : raw.per_face) raw_max = std::max(raw_max, x);
  EXPECT_GT(raw_max, 0.3 * Norm(d0));

  // An object map, face 0 off by (3k, 4k, 0).
  const float k = 0.001f;
  o.space = VectorSpace::kObject;
  testing::WriteVectorFieldMap(
      cage, [&](const float*, const float*, double d[3]) { std::copy(d0, d0 + 3, d); },
      dir / "object.ptx", o);
  auto object = PtexFile::Open(dir / "object.ptx");
  ASSERT_TRUE(object.ok());
  PtexWriterOptions w;
  w.num_channels = 3;
  auto writer = PtexWriter::Create(dir / "stepped.ptx", w, object->num_faces());
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(writer->AddMetaData(std::string(kVectorSpaceMetaKey), "object").ok());
  for (int f = 0; f < object->num_faces(); ++f) {
    ASSERT_TRUE(object->ReadFace(PtexFaceId(f), 0, texels).ok());
    for (std::size_t i = 0; f == 0 && i < texels.size(); i += 3) {
      texels[i] += 3 * k;
      texels[i + 1] += 4 * k;
    }
    ASSERT_TRUE(writer->SetFace(PtexFaceId(f), object->face_info(PtexFaceId(f)), texels).ok());
  }
  ASSERT_TRUE(writer->Finish().ok());
  VerifyReport stepped = VerifyEdges(cage, dir / "stepped.ptx");
  EXPECT_NEAR(stepped.edge_per_face.max, 5 * k, 1e-6);
  ASSERT_FALSE(stepped.worst_edges.empty());
  EXPECT_TRUE(stepped.worst_edges[0].face == 0 || stepped.worst_edges[0].neighbour == 0);
  EXPECT_NEAR(stepped.worst_edges[0].step, 5 * k, 1e-6);
}

// A map verify cannot read as scalar or vector is an error naming it, from the library and on
// the command line (one line, exit 1); so is a vector map whose space is not known. The report
// says which kind of map it measured. Rejects a verify that reads channel 0 of any map.
TEST(VectorMapErrors, MapsThatAreNeitherScalarNorVector) {
  TempDir dir;
  const std::string cage = DataPath(kSpot);
  auto base = ReadMesh(cage);
  auto surface = LimitSurface::Build(*base);
  ASSERT_TRUE(surface.ok());
  const int faces = surface->num_ptex_faces();
  auto write = [&](const std::string& name, int channels, const char* space) {
    PtexWriterOptions w;
    w.num_channels = channels;
    auto writer = PtexWriter::Create(dir / name, w, faces);
    ASSERT_TRUE(writer.ok());
    if (space) {
      ASSERT_TRUE(writer->AddMetaData(std::string(kVectorSpaceMetaKey), space).ok());
    }
    const std::vector<float> value(static_cast<std::size_t>(channels), 0.01f);
    for (int f = 0; f < faces; ++f) {
      ASSERT_TRUE(writer->SetConstantFace(PtexFaceId(f), PtexFaceInfo{}, value).ok());
    }
    ASSERT_TRUE(writer->Finish().ok());
  };
  write("three.ptx", 3, nullptr);
  write("two.ptx", 2, nullptr);
  write("world.ptx", 3, "world");
  write("object.ptx", 3, "object");
  const std::pair<const char*, const char*> cases[] = {
      {"three.ptx", "three.ptx: 3 channels but no dispex:vector_space meta data"},
      {"two.ptx", "two.ptx: 2 channels: a displacement map has 1 (scalar) or 3 (vector"},
      {"world.ptx", "world.ptx: dispex:vector_space: unknown vector space 'world'"}};
  for (const auto& [name, message] : cases) {
    VerifyOptions verify;
    verify.base_path = cage;
    verify.map_path = dir / name;
    auto report = Verify(verify);
    ASSERT_FALSE(report.ok()) << name;
    EXPECT_NE(report.status().message().find(message), std::string::npos)
        << report.status().message();
    auto cli = RunDispex("verify " + cage + " " + (dir / name), dir);
    EXPECT_EQ(cli.exit_code, 1) << cli.err;
    EXPECT_EQ(std::count(cli.err.begin(), cli.err.end(), '\n'), 1) << cli.err;
    EXPECT_NE(cli.err.find(message), std::string::npos) << cli.err;
  }
  // The kind of map, in the summary and the JSON report.
  auto cli = RunDispex(
      "verify " + cage + " " + (dir / "object.ptx") + " --report " + (dir / "v.json"), dir);
  EXPECT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_NE(cli.out.find("vector map (object space: P + D)"), std::string::npos) << cli.out;
  EXPECT_NE(cli.out.find("edge steps of |D| in object space"), std::string::npos) << cli.out;
  const std::string json = Slurp(dir / "v.json");
  EXPECT_NE(json.find("\"map_kind\": \"vector\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"vector_space\": \"object\""), std::string::npos) << json;
}

// The command line end to end: make-sculpt lists and makes the vector patterns (both layouts),
// and verify takes a vector map with no new flag, against the sculpt and the truth.
TEST(VectorCli, MakeSculptAndVerify) {
  TempDir dir;
  const std::string cage = DataPath(kSpot);
  auto help = RunDispex("make-sculpt --help", dir);
  EXPECT_NE(help.out.find("sideways"), std::string::npos);
  EXPECT_NE(help.out.find("overhang"), std::string::npos);
  for (const char* layout : {"--levels 3", "--layout jittered --density 6"}) {
    auto made = RunDispex("make-sculpt " + cage + " " + layout +
                              " --pattern overhang --amplitude 0.01 -o " + (dir / "s.obj"),
                          dir);
    EXPECT_EQ(made.exit_code, 0) << made.err;
    EXPECT_NE(made.err.find("max tangential |D|"), std::string::npos) << made.err;
    auto truth = ReadGroundTruth(dir / "s.obj.truth");
    ASSERT_TRUE(truth.ok());
    EXPECT_EQ(truth->version(), 3);
  }
  // The jittered overhang (the last one made), its object map at 64 x 64 texels per face.
  MakeSculptOptions make =
      testing::JitteredSculptOptions(cage, dir / "s.obj", 6, Pattern::kOverhang, 0.01);
  auto made = MakeSculpt(make);
  ASSERT_TRUE(made.ok());
  PatternMapOptions o;
  o.log2 = 6;
  o.space = VectorSpace::kObject;
  WritePatternMap(cage, Pattern::kOverhang, made->frame, dir / "v.ptx", o);
  const std::string tau = std::to_string(0.1 * made->max_displacement);
  auto verified = RunDispex("verify " + cage + " " + (dir / "s.obj") + " " + (dir / "v.ptx") +
                                " --truth " + (dir / "s.obj.truth") + " --tolerance " + tau,
                            dir);
  EXPECT_EQ(verified.exit_code, 0) << verified.err << verified.out;
  EXPECT_NE(verified.out.find("truth (version 3) measured as |D_map - D|"), std::string::npos)
      << verified.out;
  o.space = std::nullopt;
  WritePatternMap(cage, Pattern::kOverhang, made->frame, dir / "h.ptx", o);
  auto scalar = RunDispex("verify " + cage + " " + (dir / "h.ptx") + " --truth " +
                              (dir / "s.obj.truth") + " --tolerance " + tau + " -q",
                          dir);
  EXPECT_EQ(scalar.exit_code, 3) << scalar.err;
  EXPECT_NE(scalar.err.find("in |map N - D|"), std::string::npos) << scalar.err;
}

}  // namespace
}  // namespace dispex
