// The bad-input matrix: every class of bad input or option, through the command line. Each
// must exit non-zero with exactly one line on stderr naming the problem, and leave no file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>

#include "../extract/e2e_support.h"
#include "dispex/verify.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::SculptOptions;
using testing::RunDispex;
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
  void ExpectFailure(const std::string& args, const std::string& expect, int exit_code = 1) {
    std::size_t files = Count();
    auto r = RunDispex(args, dir_);
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

TEST_F(BadInput, UnreadableFile) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads any file";
  Write("locked.obj", "v 0 0 0\n");
  ::chmod((dir_ / "locked.obj").c_str(), 0);
  ExpectFailure(Extract(cage_, dir_ / "locked.obj"), "locked.obj");
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
  std::ofstream out(dir_ / "far.obj");
  out << "v 100 100 100\nv 101 100 100\nv 101 101 100\nv 100 101 100\nf 1 2 3 4\n";
  out.close();
  ExpectFailure(Extract(cage_, dir_ / "far.obj"), "do not overlap");
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

TEST_F(BadInput, OutputPaths) {
  ExpectFailure("extract " + cage_ + " " + sculpt_ + " -o " + (dir_ / "nodir") + "/out.ptx",
                "does not exist");
  ExpectFailure("extract " + cage_ + " " + sculpt_ + " -o " + sculpt_, "also an input", 2);
  ExpectFailure("extract " + cage_ + " " + sculpt_ + " -o " + dir_.path().string(),
                "is a directory");
  if (::geteuid() != 0) {
    fs::create_directories(dir_ / "ro");
    ::chmod((dir_ / "ro").c_str(), 0555);
    ExpectFailure("extract " + cage_ + " " + sculpt_ + " -o " + (dir_ / "ro") + "/out.ptx",
                  "ro/out.ptx");
  }
}

TEST_F(BadInput, TooLittleMemoryIsRefusedBeforeWork) {
  ExpectFailure(Extract(cage_, sculpt_, "--max-memory 1K"), "--max-memory");
}

}  // namespace
}  // namespace dispex
