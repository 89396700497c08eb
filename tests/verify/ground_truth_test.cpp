// Ground truth: sculpts with known displacement on real cages, extracted and measured.
//
// The bounds tested (docs/ACCURACY.md; verify's defaults): at every sculpt vertex
//   |map - h| <= 1.5 tolerance + 2 e_v,
// e_v the sculpt's piecewise-linear error on the faces within two rings of the vertex (the
// truth file holds it): the map's samples around a vertex take their values from rays that
// meet those faces, up to e_v from the true surface, and the bilinear read-back between
// samples off by up to e_v adds a second e_v; the stored face is within the tolerance of its
// samples, and up to half a tolerance more between them and along face edges. Over all
// vertices the RMS stays under 0.5 and the 99th percentile under 1.5 tolerances. Every case
// also shows that the same check rejects wrong maps: zero, scaled by 0.5 and 0.8, u and v
// transposed, sign flipped, and the map of another pattern.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "../extract/e2e_support.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/verify.h"

namespace dispex {
namespace {

using testing::CheckTruth;
using testing::DataPath;
using testing::RunDispex;
using testing::SculptOptions;
using testing::TempDir;
using testing::WrongMap;
using testing::WrongMapName;

struct TruthCase {
  const char* name;
  const char* cage;
  Pattern pattern;
  int levels;
  // Of the bounding-box diagonal: about 10 extraction tolerances (0.05 sculpt edges) or more,
  // so that the maps scaled by 0.8 break the bounds, and below folding except on the Ogre.
  double amplitude = 0.002;
  // The Ogre's cage self-intersects (its author says so): its limit surface passes through
  // itself and has creases of curvature radius below 1e-3 of its diagonal, so even a small
  // displacement folds a few sculpt faces and a few rays find no surface (filled as holes).
  bool self_intersecting = false;
  const char* image = nullptr;  // Pattern::kImage: the height image, under tests/data
  int density = 0;              // > 0: SculptLayout::kJittered with this density
};

std::string CaseName(const ::testing::TestParamInfo<TruthCase>& info) {
  return std::string(info.param.name) + "_" + std::string(PatternName(info.param.pattern)) +
         (info.param.density ? "_J" + std::to_string(info.param.density)
                             : "_L" + std::to_string(info.param.levels));
}

class GroundTruth : public ::testing::TestWithParam<TruthCase> {};

TEST_P(GroundTruth, ExtractionIsWithinToleranceAndTheSculptsLinearError) {
  const TruthCase& c = GetParam();
  TempDir dir;
  const std::string cage = DataPath(c.cage);
  auto base = ReadMesh(cage);
  ASSERT_TRUE(base.ok()) << base.status().message();

  MakeSculptOptions make;
  make.cage_path = cage;
  make.output_path = dir / "sculpt.obj";
  make.levels = c.levels;
  if (c.density > 0) {
    make.layout = SculptLayout::kJittered;
    make.density = c.density;
  }
  make.pattern = c.pattern;
  if (c.image != nullptr) make.image_path = DataPath(c.image);
  make.amplitude = c.amplitude * ComputeBounds(*base).diagonal();
  auto made = MakeSculpt(make);
  ASSERT_TRUE(made.ok()) << made.status().message();
  if (!c.self_intersecting) {
    ASSERT_EQ(made->folded_faces, 0u) << "the sculpt folds: amplitude too large for this cage";
  }

  ExtractOptions options;
  options.base_path = cage;
  options.sculpt_path = make.output_path;
  options.output_path = dir / "map.ptx";
  auto report = Extract(options);
  ASSERT_TRUE(report.ok()) << report.status().message();
  if (!c.self_intersecting) {
    // The tent's open boundary moves inwards when displaced: a ray or two there can miss.
    EXPECT_LE(report->sampling.misses, std::string(c.name) == "tent" ? 2 : 0);
  }
  // A jittered sculpt is not a subdivision of the base: oversampling goes by its density.
  EXPECT_EQ(report->sampling.oversample_subdivision_level, c.density > 0 ? -1 : c.levels);

  VerifyOptions verify;
  verify.base_path = cage;
  verify.sculpt_path = make.output_path;
  verify.map_path = options.output_path;
  verify.truth_path = make.output_path + ".truth";
  auto checked = Verify(verify);
  ASSERT_TRUE(checked.ok()) << checked.status().message();
  EXPECT_TRUE(checked->passed) << checked->failure;
  EXPECT_EQ(checked->truth_tolerance, report->settings.tolerance);  // from the map's meta data
  EXPECT_TRUE(checked->truth_local_checked);
  EXPECT_EQ(checked->truth_over_bound, 0u);
  EXPECT_LE(checked->truth.rms, VerifyOptions::kDefaultTruthRmsFactor * report->settings.tolerance);
  EXPECT_LE(checked->truth.p99, VerifyOptions::kDefaultTruthP99Factor * report->settings.tolerance);
  EXPECT_EQ(checked->truth.count, made->vertices);
  // Two-sided distances agree with the truth: both measure how far the displaced surface is
  // from the sculpt, so neither exceeds the global bound plus the sculpt's linear error.
  const double bound = report->settings.tolerance + 2 * made->linear_error;
  EXPECT_LE(checked->map_to_sculpt.max, bound + made->linear_error);
  EXPECT_LE(checked->sculpt_to_map.max, bound + made->linear_error);
  EXPECT_LE(checked->map_to_sculpt.rms, 2 * checked->truth.rms + made->linear_error);
  EXPECT_EQ(checked->map_misses, report->sampling.misses);

  // Negative controls: the same check (the map's tolerance, default bounds) rejects each.
  const std::string truth = make.output_path + ".truth";
  for (WrongMap kind : testing::kWrongMaps) {
    // The Ogre folds above an amplitude of about 4 tolerances: a map scaled by 0.5 or 0.8 or
    // transposed is within its tolerance there, so only the grosser controls apply.
    if (c.self_intersecting && kind != WrongMap::kZero && kind != WrongMap::kSignFlipped) {
      continue;
    }
    const std::string wrong = dir / "wrong.ptx";
    testing::WriteWrongMap(options.output_path, wrong, kind);
    VerifyReport r = CheckTruth(cage, wrong, truth, report->settings.tolerance);
    EXPECT_FALSE(r.passed) << WrongMapName(kind) << ": truth rms " << r.truth.rms << " p99 "
                           << r.truth.p99 << " worst ratio " << r.truth_worst_ratio;
  }
  MakeSculptOptions other = make;
  other.pattern = c.pattern == Pattern::kNoise ? Pattern::kSmooth : Pattern::kNoise;
  other.output_path = dir / "other.obj";
  ASSERT_TRUE(MakeSculpt(other).ok());
  VerifyReport r = CheckTruth(cage, options.output_path, other.output_path + ".truth",
                              report->settings.tolerance);
  EXPECT_FALSE(r.passed) << "another pattern: truth rms " << r.truth.rms;
}

INSTANTIATE_TEST_SUITE_P(
    Cages, GroundTruth,
    ::testing::Values(
        TruthCase{"spot", "meshes/keenan_spot/spot_control_mesh.obj", Pattern::kSmooth, 3},
        TruthCase{"spot", "meshes/keenan_spot/spot_control_mesh.obj", Pattern::kDetail, 4},
        TruthCase{"spot", "meshes/keenan_spot/spot_control_mesh.obj", Pattern::kRidges, 3, 0.003},
        TruthCase{"blub", "meshes/keenan_blub/blub_control_mesh.obj", Pattern::kSmooth, 4, 1e-3},
        TruthCase{"blub", "meshes/keenan_blub/blub_control_mesh.obj", Pattern::kDetail, 4, 1e-3},
        TruthCase{"blub", "meshes/keenan_blub/blub_control_mesh.obj", Pattern::kRidges, 4, 1.5e-3},
        TruthCase{"ogre", "meshes/jerry_the_ogre/controlmesh.obj", Pattern::kSmooth, 3, 2.5e-4,
                  true},
        TruthCase{"ogre", "meshes/jerry_the_ogre/controlmesh.obj", Pattern::kDetail, 3, 2.5e-4,
                  true},
        TruthCase{"ogre", "meshes/jerry_the_ogre/controlmesh.obj", Pattern::kRidges, 3, 2.5e-4,
                  true},
        TruthCase{"torus_creases", "meshes/opensubdiv/catmark_torus_creases0.obj", Pattern::kSmooth,
                  4, 0.005},
        TruthCase{"torus_creases", "meshes/opensubdiv/catmark_torus_creases0.obj", Pattern::kDetail,
                  4, 0.005},
        TruthCase{"torus_creases", "meshes/opensubdiv/catmark_torus_creases0.obj", Pattern::kRidges,
                  4, 0.005},
        TruthCase{"tent", "meshes/opensubdiv/catmark_tent.obj", Pattern::kSmooth, 4, 0.004},
        TruthCase{"tent", "meshes/opensubdiv/catmark_tent.obj", Pattern::kDetail, 4, 0.004},
        TruthCase{"tent", "meshes/opensubdiv/catmark_tent.obj", Pattern::kRidges, 4, 0.004},
        // Quads, pentagons and triangles with continuous UVs and a seamless 16-bit image.
        TruthCase{"wavy_plane", "image_pattern/wavy_plane.obj", Pattern::kImage, 4, 0.005, false,
                  "image_pattern/heights.png"},
        // Sculpts that are not refinements of the base (SculptLayout::kJittered).
        TruthCase{"spot", "meshes/keenan_spot/spot_control_mesh.obj", Pattern::kDetail, 0, 0.002,
                  false, nullptr, 12},
        TruthCase{"torus_creases", "meshes/opensubdiv/catmark_torus_creases0.obj", Pattern::kRidges,
                  0, 0.005, false, nullptr, 23},
        TruthCase{"tent", "meshes/opensubdiv/catmark_tent.obj", Pattern::kSmooth, 0, 0.004, false,
                  nullptr, 12},
        TruthCase{"wavy_plane", "image_pattern/wavy_plane.obj", Pattern::kImage, 0, 0.005, false,
                  "image_pattern/heights.png", 12}),
    CaseName);

// The command line: --pattern image:FILE.png, and its errors.
TEST(ImagePatternCli, MakesASculptAndFailsOnBadImages) {
  TempDir dir;
  const std::string cage = DataPath("image_pattern/wavy_plane.obj");
  const std::string image = DataPath("image_pattern/heights.png");
  auto made = RunDispex("make-sculpt " + cage + " --levels 2 --pattern image:" + image +
                            " --amplitude 0.05 -o " + (dir / "s.obj"),
                        dir);
  EXPECT_EQ(made.exit_code, 0) << made.err;
  EXPECT_NE(made.err.find("pattern image:" + image), std::string::npos) << made.err;
  EXPECT_NE(testing::Slurp(dir / "s.obj").find("pattern image:" + image), std::string::npos);
  auto truth = ReadGroundTruth(dir / "s.obj.truth");
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  for (float h : truth->h) {
    ASSERT_LE(std::abs(h), 0.05f);
  }

  auto missing = RunDispex(
      "make-sculpt " + cage + " --pattern image:" + (dir / "none.png") + " -o " + (dir / "t.obj"),
      dir);
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_EQ(missing.err, "dispex: " + (dir / "none.png") + ": no such file\n");
  auto no_uvs = RunDispex("make-sculpt " + DataPath("meshes/opensubdiv/catmark_pole8.obj") +
                              " --pattern image:" + image + " -o " + (dir / "t.obj"),
                          dir);
  EXPECT_NE(no_uvs.exit_code, 0);
  EXPECT_NE(no_uvs.err.find("catmark_pole8.obj: the cage has no texture coordinates"),
            std::string::npos)
      << no_uvs.err;
  auto bare = RunDispex("make-sculpt " + cage + " --pattern image: -o " + (dir / "t.obj"), dir);
  EXPECT_EQ(bare.exit_code, 2) << bare.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "t.obj"));
}

