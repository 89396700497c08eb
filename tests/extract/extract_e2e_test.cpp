// End-to-end extraction on real cages with generated sculpts of known displacement.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/verify.h"
#include "e2e_support.h"
#include "subdiv_ptex_faces.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::RunDispex;
using testing::SculptOptions;
using testing::TempDir;

struct Case {
  const char* cage;
  const char* what;
  int density = 0;  // > 0: a jittered sculpt (SculptLayout::kJittered) of this density
  // Of the diagonal: at least ~10 tolerances, so that the maps scaled by 0.8 break the bounds.
  double amplitude = 0.002;
};

class ExtractRealCages : public ::testing::TestWithParam<Case> {};

TEST_P(ExtractRealCages, MapMatchesTheKnownDisplacementAndTheReportAddsUp) {
  TempDir dir;
  const std::string cage = DataPath(GetParam().cage);
  auto base = ReadMesh(cage);
  ASSERT_TRUE(base.ok()) << base.status().message();
  const double diagonal = ComputeBounds(*base).diagonal();

  const int density = GetParam().density;
  const double amplitude = GetParam().amplitude * diagonal;
  MakeSculptOptions make =
      density > 0 ? testing::JitteredSculptOptions(cage, dir / "sculpt.obj", density,
                                                   Pattern::kSmooth, amplitude)
                  : SculptOptions(cage, dir / "sculpt.obj", 3, Pattern::kSmooth, amplitude);
  auto made = MakeSculpt(make);
  ASSERT_TRUE(made.ok()) << made.status().message();
  ASSERT_EQ(made->folded_faces, 0u);

  ExtractOptions options;
  options.base_path = cage;
  options.sculpt_path = make.output_path;
  options.output_path = dir / "map.ptx";
  auto report = Extract(options);
  ASSERT_TRUE(report.ok()) << report.status().message();

  // The file: one face per Ptex face, with OpenSubdiv's adjacency (checked against the oracle).
  auto map = PtexFile::Open(options.output_path);
  ASSERT_TRUE(map.ok()) << map.status().message();
  auto faces = ComputeSubdivPtexFaces(*base);
  ASSERT_TRUE(faces.ok());
  ASSERT_EQ(map->num_faces(), faces->num_faces());
  EXPECT_EQ(map->header().data_type, PtexDataType::kFloat);
  EXPECT_EQ(map->header().mesh_type, PtexMeshType::kQuad);
  std::int64_t texels = 0;
  for (int f = 0; f < map->num_faces(); ++f) {
    const PtexFaceInfo& info = map->face_info(PtexFaceId(f));
    EXPECT_EQ(info.adjfaces, faces->faces[f].adjfaces) << "face " << f;
    EXPECT_EQ(info.adjedges, faces->faces[f].adjedges) << "face " << f;
    EXPECT_EQ(info.subface, faces->faces[f].subface) << "face " << f;
    texels += info.constant ? 1 : static_cast<std::int64_t>(info.num_texels());
  }
  ASSERT_NE(map->FindMetaData("dispex:options"), nullptr);
  ASSERT_NE(map->FindMetaData("PtexFaceVertCounts"), nullptr);

  // The report adds up.
  EXPECT_EQ(report->inputs.ptex_faces, static_cast<std::size_t>(faces->num_faces()));
  EXPECT_EQ(report->spectral.texels_after, texels);
  std::int64_t samples = 0;
  for (std::size_t k = 0; k < report->sampling.oversample_faces.size(); ++k) {
    samples += report->sampling.oversample_faces[k] << (2 * k);
  }
  EXPECT_EQ(report->sampling.samples, samples);
  EXPECT_EQ(report->spectral.texels_before, samples);
  // A refined sculpt's vertex displacements are interpolated through the subdivision
  // correspondence (ExtractMethod::kAuto): no rays.
  EXPECT_EQ(report->method.used, density == 0 ? ExtractMethod::kInterpolate : ExtractMethod::kRays);
  const std::int64_t traced = report->method.used == ExtractMethod::kRays ? samples : 0;
  EXPECT_GE(report->sampling.rays_cast, static_cast<std::uint64_t>(traced));
  EXPECT_LE(report->sampling.rays_cast, static_cast<std::uint64_t>(3 * traced));
  EXPECT_EQ(
      report->sampling.hits_positive + report->sampling.hits_negative + report->sampling.misses,
      samples);
  EXPECT_EQ(report->sampling.misses, 0);
  EXPECT_EQ(report->sampling.hits_opposed, 0);  // the sculpt does not fold
  EXPECT_LE(report->spectral.max_measured_error, report->settings.tolerance);
  if (density == 0) {
    // A level-3 sculpt of the cage: 2^4 samples per side on quads, 2^3 on n-gon sub-faces.
    EXPECT_EQ(report->sampling.oversample_subdivision_level, 3);
    EXPECT_EQ(report->sampling.oversample_faces[0] + report->sampling.oversample_faces[1] +
                  report->sampling.oversample_faces[2] + report->sampling.oversample_faces[5],
              0);
  } else {
    // Not a subdivision of the base: by the sculpt's density (the area-based path), about
    // two samples per cell side on average (per face it follows the face's area, not its
    // cells: small n-gon sub-faces get fewer).
    EXPECT_EQ(report->sampling.oversample_subdivision_level, -1);
    auto json = nlohmann::json::parse(ExtractReportJson(*report));
    EXPECT_EQ(json["statistics"]["oversample_rule"], "sculpt density");
    EXPECT_GE(report->sampling.samples, static_cast<std::int64_t>(2 * made->faces));
  }

  // Sign and magnitude: the map against the exact displacement, with verify's bounds
  // (1.5 tolerances + 2 x the sculpt's local linear error per vertex, RMS and p99 in
  // tolerances).
  const std::string truth = make.output_path + ".truth";
  VerifyReport checked =
      testing::CheckTruth(cage, options.output_path, truth, report->settings.tolerance);
  EXPECT_TRUE(checked.passed) << GetParam().what << ": " << checked.failure;
  EXPECT_TRUE(checked.truth_local_checked);
  // The same check rejects every negative control.
  for (testing::WrongMap kind : testing::kWrongMaps) {
    testing::WriteWrongMap(options.output_path, dir / "wrong.ptx", kind);
    VerifyReport wrong =
        testing::CheckTruth(cage, dir / "wrong.ptx", truth, report->settings.tolerance);
    EXPECT_FALSE(wrong.passed) << GetParam().what << ", " << testing::WrongMapName(kind);
  }
  MakeSculptOptions other = make;
  other.pattern = Pattern::kNoise;
  other.output_path = dir / "other.obj";
  ASSERT_TRUE(MakeSculpt(other).ok());
  EXPECT_FALSE(testing::CheckTruth(cage, options.output_path, other.output_path + ".truth",
                                   report->settings.tolerance)
                   .passed)
      << GetParam().what << ", another pattern";
}

