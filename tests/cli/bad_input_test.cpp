// The bad-input matrix: every class of bad input or option, through the command line. Each
// must exit non-zero with exactly one line on stderr naming the problem, and leave no file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "../extract/e2e_support.h"
#include "dispex/mesh.h"
#include "dispex/verify.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::RunDispex;
using testing::SculptOptions;
using testing::TempDir;
namespace fs = std::filesystem;

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    cage_ = DataPath("meshes/keenan_blub/blub_control_mesh.obj");
    MakeSculptOptions make = SculptOptions(cage_, dir_ / "sculpt.obj", 2, Pattern::kDetail, 0.004);
    ASSERT_TRUE(MakeSculpt(make).ok());
    sculpt_ = make.output_path;
    fs::remove(make.output_path + ".truth");
  }

  void Write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }

  // Runs `dispex <args>` and checks the failure: exit code, one line on stderr that contains
  // `expect`, and no new file in the folder.
  void ExpectFailure(const std::string& args, const std::string& expect, int exit_code = 1,
                     const std::string& wrapper = "") {
    std::size_t files = Count();
    auto r = RunDispex(args, dir_, wrapper);
    EXPECT_EQ(r.exit_code, exit_code) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << args << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("dispex: ", 0), 0u) << r.err;
    EXPECT_EQ(Count(), files) << args << ": a file was left behind";
    EXPECT_FALSE(fs::exists(dir_ / "out.ptx")) << args;
  }
  std::size_t Count() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_.path()), {}));
  }
  std::string Extract(const std::string& base, const std::string& sculpt,
                      const std::string& more = "") {
    return "extract " + base + " " + sculpt + " -o " + (dir_ / "out.ptx") + " " + more;
  }

  TempDir dir_;
  std::string cage_, sculpt_;
};

TEST_F(BadInput, MissingDirectoryEmptyGarbageAndWrongFormat) {
  ExpectFailure(Extract(dir_ / "missing.obj", sculpt_), "missing.obj: no such file");
  ExpectFailure(Extract(cage_, dir_.path().string()), "is a directory");
  Write("empty.obj", "");
  ExpectFailure(Extract(cage_, dir_ / "empty.obj"), "empty.obj");
  Write("garbage.obj", std::string("\x7f\x45\x4c\x46\x02\x01\x01\x00\xff\xfe\x00\x13", 12));
  ExpectFailure(Extract(cage_, dir_ / "garbage.obj"), "garbage.obj");
  Write("mesh.stl", "solid x\nendsolid x\n");
  ExpectFailure(Extract(cage_, dir_ / "mesh.stl"), "mesh.stl");
  Write("garbage.ptx", "Ptex garbage");
  ExpectFailure("info " + (dir_ / "garbage.ptx"), "garbage.ptx");
}

// Root reads any file through its capabilities CAP_DAC_OVERRIDE and CAP_DAC_READ_SEARCH: as
// root the command runs without them (setpriv drops them from the bounding set, so the exec'd
// dispex never has them), and the file's mode 0 then refuses root as it refuses its owner.
TEST_F(BadInput, UnreadableFile) {
  Write("locked.obj", "v 0 0 0\n");
  ::chmod((dir_ / "locked.obj").c_str(), 0);
  const std::string wrapper =
      ::geteuid() == 0 ? "setpriv --bounding-set=-dac_override,-dac_read_search --" : "";
  ExpectFailure(Extract(cage_, dir_ / "locked.obj"), "locked.obj: Permission denied", 1, wrapper);
}

// A FIFO (or any file that is not a regular file) is refused by its type, before it is opened:
// opening a FIFO for reading would wait for a writer for ever.
TEST_F(BadInput, FifoInsteadOfAFile) {
  ASSERT_EQ(::mkfifo((dir_ / "pipe.obj").c_str(), 0644), 0);
  ExpectFailure(Extract(cage_, dir_ / "pipe.obj"), "pipe.obj: not a regular file");
  ExpectFailure(Extract(dir_ / "pipe.obj", sculpt_), "pipe.obj: not a regular file");
}