// Maps that are wrong on purpose fail verify's thresholds.
class WrongMaps : public ::testing::Test {
 protected:
  void SetUp() override {
    cage_ = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
    MakeSculptOptions make = SculptOptions(cage_, dir_ / "sculpt.obj", 3, Pattern::kDetail, 0.004);
    auto made = MakeSculpt(make);
    ASSERT_TRUE(made.ok()) << made.status().message();
    linear_error_ = made->linear_error;
    sculpt_ = make.output_path;
    ExtractOptions options;
    options.base_path = cage_;
    options.sculpt_path = sculpt_;
    options.output_path = dir_ / "good.ptx";
    auto report = Extract(options);
    ASSERT_TRUE(report.ok()) << report.status().message();
    tolerance_ = report->settings.tolerance;
  }

  // A copy of the good map with every texel of face f replaced by edit(f, value), read from
  // face source(f).
  template <class Source, class Edit>
  std::string Rewrite(const std::string& name, Source source, Edit edit) {
    auto good = PtexFile::Open(dir_ / "good.ptx");
    EXPECT_TRUE(good.ok());
    std::string path = dir_ / name;
    auto writer = PtexWriter::Create(path, PtexWriterOptions{}, good->num_faces());
    EXPECT_TRUE(writer.ok());
    std::vector<float> texels;
    for (int f = 0; f < good->num_faces(); ++f) {
      PtexFaceId from(source(f, good->num_faces()));
      PtexFaceInfo info = good->face_info(from);
      PtexFaceInfo target = good->face_info(PtexFaceId(f));
      info.adjfaces = target.adjfaces;
      info.adjedges = target.adjedges;
      info.subface = target.subface;
      EXPECT_TRUE(good->ReadFace(from, 0, texels).ok());
      for (float& v : texels) v = edit(v);
      EXPECT_TRUE(writer->SetFace(PtexFaceId(f), info, texels).ok());
    }
    EXPECT_TRUE(writer->Finish().ok());
    return path;
  }