INSTANTIATE_TEST_SUITE_P(
    Cages, ExtractRealCages,
    ::testing::Values(Case{"meshes/keenan_spot/spot_control_mesh.obj", "n-gons"},
                      Case{"meshes/stanford_bunny/bun_zipper_quadriflow_1000.obj", "quads"},
                      Case{"meshes/opensubdiv/catmark_torus_creases0.obj", "creases", 0, 0.01},
                      Case{"meshes/opensubdiv/catmark_tent.obj", "boundaries", 0, 0.008},
                      Case{"meshes/keenan_spot/spot_control_mesh.obj", "jittered n-gons", 12},
                      Case{"meshes/opensubdiv/catmark_torus_creases0.obj", "jittered creases", 23,
                           0.005}),
    [](const auto& param_info) {
      std::string name = param_info.param.what;
      for (char& c : name) {
        if (c == '-' || c == ' ') c = '_';
      }
      return name;
    });

class ExtractTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cage_ = DataPath("meshes/keenan_blub/blub_control_mesh.obj");
    MakeSculptOptions make = SculptOptions(cage_, dir_ / "sculpt.obj", 3, Pattern::kDetail, 0.005);
    auto made = MakeSculpt(make);
    ASSERT_TRUE(made.ok()) << made.status().message();
    sculpt_ = make.output_path;
  }
  ExtractOptions Options(const std::string& out) const {
    ExtractOptions o;
    o.base_path = cage_;
    o.sculpt_path = sculpt_;
    o.output_path = dir_ / out;
    return o;
  }

  TempDir dir_;
  std::string cage_, sculpt_;
};