TEST_F(BadInput, NonFiniteCoordinates) {
  Write("nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n");
  ExpectFailure(Extract(cage_, dir_ / "nan.obj"), "nan.obj:2");
  Write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nv 1 1 0\nf 1 2 4 3\n");
  ExpectFailure(Extract(dir_ / "inf.obj", sculpt_), "inf.obj:3");
}

TEST_F(BadInput, DegenerateAndNonManifoldBases) {
  // A quad using one vertex twice.
  Write("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 2 4\nf 1 2 3 4\n");
  ExpectFailure(Extract(dir_ / "degenerate.obj", sculpt_), "degenerate.obj");
  // No faces at all.
  Write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  ExpectFailure(Extract(dir_ / "points.obj", sculpt_), "points.obj");
}

TEST_F(BadInput, SculptNotOverlappingTheBase) {
  auto far = ReadMesh(sculpt_);
  ASSERT_TRUE(far.ok());
  for (Float3& p : far->positions) p = {p.x + 100, p.y + 100, p.z + 100};
  ASSERT_TRUE(WriteObj(dir_ / "far.obj", *far).ok());
  ExpectFailure(Extract(cage_, dir_ / "far.obj"), "do not overlap");
}

TEST_F(BadInput, BaseAndSculptSwapped) {
  ExpectFailure(Extract(sculpt_, cage_), "base and sculpt swapped?");
  ExpectFailure(Extract(sculpt_, cage_), "extract with --no-input-checks if this is meant");
}

TEST_F(BadInput, BadOptionValues) {
  ExpectFailure(Extract(cage_, sculpt_, "--search-distance 0"), "--search-distance", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--search-distance -1"), "--search-distance", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--search-distance-rel -0.1"), "--search-distance-rel", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--tolerance -1"), "--tolerance", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--tolerance nan"), "--tolerance", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--oversample 3"), "--oversample", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--ray-policy sideways"), "--ray-policy", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--data-type double"), "--data-type", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--holes maybe"), "--holes", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--max-memory lots"), "--max-memory", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--frobnicate"), "--frobnicate", 2);
  ExpectFailure("frobnicate", "frobnicate", 2);
}

