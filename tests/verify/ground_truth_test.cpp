// Ground truth: sculpts with known displacement on real cages, extracted and measured.
//
// The bound tested: a map extracted from a generated sculpt is within
//   tolerance + 2 x (the sculpt's own piecewise-linear error)
// of the exact displacement at every sculpt vertex. The sculpt is the displaced surface
// sampled at its vertices and linear in between, so the ray from a sample meets it up to its
// linear error e away from the truth; the stored face adds at most the tolerance at the
// samples; the truth is read at sculpt vertices, half-way between samples, where the
// bilinear read-back of two samples each off by up to e (plus the curvature of h over half a
// sample spacing, far below e at two samples per sculpt edge) stays within a second e.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/verify.h"
#include "../extract/e2e_support.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::SculptOptions;
using testing::RunDispex;
using testing::TempDir;

struct TruthCase {
  const char* name;
  const char* cage;
  Pattern pattern;
  int levels;
  double amplitude = 0.002;  // of the bounding-box diagonal
  // The Ogre's cage self-intersects (its author says so): its limit surface passes through
  // itself and has creases of curvature radius below 1e-3 of its diagonal, so even a small
  // displacement folds a few sculpt faces and a few rays find no surface (filled as holes).
  bool self_intersecting = false;
  const char* image = nullptr;  // Pattern::kImage: the height image, under tests/data
};

std::string CaseName(const ::testing::TestParamInfo<TruthCase>& info) {
  return std::string(info.param.name) + "_" + std::string(PatternName(info.param.pattern)) +
         "_L" + std::to_string(info.param.levels);
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
    EXPECT_EQ(report->misses, 0);
  }

  VerifyOptions verify;
  verify.base_path = cage;
  verify.sculpt_path = make.output_path;
  verify.map_path = options.output_path;
  verify.truth_path = make.output_path + ".truth";
  auto checked = Verify(verify);
  ASSERT_TRUE(checked.ok()) << checked.status().message();
  const double bound = report->tolerance + 2 * made->linear_error;
  EXPECT_LE(checked->truth.max, bound)
      << "tolerance " << report->tolerance << ", linear error " << made->linear_error;
  EXPECT_EQ(checked->truth.count, made->vertices);
  // Two-sided distances agree with the truth: both measure how far the displaced surface is
  // from the sculpt, so neither exceeds the truth's bound plus the sculpt's linear error.
  EXPECT_LE(checked->map_to_sculpt.max, bound + made->linear_error);
  EXPECT_LE(checked->sculpt_to_map.max, bound + made->linear_error);
  EXPECT_LE(checked->map_to_sculpt.rms, 2 * checked->truth.rms + made->linear_error);
  EXPECT_TRUE(checked->passed);
  EXPECT_EQ(checked->map_misses, report->misses);
}

INSTANTIATE_TEST_SUITE_P(
    Cages, GroundTruth,
    ::testing::Values(
        TruthCase{"spot", "meshes/keenan_spot/spot_control_mesh.obj", Pattern::kSmooth, 3},
        TruthCase{"spot", "meshes/keenan_spot/spot_control_mesh.obj", Pattern::kDetail, 4},
        TruthCase{"spot", "meshes/keenan_spot/spot_control_mesh.obj", Pattern::kRidges, 3},
        TruthCase{"blub", "meshes/keenan_blub/blub_control_mesh.obj", Pattern::kSmooth, 4, 1e-3},
        TruthCase{"blub", "meshes/keenan_blub/blub_control_mesh.obj", Pattern::kDetail, 4, 1e-3},
        TruthCase{"blub", "meshes/keenan_blub/blub_control_mesh.obj", Pattern::kRidges, 4, 1e-3},
        TruthCase{"ogre", "meshes/jerry_the_ogre/controlmesh.obj", Pattern::kSmooth, 3, 2.5e-4, true},
        TruthCase{"ogre", "meshes/jerry_the_ogre/controlmesh.obj", Pattern::kDetail, 3, 2.5e-4, true},
        TruthCase{"ogre", "meshes/jerry_the_ogre/controlmesh.obj", Pattern::kRidges, 3, 2.5e-4, true},
        TruthCase{"torus_creases", "meshes/opensubdiv/catmark_torus_creases0.obj",
                  Pattern::kSmooth, 4},
        TruthCase{"torus_creases", "meshes/opensubdiv/catmark_torus_creases0.obj",
                  Pattern::kDetail, 4},
        TruthCase{"torus_creases", "meshes/opensubdiv/catmark_torus_creases0.obj",
                  Pattern::kRidges, 4},
        TruthCase{"tent", "meshes/opensubdiv/catmark_tent.obj", Pattern::kSmooth, 4},
        TruthCase{"tent", "meshes/opensubdiv/catmark_tent.obj", Pattern::kDetail, 4},
        TruthCase{"tent", "meshes/opensubdiv/catmark_tent.obj", Pattern::kRidges, 4},
        // Quads, pentagons and triangles with continuous UVs and a seamless 16-bit image.
        TruthCase{"wavy_plane", "image_pattern/wavy_plane.obj", Pattern::kImage, 4, 0.005,
                  false, "image_pattern/heights.png"}),
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

  auto missing = RunDispex("make-sculpt " + cage + " --pattern image:" + (dir / "none.png") +
                               " -o " + (dir / "t.obj"),
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
    tolerance_ = report->tolerance;
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
  const double max_rms = 2 * std::max({good.truth.rms, good.map_to_sculpt.rms,
                                       good.sculpt_to_map.rms});
  EXPECT_TRUE(Check(dir_ / "good.ptx", max_rms).passed);
  auto same = [](int f, int) { return f; };
  auto reversed = [](int f, int n) { return n - 1 - f; };
  const auto shift = static_cast<float>(tolerance_ + 2 * linear_error_);
  VerifyReport shifted =
      Check(Rewrite("shifted.ptx", same, [&](float v) { return v + 1.5f * shift; }), max_rms);
  EXPECT_FALSE(shifted.passed);
  EXPECT_NE(shifted.failure.find("exceeds --max-error"), std::string::npos) << shifted.failure;
  VerifyReport scaled = Check(Rewrite("scaled.ptx", same, [](float v) { return 3 * v; }), max_rms);
  EXPECT_FALSE(scaled.passed);
  VerifyReport swapped = Check(Rewrite("reversed.ptx", reversed, [](float v) { return v; }), max_rms);
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
  auto passing = RunDispex("verify " + cage_ + " " + (dir_ / "good.ptx") + " --truth " +
                               sculpt_ + ".truth --report " + (dir_ / "v.json"),
                           dir_);
  EXPECT_EQ(passing.exit_code, 0) << passing.err;
  EXPECT_NE(testing::Slurp(dir_ / "v.json").find("\"truth\""), std::string::npos);
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
  std::string bytes = testing::Slurp(dir / "t.truth");
  std::ofstream(dir / "short.truth", std::ios::binary) << bytes.substr(0, bytes.size() - 3);
  EXPECT_FALSE(ReadGroundTruth(dir / "short.truth").ok());
  std::ofstream(dir / "junk.truth") << "not a truth file at all";
  EXPECT_FALSE(ReadGroundTruth(dir / "junk.truth").ok());
}

}  // namespace
}  // namespace dispex