  VerifyReport Check(const std::string& map, double max_rms) {
    VerifyOptions verify;
    verify.base_path = cage_;
    verify.sculpt_path = sculpt_;
    verify.map_path = map;
    verify.truth_path = sculpt_ + ".truth";
    verify.max_error = tolerance_ + 2 * linear_error_;
    verify.max_rms = max_rms;
    auto report = Verify(verify);
    EXPECT_TRUE(report.ok()) << report.status().message();
    return report.ok() ? *report : VerifyReport{};
  }

  TempDir dir_;
  std::string cage_, sculpt_;
  double tolerance_ = 0, linear_error_ = 0;
};

TEST_F(WrongMaps, GoodMapPassesAndShiftedScaledReversedMapsFail) {
  VerifyReport good = Check(dir_ / "good.ptx", 0);
  EXPECT_TRUE(good.passed) << good.failure;
  // Thresholds a good map meets with room to spare: twice its RMS error.
  const double max_rms =
      2 * std::max({good.truth.rms, good.map_to_sculpt.rms, good.sculpt_to_map.rms});
  EXPECT_TRUE(Check(dir_ / "good.ptx", max_rms).passed);
  auto same = [](int f, int) { return f; };
  auto reversed = [](int f, int n) { return n - 1 - f; };
  const auto shift = static_cast<float>(tolerance_ + 2 * linear_error_);
  VerifyReport shifted =
      Check(Rewrite("shifted.ptx", same, [&](float v) { return v + 1.5f * shift; }), max_rms);
  EXPECT_FALSE(shifted.passed);
  EXPECT_NE(shifted.failure.find("exceeds max_error"), std::string::npos) << shifted.failure;
  VerifyReport scaled = Check(Rewrite("scaled.ptx", same, [](float v) { return 3 * v; }), max_rms);
  EXPECT_FALSE(scaled.passed);
  VerifyReport swapped =
      Check(Rewrite("reversed.ptx", reversed, [](float v) { return v; }), max_rms);
  EXPECT_FALSE(swapped.passed);

  // The command line exits 3 with one line naming the map and the error.
  std::string shifted_map = dir_ / "shifted.ptx";
  auto r = RunDispex("verify " + cage_ + " " + sculpt_ + " " + shifted_map + " --max-error " +
                         std::to_string(tolerance_ + 2 * linear_error_),
                     dir_);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("shifted.ptx: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exceeds --max-error"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("FAILED"), std::string::npos);
  auto passing = RunDispex("verify " + cage_ + " " + (dir_ / "good.ptx") + " --truth " + sculpt_ +
                               ".truth --report " + (dir_ / "v.json"),
                           dir_);
  EXPECT_EQ(passing.exit_code, 0) << passing.err;
  EXPECT_NE(testing::Slurp(dir_ / "v.json").find("\"truth\""), std::string::npos);
  EXPECT_NE(testing::Slurp(dir_ / "v.json").find("\"records_over\": 0"), std::string::npos);
  // The truth bounds: the scaled map breaks them (exit 3, one line); bad factors are exit 2.
  std::string scaled_map = dir_ / "scaled.ptx";
  auto scaled_cli = RunDispex("verify " + cage_ + " " + scaled_map + " --truth " + sculpt_ +
                                  ".truth --tolerance " + std::to_string(tolerance_) + " -q",
                              dir_);
  EXPECT_EQ(scaled_cli.exit_code, 3) << scaled_cli.err;
  EXPECT_NE(scaled_cli.err.find("records exceed 1.5 x tolerance"), std::string::npos)
      << scaled_cli.err;
  EXPECT_EQ(std::count(scaled_cli.err.begin(), scaled_cli.err.end(), '\n'), 1);
  auto bad = RunDispex(
      "verify " + cage_ + " " + scaled_map + " --truth " + sculpt_ + ".truth --truth-rms-factor -1",
      dir_);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

TEST_F(WrongMaps, MapOfAnotherMeshIsRejected) {
  VerifyOptions verify;
  verify.base_path = DataPath("meshes/keenan_blub/blub_control_mesh.obj");
  verify.sculpt_path = sculpt_;
  verify.map_path = dir_ / "good.ptx";
  auto report = Verify(verify);
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.status().message().find("not a map of this base mesh"), std::string::npos)
      << report.status().message();
}