TEST_F(ExtractTest, OneTwoAndEightThreadsGiveIdenticalBytes) {
  // Eight threads on this 2-core CI machine: oversubscribed, so tasks interleave and finish
  // in a different order on every run.
  std::string first;
  for (int threads : {1, 2, 8}) {
    ExtractOptions o = Options(fmt::format("threads{}.ptx", threads));
    o.threads = threads;
    auto report = Extract(o);
    ASSERT_TRUE(report.ok()) << report.status().message();
    EXPECT_EQ(report->settings.threads, threads);
    std::string bytes = testing::Slurp(o.output_path);
    ASSERT_GT(bytes.size(), 1000u);
    if (first.empty()) {
      first = bytes;
    } else {
      EXPECT_TRUE(bytes == first) << "the map at " << threads << " threads differs from 1 thread";
    }
  }
}

TEST_F(ExtractTest, HalfFloatAndFixedResolution) {
  ExtractOptions o = Options("half.ptx");
  o.data_type = PtexDataType::kHalf;
  o.resolution_rule = ResolutionRule::kFixed;
  o.fixed_ulog2 = 3;
  o.fixed_vlog2 = 2;
  auto report = Extract(o);
  ASSERT_TRUE(report.ok()) << report.status().message();
  auto map = PtexFile::Open(o.output_path);
  ASSERT_TRUE(map.ok());
  EXPECT_EQ(map->header().data_type, PtexDataType::kHalf);
  for (int f = 0; f < map->num_faces(); ++f) {
    const PtexFaceInfo& info = map->face_info(PtexFaceId(f));
    if (info.constant) continue;
    EXPECT_EQ(info.ulog2, 3);
    EXPECT_EQ(info.vlog2, 2);
  }
}

TEST_F(ExtractTest, SculptFarAwayIsAClearErrorAndWritesNothing) {
  auto sculpt = ReadMesh(sculpt_);
  ASSERT_TRUE(sculpt.ok());
  // Moved by ten bounding-box diagonals: no ray can reach it.
  std::string moved = dir_ / "moved.obj";
  {
    std::ofstream out(moved);
    for (const Float3& p : sculpt->positions)
      out << "v " << p.x + 30 << ' ' << p.y << ' ' << p.z << '\n';
    for (std::size_t f = 0; f < sculpt->num_faces(); ++f) {
      out << 'f';
      for (int v : sculpt->face(f)) out << ' ' << v + 1;
      out << '\n';
    }
  }
  ExtractOptions o = Options("far.ptx");
  o.sculpt_path = moved;
  auto report = Extract(o);
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.status().message().find("do not overlap"), std::string::npos)
      << report.status().message();
  EXPECT_FALSE(testing::fs::exists(o.output_path));
  // Only the inputs: sculpt.obj, its truth file and moved.obj.
  EXPECT_EQ(std::distance(testing::fs::directory_iterator(dir_.path()), {}), 3);

  o.search_distance = {SearchDistanceSpec::Kind::kAbsolute, 0.01};
  report = Extract(o);
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.status().message().find("do not overlap"), std::string::npos);
  EXPECT_FALSE(testing::fs::exists(o.output_path));
}

