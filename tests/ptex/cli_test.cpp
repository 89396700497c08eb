// `dispex info` on Ptex files, through the real binary: summary, --faces (compared with the
// golden dump), --dump, --json, and errors on malformed files.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "dispex/ptex.h"
#include "golden_cases.h"
#include "ptex_test_util.h"

namespace dispex {
namespace {

struct CliResult {
  int exit_code = -1;
  std::string out, err;
};

CliResult Dispex(const std::string& args, const ptex_test::TempDir& dir) {
  const std::string err_path = (dir / "stderr.txt").string();
  const std::string cmd = std::string(DISPEX_EXE) + " " + args + " 2>" + err_path;
  CliResult r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  EXPECT_NE(pipe, nullptr);
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) r.out.append(buffer, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err_path);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  return r;
}

TEST(PtexInfoCli, Summary) {
  ptex_test::TempDir dir;
  CliResult r = Dispex("info " + ptex_test::FixturePath("quad_meta.ptx"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("mesh type     quad\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("data type     float32\n"), std::string::npos);
  EXPECT_NE(r.out.find("faces         2 (0 constant, 0 subfaces)\n"), std::string::npos);
  EXPECT_NE(r.out.find("border modes  u black, v periodic\n"), std::string::npos);
  EXPECT_NE(r.out.find("edge filter   tanvec\n"), std::string::npos);
  EXPECT_NE(r.out.find("size on disk  1027 bytes\n"), std::string::npos);
  EXPECT_NE(r.out.find("texels        24 at level 0"), std::string::npos);
  EXPECT_NE(r.out.find("  int8s int8[5]: -128 -1 0 1 127\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  author string[1]: \"ptexcheck fixture\"\n"), std::string::npos);
  EXPECT_NE(
      r.out.find("  big_floats float[300] (large): 0 0.5 1 1.5 2 2.5 3 3.5 ... (300 values)\n"),
      std::string::npos)
      << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(PtexInfoCli, FacesMatchTheGoldenDump) {
  ptex_test::TempDir dir;
  const ptex_test::GoldenCase c = ptex_test::GoldenCases()[0];
  const std::string path = (dir / "g.ptx").string();
  StatusOr<PtexWriter> w = PtexWriter::Create(path, c.options, c.num_faces);
  ASSERT_TRUE(w.ok());
  ASSERT_TRUE(c.fill(*w).ok());
  ASSERT_TRUE(w->Finish().ok());
  CliResult r = Dispex("info --faces " + path, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(ptex_test::GoldenDumpPath(c.name));
  std::stringstream golden;
  golden << in.rdbuf();
  const std::string g = golden.str();
  const std::string header = "# dispex info --faces\n";
  ASSERT_EQ(g.rfind(header, 0), 0u);
  EXPECT_EQ(r.out, g.substr(header.size(), g.find("# structure\n") - header.size()));
}

TEST(PtexInfoCli, DumpFace) {
  ptex_test::TempDir dir;
  CliResult r = Dispex("info --dump 0 " + ptex_test::FixturePath("example_2faces.ptx"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out,
            "face 0 4x4 float32 -\n"
            "v=0: 0 0.03125 0.0625 0.09375\n"
            "v=1: -0.0009765625 0.030273438 0.061523438 0.09277344\n"
            "v=2: -0.001953125 0.029296875 0.060546875 0.091796875\n"
            "v=3: -0.0029296875 0.028320312 0.059570312 0.09082031\n");
  r = Dispex("info --dump 2 " + ptex_test::FixturePath("example_2faces.ptx"), dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("face 2 is not in 0..1"), std::string::npos) << r.err;
}

TEST(PtexInfoCli, Json) {
  ptex_test::TempDir dir;
  CliResult r =
      Dispex("info --json --faces " + ptex_test::FixturePath("cc_pentagon_triangle.ptx"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["faces"], 10);
  EXPECT_EQ(j["constant_faces"], 1);
  EXPECT_EQ(j["subfaces"], 8);
  EXPECT_EQ(j["level_entries"], nlohmann::json::array({10, 2}));
  EXPECT_EQ(j["data_type"], "float32");
  EXPECT_EQ(j["meta_data"][0]["key"], "PtexFaceVertCounts");
  EXPECT_EQ(j["meta_data"][0]["value"], nlohmann::json::array({4, 5, 4, 3}));
  EXPECT_EQ(j["face_list"][4]["adjfaces"], nlohmann::json::array({6, 5, 3, 9}));
  EXPECT_EQ(j["face_list"][3]["constant"], true);
}

TEST(PtexInfoCli, MalformedFileIsAnError) {
  ptex_test::TempDir dir;
  std::vector<std::uint8_t> bytes = ptex_test::ReadBytes(ptex_test::FixturePath("quad_float1.ptx"));
  bytes.resize(300);
  const std::string path = (dir / "cut.ptx").string();
  ptex_test::WriteBytes(path, bytes);
  CliResult r = Dispex("info " + path, dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.rfind("dispex: " + path + ": ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line";
  EXPECT_TRUE(r.out.empty());
  // Corrupt face data is found by the summary's full check.
  bytes = ptex_test::ReadBytes(ptex_test::FixturePath("quad_float1.ptx"));
  bytes[bytes.size() - 20] ^= 0xff;
  ptex_test::WriteBytes(path, bytes);
  r = Dispex("info " + path, dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("level"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dispex