// The jittered layout: watertight (n-gon sub-faces and Ptex edges shared), vertices off the
// texel grids, triangles, seeded, and exact truth records.
TEST(JitteredLayout, IsWatertightDeterministicAndOffTheGrid) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");  // n-gons
  MakeSculptOptions make =
      testing::JitteredSculptOptions(cage, dir / "a.obj", 6, Pattern::kSmooth, 0.004);
  auto made = MakeSculpt(make);
  ASSERT_TRUE(made.ok()) << made.status().message();
  auto sculpt = ReadMesh(make.output_path);
  ASSERT_TRUE(sculpt.ok());
  MeshValidation valid = ValidateMesh(*sculpt);
  EXPECT_TRUE(valid.clean());
  EXPECT_EQ(valid.boundary_edges, 0u);  // spot is closed, and so is its sculpt
  auto base = ReadMesh(cage);
  auto surface = LimitSurface::Build(*base);
  ASSERT_TRUE(surface.ok());
  // 6 x 6 cells per quad, 3 x 3 per n-gon sub-face, two triangles each.
  auto cells = [&](PtexFaceId f) {
    return surface->base_face_size(surface->base_face(f)) == 4 ? 6 : 3;
  };
  std::size_t triangles = 0, triangles_at_4 = 0;
  for (int f = 0; f < surface->num_ptex_faces(); ++f) {
    triangles += 2 * std::size_t(cells(PtexFaceId(f)) * cells(PtexFaceId(f)));
    triangles_at_4 += 2 * std::size_t(cells(PtexFaceId(f)) * cells(PtexFaceId(f)) * 4) / 9;
  }
  EXPECT_EQ(sculpt->num_faces(), triangles);
  for (std::size_t f = 0; f < sculpt->num_faces(); ++f) ASSERT_EQ(sculpt->face_size(f), 3);
  // A closed surface's Euler characteristic: the cage's and the sculpt's agree.
  auto euler = [](const Mesh& m) {
    std::size_t corners = m.face_indices.size();
    return static_cast<long>(m.num_vertices()) - static_cast<long>(corners / 2) +
           static_cast<long>(m.num_faces());
  };
  EXPECT_EQ(euler(*sculpt), euler(*base));

  auto truth = ReadGroundTruth(make.output_path + ".truth");
  ASSERT_TRUE(truth.ok());
  ASSERT_EQ(truth->size(), sculpt->num_vertices());
  ASSERT_EQ(truth->local_error.size(), truth->size());
  std::size_t off_grid = 0;
  for (std::size_t i = 0; i < truth->size(); ++i) {
    const float m = static_cast<float>(cells(truth->faces[i]));
    float u = truth->uvs[2 * i] * m, v = truth->uvs[2 * i + 1] * m;
    off_grid += std::abs(u - std::round(u)) > 1e-3f && std::abs(v - std::round(v)) > 1e-3f;
    EXPECT_LE(truth->local_error[i], made->linear_error);
  }
  EXPECT_GT(off_grid, truth->size() / 3);
  // Each vertex is the limit point of its record moved by h along the normal.
  LimitEvaluator evaluator(*surface);
  for (std::size_t i = 0; i < truth->size(); i += 97) {
    float p[3], n[3];
    ASSERT_TRUE(evaluator.EvaluatePoints(truth->faces[i], {&truth->uvs[2 * i], 2}, p, n).ok());
    const Float3& q = sculpt->positions[i];
    EXPECT_NEAR(q.x, p[0] + truth->h[i] * n[0], 1e-5);
    EXPECT_NEAR(q.y, p[1] + truth->h[i] * n[1], 1e-5);
    EXPECT_NEAR(q.z, p[2] + truth->h[i] * n[2], 1e-5);
  }

  make.output_path = dir / "b.obj";
  ASSERT_TRUE(MakeSculpt(make).ok());
  EXPECT_EQ(testing::Slurp(dir / "a.obj"), testing::Slurp(dir / "b.obj"));
  EXPECT_EQ(testing::Slurp(dir / "a.obj.truth"), testing::Slurp(dir / "b.obj.truth"));
  make.seed = 2;
  make.output_path = dir / "c.obj";
  ASSERT_TRUE(MakeSculpt(make).ok());
  EXPECT_NE(testing::Slurp(dir / "a.obj.truth"), testing::Slurp(dir / "c.obj.truth"));

  make.density = 1;
  auto bad = MakeSculpt(make);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(),
            "density 1: the jittered layout needs 2..256 cells per Ptex face side");
  make.density = 7;
  bad = MakeSculpt(make);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(),
            "density 7: the cage has n-gons, whose sub-faces take density / 2 cells per side: "
            "must be even");
  for (const char* args : {"--layout jittered", "--layout jittered --density 300",
                           "--layout grid --density 4", "--density 4"}) {
    auto r = RunDispex("make-sculpt " + cage + " " + args + " -o " + (dir / "d.obj"), dir);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  auto cli = RunDispex(
      "make-sculpt " + cage + " --layout jittered --density 4 -o " + (dir / "d.obj"), dir);
  EXPECT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_NE(cli.err.find(std::to_string(triangles_at_4) + " triangles"), std::string::npos)
      << cli.err;
}