TEST_F(ExtractTest, BadInputsAreClearErrors) {
  std::string empty = dir_ / "empty.obj", no_faces = dir_ / "points.obj";
  std::ofstream(empty).close();
  std::ofstream(dir_ / "file.txt") << "x";
  std::ofstream(no_faces) << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  struct Bad {
    std::string base, sculpt, out, expect;
  };
  const Bad cases[] = {
      {cage_, empty, dir_ / "a.ptx", "empty.obj"},
      {cage_, no_faces, dir_ / "a.ptx", "points.obj"},
      {no_faces, sculpt_, dir_ / "a.ptx", "points.obj"},
      {cage_, dir_ / "missing.obj", dir_ / "a.ptx", "missing.obj: no such file"},
      {cage_, sculpt_, (dir_.path() / "file.txt" / "a.ptx").string(), "is not a folder"},
      {cage_, sculpt_, sculpt_, "also an input"},
      {cage_, sculpt_, dir_ / "a.exr", "a.exr: the name says OpenEXR"},
      // The outputs are checked before the meshes are read.
      {dir_ / "missing.obj", sculpt_, dir_ / "a.png", "a.png: the name says PNG"},
  };
  for (const Bad& bad : cases) {
    ExtractOptions o;
    o.base_path = bad.base;
    o.sculpt_path = bad.sculpt;
    o.output_path = bad.out;
    auto report = Extract(o);
    ASSERT_FALSE(report.ok()) << bad.expect;
    EXPECT_NE(report.status().message().find(bad.expect), std::string::npos)
        << report.status().message();
    EXPECT_EQ(report.status().message().find('\n'), std::string::npos);
  }
  EXPECT_FALSE(testing::fs::exists(dir_ / "a.ptx"));
}

TEST(ExtractFolds, HitsOnAFoldedSculptAreCounted) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  MakeSculptOptions make;
  make.cage_path = cage;
  make.output_path = dir / "folded.obj";
  make.levels = 3;
  make.pattern = Pattern::kSmooth;
  make.amplitude = 0.03;  // about 1% of the diagonal: folds in Spot's tight creases
  auto made = MakeSculpt(make);
  ASSERT_TRUE(made.ok()) << made.status().message();
  ASSERT_GT(made->folded_faces, 0u);
  ExtractOptions options;
  options.base_path = cage;
  options.sculpt_path = make.output_path;
  options.output_path = dir / "map.ptx";
  options.method = ExtractMethod::kMapping;  // rays (interpolated vertices meet no sheet)
  auto report = Extract(options);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_GT(report->sampling.hits_opposed, 0);
  EXPECT_LT(report->sampling.hits_opposed, report->sampling.samples / 10);
}

TEST_F(ExtractTest, HolesFailMakesAnyMissAnError) {
  ExtractOptions o = Options("fail.ptx");
  o.holes = HolePolicy::kFail;
  o.search_distance = {SearchDistanceSpec::Kind::kAbsolute, 1e-5};
  auto report = Extract(o);
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.status().message().find("holes = fail"), std::string::npos)
      << report.status().message();
  EXPECT_FALSE(testing::fs::exists(o.output_path));
}

TEST_F(ExtractTest, CommandLineWritesMapAndJsonReport) {
  std::string map = dir_ / "cli.ptx", json = dir_ / "report.json";
  auto r = RunDispex("extract " + cage_ + " " + sculpt_ + " -o " + map + " --report " + json +
                         " --tolerance 0.0002",
                     dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("texels"), std::string::npos);  // the summary
  auto report = nlohmann::json::parse(testing::Slurp(json));
  EXPECT_EQ(report["statistics"]["tolerance"].get<double>(), 0.0002);
  EXPECT_FALSE(report["statistics"]["tolerance_auto"].get<bool>());
  // The sculpt is the cage refined: its vertex displacements are interpolated, with no rays
  // and so no search distance.
  EXPECT_EQ(report["statistics"]["method"], "interpolate");
  EXPECT_FALSE(report["statistics"]["search_distance_auto"].get<bool>());
  for (const char* phase :
       {"read_base", "read_sculpt", "topology", "bvh", "sample_trace", "write", "total"}) {
    EXPECT_TRUE(report["phases_seconds"].contains(phase)) << phase;
  }
  EXPECT_GT(report["output"]["bytes"].get<std::uint64_t>(), 0u);
  EXPECT_GT(report["peak_rss_bytes"].get<std::uint64_t>(), 0u);

  // --preview writes the atlas and the comparison render beside the map.
  auto previewed = RunDispex(
      "extract " + cage_ + " " + sculpt_ + " -o " + map + " -q --preview " + (dir_ / "previews"),
      dir_);
  ASSERT_EQ(previewed.exit_code, 0) << previewed.err;
  for (const char* png : {"previews/cli_atlas.png", "previews/cli_compare.png"}) {
    std::string bytes = testing::Slurp(dir_ / png);
    ASSERT_GT(bytes.size(), 1000u) << png;
    EXPECT_EQ(bytes.substr(1, 3), "PNG") << png;
  }

  auto quiet = RunDispex("extract " + cage_ + " " + sculpt_ + " -o " + map + " -q", dir_);
  EXPECT_EQ(quiet.exit_code, 0);
  EXPECT_EQ(quiet.err, "");
  EXPECT_EQ(quiet.out, "");

  auto bad = RunDispex("extract " + cage_ + " " + sculpt_ + " -o " + map + " --tolerance -1", dir_);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--tolerance"), std::string::npos) << bad.err;
}