// Zero or negative values of options that must be positive are errors, never a silent
// "automatic" or "off".
TEST_F(BadInput, ZeroOrNegativeValuesOfPositiveOptions) {
  for (const char* option : {"--tolerance", "--tolerance-fraction", "--search-distance-rel",
                             "--max-oversample", "--min-oversample"}) {
    for (const char* value : {"0", "-1"}) {
      ExpectFailure(Extract(cage_, sculpt_, std::string(option) + " " + value), option, 2);
    }
  }
  ExpectFailure(Extract(cage_, sculpt_, "--threads -1"), "--threads", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--max-miss-fraction 1.5"), "--max-miss-fraction", 2);
  ExpectFailure(Extract(cage_, sculpt_, "--max-miss-fraction -0.1"), "--max-miss-fraction", 2);
  const std::string map = dir_ / "map.ptx";
  for (const char* option : {"--max-error", "--max-error-rel", "--max-rms"}) {
    ExpectFailure("verify " + cage_ + " " + sculpt_ + " " + map + " " + option + " 0", option, 2);
  }
  const std::string make = "make-sculpt " + cage_ + " -o " + (dir_ / "s.obj") + " ";
  ExpectFailure(make + "--amplitude 0", "--amplitude", 2);
  ExpectFailure(make + "--amplitude -0.1", "--amplitude", 2);
  ExpectFailure(make + "--levels 0", "--levels", 2);
  ExpectFailure("make-sculpt " + cage_ + " -o " + (dir_ / "s.stl"),
                "s.stl: -o must name an OBJ or PLY file (.obj or .ply)");
  const std::string render = "render " + cage_ + " -o " + (dir_ / "r.png") + " ";
  for (const char* option : {"--density 0", "--min-density 0", "--max-density 0", "--supersample 0",
                             "--ao -1", "--ao-distance 0"}) {
    ExpectFailure(render + option, std::string(option).substr(0, std::string(option).find(' ')), 2);
  }
  const std::string preview = "preview " + map + " -o " + (dir_ / "p.png") + " ";
  ExpectFailure(preview + "--tile 0", "--tile", 2);
  ExpectFailure(preview + "--max-tile 0", "--max-tile", 2);
}

// A sculpt that covers only half of the base: most rays from the other half find nothing,
// and a map that would be half invented by hole filling is refused.
TEST_F(BadInput, SculptCoveringHalfTheBaseIsRefused) {
  auto mesh = ReadMesh(sculpt_);
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  const BoundingBox box = ComputeBounds(*mesh);
  const float middle = 0.5f * (box.min.x + box.max.x);
  std::ofstream out(dir_ / "half.obj");
  for (const Float3& p : mesh->positions) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (std::size_t f = 0; f < mesh->num_faces(); ++f) {
    const auto first = mesh->face_indices[mesh->face_offsets[f]];
    if (mesh->positions[static_cast<std::size_t>(first)].x > middle) continue;
    out << 'f';
    for (auto k = mesh->face_offsets[f]; k < mesh->face_offsets[f + 1]; ++k) {
      out << ' ' << mesh->face_indices[k] + 1;
    }
    out << '\n';
  }
  out.close();
  ExpectFailure(Extract(cage_, dir_ / "half.obj"), "more than --max-miss-fraction (5%)");
  // The automatic settings are named by their options.
  ExpectFailure(Extract(cage_, dir_ / "half.obj"),
                "(automatic), more than --max-miss-fraction (5%): the sculpt covers only part of");
  ExpectFailure(Extract(cage_, dir_ / "half.obj"),
                "give a longer --search-distance, or raise --max-miss-fraction");
  // The limit is an option: raised, the same extraction succeeds and reports the fraction.
  auto r = RunDispex(
      Extract(cage_, dir_ / "half.obj", "--max-miss-fraction 1 -q --report " + (dir_ / "r.json")),
      dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.ptx"));
  std::ifstream report(dir_ / "r.json");
  const std::string text((std::istreambuf_iterator<char>(report)), {});
  const auto at = text.find("\"miss_fraction\": ");
  ASSERT_NE(at, std::string::npos);
  const double fraction = std::stod(text.substr(at + 17));
  EXPECT_GT(fraction, 0.2);
  EXPECT_LT(fraction, 0.8);
}

TEST_F(BadInput, OutputPaths) {
  Write("file.txt", "x");
  const std::string under_file = dir_ / "file.txt/sub";
  const std::string run = "extract " + cage_ + " " + sculpt_;
  ExpectFailure(run + " -o " + under_file + "/out.ptx", "-o: " + under_file + "/out.ptx: ", 2);
  ExpectFailure(run + " -o " + sculpt_, "also an input", 2);
  ExpectFailure(run + " -o " + dir_.path().string(), "is a folder", 2);
  ExpectFailure(run + " -o " + (dir_ / "map.exr"), "map.exr: the name says OpenEXR", 2);
  // Every output is checked before any work: no map is written when the report cannot be.
  ExpectFailure(run + " -o " + (dir_ / "m.ptx") + " --report " + under_file + "/r.json",
                "--report: " + under_file + "/r.json", 2);
  ExpectFailure(run + " -o " + (dir_ / "m.ptx") + " --preview " + (dir_ / "file.txt"),
                "--preview: " + (dir_ / "file.txt") + ": is a file, not a folder", 2);
  ExpectFailure("verify " + cage_ + " " + sculpt_ + " " + (dir_ / "no.ptx") + " --report " +
                    under_file + "/v.json",
                "--report: ", 2);
  ExpectFailure("render " + cage_ + " -o " + under_file + "/r.png", "-o: ", 2);
  // Missing folders are made for every output, and only by a run that writes it: a run that
  // fails leaves none.
  ExpectFailure(
      "extract " + (dir_ / "missing.obj") + " " + sculpt_ + " -o " + (dir_ / "new/out.ptx"),
      "missing.obj: no such file");
  const auto made =
      RunDispex(run + " -q -o " + (dir_ / "a/b/m.ptx") + " --report " + (dir_ / "c/r.json"), dir_);
  EXPECT_EQ(made.exit_code, 0) << made.err;
  EXPECT_TRUE(fs::exists(dir_ / "a/b/m.ptx"));
  EXPECT_TRUE(fs::exists(dir_ / "c/r.json"));
  if (::geteuid() != 0) {
    fs::create_directories(dir_ / "ro");
    ::chmod((dir_ / "ro").c_str(), 0555);
    ExpectFailure("extract " + cage_ + " " + sculpt_ + " -o " + (dir_ / "ro") + "/out.ptx",
                  "ro/out.ptx");
  }
}

// `dispex match`: a sculpt that is the base refined is matched (facts on stdout, JSON on
// request), wound either way; one of another cage, or too far from the limit surface, is
// refused with the reason.
TEST_F(BadInput, MatchRefusesWithTheReasonAndAcceptsTheRefinedBase) {
  const std::string spot = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  ExpectFailure("match " + spot + " " + sculpt_ + " --json " + (dir_ / "m.json"),
                "counts fit no level of");
  ExpectFailure("match " + cage_ + " " + sculpt_ + " --max-offset 1e-9 --json " + (dir_ / "m.json"),
                "the position check failed");
  ExpectFailure("match " + cage_ + " " + sculpt_ + " --max-offset 0", "--max-offset", 2);
  ExpectFailure("match " + cage_ + " " + sculpt_ + " --max-levels 8", "--max-levels", 2);
  auto r = RunDispex("match " + cage_ + " " + sculpt_ + " --json " + (dir_ / "m.json"), dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("level 2 (the sculpt is"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("components 1\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max offset "), std::string::npos) << r.out;
  std::ifstream json(dir_ / "m.json");
  const std::string text((std::istreambuf_iterator<char>(json)), {});
  EXPECT_NE(text.find("\"levels\": 2"), std::string::npos) << text;
  EXPECT_NE(text.find("\"reversed\": false"), std::string::npos) << text;
  EXPECT_EQ(r.out.find("reversed"), std::string::npos) << r.out;

  // Wound the other way (flipped normals): matched reversed, and said.
  auto flipped = ReadMesh(sculpt_);
  ASSERT_TRUE(flipped.ok());
  ReverseWinding(*flipped);
  ASSERT_TRUE(WriteObj(dir_ / "flipped.obj", *flipped).ok());
  r = RunDispex("match " + cage_ + " " + (dir_ / "flipped.obj") + " --json " + (dir_ / "f.json"),
                dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("level 2 (the sculpt is"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nreversed (every sculpt face winds the other way"), std::string::npos)
      << r.out;
  std::ifstream flipped_json(dir_ / "f.json");
  const std::string flipped_text((std::istreambuf_iterator<char>(flipped_json)), {});
  EXPECT_NE(flipped_text.find("\"reversed\": true"), std::string::npos) << flipped_text;
}

// Vector maps through the command line: a bad space, a sculpt that is not the base refined,
// then a map from the command line and one from a manifest's per-shape options.
TEST_F(BadInput, VectorMaps) {
  const std::string spot = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  ExpectFailure(Extract(cage_, sculpt_, "--vector world"),
                "--vector: unknown vector space 'world' (expected tangent, parametric or object)",
                2);
  ExpectFailure(Extract(spot, sculpt_, "--vector object"),
                "vector displacement reads the sculpt through its correspondence with the base, "
                "and there is none");
  auto r = RunDispex(Extract(cage_, sculpt_, "--vector tangent"), dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("vector (tangent): the sculpt is the base refined 2 times"),
            std::string::npos)
      << r.err;
  auto map = PtexFile::Open(dir_ / "out.ptx");
  ASSERT_TRUE(map.ok()) << map.status().message();
  EXPECT_EQ(map->header().num_channels, 3);
  Write("asset.json", "{\"shapes\": [{\"name\": \"cube\", \"base\": \"" + cage_ +
                          "\", \"sculpt\": \"" + sculpt_ +
                          "\", \"options\": {\"vector\": \"object\"}}]}");
  r = RunDispex("extract --manifest " + (dir_ / "asset.json") + " --out-dir " + (dir_ / "maps"),
                dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  auto shape = PtexFile::Open(dir_ / "maps/cube.ptx");
  ASSERT_TRUE(shape.ok()) << shape.status().message();
  ASSERT_NE(shape->FindMetaData("dispex:vector_space"), nullptr);
  EXPECT_EQ(shape->FindMetaData("dispex:vector_space")->AsString(), "object");
}

// Assets of several shapes through the command line: the errors, and a run that works.
TEST_F(BadInput, ShapesOptionsAndNames) {
  // Two shapes of the same cage in one base; the sculpt names one of them in other letter case.
  auto cage = ReadMesh(cage_);
  auto sculpt = ReadMesh(sculpt_);
  ASSERT_TRUE(cage.ok() && sculpt.ok());
  // An OBJ of `mesh` once per name, each an `o` group.
  auto groups = [](const Mesh& mesh, std::initializer_list<const char*> names) {
    std::ostringstream out;
    out.precision(9);
    std::size_t offset = 1;
    for (const char* name : names) {
      out << "o " << name << "\n";
      for (const Float3& p : mesh.positions) out << "v " << p.x << " " << p.y << " " << p.z << "\n";
      for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
        out << "f";
        for (std::int32_t v : mesh.face(f)) out << " " << offset + static_cast<std::size_t>(v);
        out << "\n";
      }
      offset += mesh.num_vertices();
    }
    return out.str();
  };
  Write("asset.obj", groups(*cage, {"left", "right"}));
  Write("asset_sculpt.obj", groups(*sculpt, {"Right"}));
  const std::string base = dir_ / "asset.obj", asset_sculpt = dir_ / "asset_sculpt.obj";

  ExpectFailure(Extract(base, asset_sculpt),
                "2 shapes ('left', 'right'): write one map per "
                "shape with --out-dir");
  ExpectFailure("extract " + base + " " + asset_sculpt + " --out-dir " + (dir_ / "maps"),
                "has no shape 'left'");
  ExpectFailure(
      "extract " + base + " " + asset_sculpt + " --out-dir " + (dir_ / "maps") + " --shapes right",
      "differs from 'right' only in letter case or blanks");
  ExpectFailure("extract " + base + " " + sculpt_ + " -o " + (dir_ / "out.ptx") + " --shapes left",
                "--shapes needs --out-dir", 2);
  ExpectFailure("extract --manifest " + (dir_ / "missing.json"), "missing.json: cannot be read", 2);

  // With a sculpt of two matching shapes: one map per shape, and the selection.
  Write("asset_sculpt.obj", groups(*sculpt, {"right", "left"}));
  auto r = RunDispex("extract " + base + " " + asset_sculpt + " --out-dir " + (dir_ / "maps") +
                         " --shapes right -q --report " + (dir_ / "asset.json"),
                     dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "maps/right.ptx"));
  EXPECT_FALSE(fs::exists(dir_ / "maps/left.ptx"));
  EXPECT_NE(testing::Slurp(dir_ / "asset.json").find("\"shape\": \"right\""), std::string::npos);
}

TEST_F(BadInput, TooLittleMemoryIsRefusedBeforeWork) {
  ExpectFailure(Extract(cage_, sculpt_, "--max-memory 1K"), "--max-memory");
}

}  // namespace
}  // namespace dispex