TEST(PatternTest, ParsesNamesAndIsDeterministic) {
  EXPECT_EQ(*ParsePattern("ridges"), Pattern::kRidges);
  EXPECT_FALSE(ParsePattern("waves").ok());
  PatternFrame frame;
  frame.amplitude = 0.5;
  const float p[3] = {0.1f, 0.2f, 0.3f};
  for (Pattern pattern : {Pattern::kSmooth, Pattern::kDetail, Pattern::kRidges, Pattern::kNoise}) {
    double h = EvaluatePattern(pattern, frame, p);
    EXPECT_EQ(h, EvaluatePattern(pattern, frame, p));
    EXPECT_LE(std::abs(h), 2 * frame.amplitude);
  }
  // The smooth pattern at the centre: A (0.5 sin 0.3 + 0.3 sin 1.1 + 0.2 sin 2).
  const float centre[3] = {0, 0, 0};
  EXPECT_NEAR(EvaluatePattern(Pattern::kSmooth, frame, centre),
              0.5 * (0.5 * std::sin(0.3) + 0.3 * std::sin(1.1) + 0.2 * std::sin(2.0)), 1e-12);
}

TEST(GroundTruthFile, RoundTripsAndRejectsBadFiles) {
  TempDir dir;
  dispex::GroundTruth truth;
  truth.faces = {PtexFaceId(0), PtexFaceId(7)};
  truth.uvs = {0.25f, 0.5f, 1.0f, 0.0f};
  truth.h = {0.125f, -2.0f};
  ASSERT_TRUE(WriteGroundTruth(dir / "t.truth", truth).ok());
  auto back = ReadGroundTruth(dir / "t.truth");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->faces, truth.faces);
  EXPECT_EQ(back->uvs, truth.uvs);
  EXPECT_EQ(back->h, truth.h);
  EXPECT_TRUE(back->local_error.empty());  // version 1
  truth.local_error = {0.5f, 0.25f};
  ASSERT_TRUE(WriteGroundTruth(dir / "t2.truth", truth).ok());
  auto back2 = ReadGroundTruth(dir / "t2.truth");
  ASSERT_TRUE(back2.ok());
  EXPECT_EQ(back2->h, truth.h);
  EXPECT_EQ(back2->local_error, truth.local_error);
  EXPECT_EQ(testing::Slurp(dir / "t2.truth").size(), 24u + 2 * 20);
  std::string bytes = testing::Slurp(dir / "t.truth");
  std::ofstream(dir / "short.truth", std::ios::binary) << bytes.substr(0, bytes.size() - 3);
  EXPECT_FALSE(ReadGroundTruth(dir / "short.truth").ok());
  std::ofstream(dir / "junk.truth") << "not a truth file at all";
  EXPECT_FALSE(ReadGroundTruth(dir / "junk.truth").ok());
}

}  // namespace
}  // namespace dispex