// A cage with tags dispex does not use: every command that reads it says so on stderr, naming
// the file and the tag, and the extract report lists it. The Chaikin box also takes its
// crease rule through make-sculpt, extract and verify: the map is within 4e-3 of the diagonal
// of the exact heights (measured 1.6e-3), where the rules differ by 8.7e-3.
TEST(IgnoredTags, EveryCommandAnnouncesThem) {
  TempDir dir;
  const std::string cage = dir / "tagged.obj";
  {
    std::ofstream out(cage, std::ios::binary);
    out << testing::Slurp(DataPath("meshes/dispex/chaikin_box.obj"))
        << "t facevaryinginterpolateboundary 1/0/0 1\nt somethingnew 0/0/0\n";
  }
  const std::string fvar = fmt::format(
      "{}: tag 'facevaryinginterpolateboundary' (1 line) ignored (face-varying data is not used)",
      cage);
  const std::string unknown =
      fmt::format("{}: tag 'somethingnew' (1 line) ignored: dispex does not know it", cage);
  const std::string sculpt = dir / "sculpt.obj", map = dir / "map.ptx", json = dir / "r.json";

  auto made = RunDispex("make-sculpt " + cage + " -o " + sculpt + " --levels 4", dir);
  ASSERT_EQ(made.exit_code, 0) << made.err;
  EXPECT_NE(made.err.find("dispex: warning: " + fvar + "\n"), std::string::npos) << made.err;
  EXPECT_NE(made.err.find("dispex: warning: " + unknown + "\n"), std::string::npos) << made.err;

  auto extracted =
      RunDispex("extract " + cage + " " + sculpt + " -o " + map + " --report " + json, dir);
  ASSERT_EQ(extracted.exit_code, 0) << extracted.err;
  EXPECT_NE(extracted.err.find("  warning: " + fvar + "\n"), std::string::npos) << extracted.err;
  EXPECT_NE(extracted.err.find("  warning: " + unknown + "\n"), std::string::npos) << extracted.err;
  const auto report = nlohmann::json::parse(testing::Slurp(json));
  const auto& warnings = report["warnings"];
  EXPECT_NE(std::find(warnings.begin(), warnings.end(), fvar), warnings.end()) << warnings;
  EXPECT_NE(std::find(warnings.begin(), warnings.end(), unknown), warnings.end()) << warnings;

  auto verified = RunDispex(
      "verify " + cage + " " + map + " --truth " + sculpt + ".truth --max-error-rel 4e-3", dir);
  EXPECT_EQ(verified.exit_code, 0) << verified.out << verified.err;
  EXPECT_NE(verified.err.find("dispex: warning: " + fvar + "\n"), std::string::npos)
      << verified.err;

  auto rendered = RunDispex("render " + cage + " -o " + (dir / "r.png") + " --size 64x64", dir);
  EXPECT_EQ(rendered.exit_code, 0) << rendered.err;
  EXPECT_NE(rendered.err.find("dispex: warning: " + unknown + "\n"), std::string::npos)
      << rendered.err;

  // Quiet commands print nothing, warnings included; the clean cage has none.
  auto quiet = RunDispex("render " + cage + " -o " + (dir / "q.png") + " --size 64x64 -q", dir);
  EXPECT_EQ(quiet.err, "");
  auto clean = RunDispex("render " + DataPath("meshes/dispex/chaikin_box.obj") + " -o " +
                             (dir / "c.png") + " --size 64x64",
                         dir);
  EXPECT_EQ(clean.err.find("warning"), std::string::npos) << clean.err;
}

}  // namespace
}  // namespace dispex
