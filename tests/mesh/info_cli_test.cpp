// `dispex info MESH` end to end: runs the dispex binary and checks its output and exit code.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace {

struct CliRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

CliRun Dispex(const std::string& args) {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string err_path =
      ::testing::TempDir() + "/dispex_" + test->name() + "_" + std::to_string(::getpid()) + ".err";
  const std::string command = std::string(DISPEX_EXE) + " " + args + " 2>" + err_path;
  CliRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.err = Slurp(err_path);
  std::remove(err_path.c_str());
  return run;
}

std::string Data(const std::string& relative) {
  return (std::filesystem::path(DISPEX_TEST_DATA_DIR) / relative).string();
}

TEST(InfoCli, TextSummary) {
  const std::string path = Data("meshes/keenan_spot/spot_control_mesh.obj");
  const CliRun run = Dispex("info " + path);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  EXPECT_NE(run.out.find("mesh          " + path + "\n"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("format        OBJ\n"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("vertices      188\n"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("faces         180 (4 triangles, 160 quads, 16 5-gons)\n"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("bounds        min (-0.585967, -0.759125, -0.696223) max (0.585967, "
                         "0.984026, 1.07776)\n"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("warnings      0\n"), std::string::npos) << run.out;
  // 267 `vt` lines in the file, named by every face.
  EXPECT_NE(run.out.find("uvs           267 texture coordinates on every face\n"),
            std::string::npos)
      << run.out;
}

TEST(InfoCli, TagsAndWarningsInText) {
  const CliRun run = Dispex("info " + Data("meshes/opensubdiv/catmark_fan.obj"));
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("boundary      edge_and_corner (from the file)\n"), std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("edges         20 boundary, 4 non-manifold, 0 inconsistently wound\n"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("  warning: 4 non-manifold edges"), std::string::npos) << run.out;
  const CliRun creases = Dispex("info " + Data("meshes/opensubdiv/catmark_cubes_infsharp.obj"));
  EXPECT_NE(creases.out.find("creases       18 (17 infinitely sharp)\n"), std::string::npos)
      << creases.out;
  EXPECT_NE(creases.out.find("ignored tags  1 (facevaryinginterpolateboundary)\n"),
            std::string::npos)
      << creases.out;
  EXPECT_NE(creases.out.find("crease method uniform (default)\n"), std::string::npos)
      << creases.out;
  const CliRun tris = Dispex("info " + Data("meshes/opensubdiv/catmark_smoothtris0.obj"));
  EXPECT_NE(tris.out.find("triangles     catmark (from the file)\n"), std::string::npos)
      << tris.out;
  EXPECT_NE(tris.out.find("ignored tags  0\n"), std::string::npos) << tris.out;
}

TEST(InfoCli, JsonParses) {
  const CliRun run = Dispex("info --json " + Data("meshes/stanford_bunny/bun_zipper.ply"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["format"], "PLY");
  EXPECT_EQ(j["vertices"], 35947);
  EXPECT_EQ(j["faces"], 69451);
  EXPECT_EQ(j["faces_by_size"]["3"], 69451);
  EXPECT_EQ(j["face_corners"], 3 * 69451);
  EXPECT_EQ(j["groups"].size(), 0u);
  EXPECT_EQ(j["tags"]["boundary"], "edge_and_corner");
  EXPECT_EQ(j["tags"]["boundary_from_file"], false);
  EXPECT_EQ(j["tags"]["crease_method"], "uniform");
  EXPECT_EQ(j["tags"]["triangles"], "catmark");
  EXPECT_EQ(j["tags"]["ignored"], 0);
  EXPECT_EQ(j["tags"]["ignored_names"].size(), 0u);
  EXPECT_NEAR(j["bounds"]["min"][0].get<double>(), -0.0946899, 1e-7);
  EXPECT_NEAR(j["bounds"]["max"][1].get<double>(), 0.187321, 1e-7);
  EXPECT_NEAR(j["median_edge_length"].get<double>(), 0.0014670207735407127, 1e-9);
  EXPECT_EQ(j["validation"]["clean"], false);
  EXPECT_EQ(j["validation"]["boundary_edges"], 223);
  EXPECT_EQ(j["validation"]["unreferenced_vertices"], 1113);
  ASSERT_EQ(j["validation"]["warnings"].size(), 1u);
  EXPECT_EQ(j["validation"]["warnings"][0], "1113 unreferenced vertices (first: vertex 8)");
}

TEST(InfoCli, StrictTurnsWarningsIntoFailure) {
  const std::string bunny = Data("meshes/stanford_bunny/bun_zipper.ply");
  const CliRun run = Dispex("info --strict " + bunny);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err, "dispex: " + bunny +
                         ": mesh is not clean: 1113 unreferenced vertices (first: vertex 8)\n");
  const CliRun clean = Dispex("info --strict " + Data("meshes/opensubdiv/catmark_cube.obj"));
  EXPECT_EQ(clean.exit_code, 0) << clean.err;
  EXPECT_EQ(clean.err, "");
}

TEST(InfoCli, ErrorsExitOneWithOneLine) {
  const std::string bad = Data("malformed/obj_index_out_of_range.obj");
  const CliRun run = Dispex("info " + bad);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.out, "");
  EXPECT_EQ(run.err, "dispex: " + bad + ":4: face index 4 out of range (3 vertices)\n");
  const CliRun json = Dispex("info --json " + Data("malformed/ply_huge_face_count.ply"));
  EXPECT_EQ(json.exit_code, 1);
  EXPECT_EQ(json.out, "");
  EXPECT_EQ(json.err.find("dispex: "), 0u);
  EXPECT_EQ(json.err.find('\n'), json.err.size() - 1) << json.err;
  const CliRun missing = Dispex("info " + Data("meshes/no_such_mesh.obj"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("no such file"), std::string::npos) << missing.err;
  const CliRun unknown = Dispex("info " + Data("malformed/not_a_mesh.stl"));
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.err.find("unknown mesh format"), std::string::npos) << unknown.err;
}

}  // namespace

// `dispex convert`: OBJ to binary PLY and back keeps the mesh (the same summary, bounds and
// median edge to the bit: positions are copied, not printed and parsed), says what it drops,
// and refuses a name of neither format before reading anything.
TEST(ConvertCli, ObjToPlyAndBackKeepsTheMesh) {
  const std::string obj = Data("meshes/keenan_spot/spot_control_mesh.obj");
  const std::string ply =
      ::testing::TempDir() + "/dispex_convert_" + std::to_string(::getpid()) + ".ply";
  const std::string back = ply + ".obj";
  const CliRun to_ply = Dispex("convert " + obj + " " + ply);
  ASSERT_EQ(to_ply.exit_code, 0) << to_ply.err;
  EXPECT_EQ(to_ply.err,
            "dispex: warning: " + obj + ": texture coordinates not written to " + ply + "\n");
  EXPECT_NE(to_ply.out.find("(188 vertices, 180 faces) -> " + ply), std::string::npos)
      << to_ply.out;
  const CliRun to_obj = Dispex("convert -q " + ply + " " + back);
  ASSERT_EQ(to_obj.exit_code, 0) << to_obj.err;
  EXPECT_EQ(to_obj.out, "");
  auto summary = [](const std::string& path) {
    nlohmann::json j = nlohmann::json::parse(Dispex("info --json " + path).out);
    return nlohmann::json{{"vertices", j["vertices"]},
                          {"faces", j["faces"]},
                          {"sizes", j["faces_by_size"]},
                          {"bounds", j["bounds"]},
                          {"median", j["median_edge_length"]}};
  };
  const nlohmann::json original = summary(obj);
  EXPECT_EQ(summary(ply), original);
  EXPECT_EQ(summary(back), original);
  EXPECT_EQ(nlohmann::json::parse(Dispex("info --json " + ply).out)["format"], "PLY");
  std::remove(ply.c_str());
  std::remove(back.c_str());
}

// --fingerprint prints what a map records of the mesh (dispex:sculpt_fingerprint): the same for
// the mesh as OBJ and as binary PLY (UVs are not part of it), another for a moved vertex.
TEST(InfoCli, FingerprintIsTheMeshsNotTheFiles) {
  const std::string obj = Data("meshes/keenan_spot/spot_control_mesh.obj");
  const std::string ply =
      ::testing::TempDir() + "/dispex_fingerprint_" + std::to_string(::getpid()) + ".ply";
  ASSERT_EQ(Dispex("convert -q " + obj + " " + ply).exit_code, 0);
  const CliRun from_obj = Dispex("info --fingerprint " + obj);
  EXPECT_EQ(from_obj.exit_code, 0) << from_obj.err;
  ASSERT_EQ(from_obj.out.size(), std::string("xxh3-128:").size() + 32 + 1) << from_obj.out;
  EXPECT_EQ(from_obj.out.rfind("xxh3-128:", 0), 0u) << from_obj.out;
  EXPECT_EQ(Dispex("info --fingerprint " + ply).out, from_obj.out);
  const std::string moved = ply + ".obj";
  std::string text = Slurp(obj);
  text[text.find("\nv ") + 3] = '9';  // the second vertex's x: 0.38... becomes 9.38...
  std::ofstream(moved) << text;
  EXPECT_NE(Dispex("info --fingerprint " + moved).out, from_obj.out);
  std::remove(ply.c_str());
  std::remove(moved.c_str());
}

TEST(ConvertCli, AnOutputOfNeitherFormatIsRefused) {
  const std::string out =
      ::testing::TempDir() + "/dispex_convert_" + std::to_string(::getpid()) + ".stl";
  const CliRun run =
      Dispex("convert " + Data("meshes/keenan_spot/spot_control_mesh.obj") + " " + out);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err, "dispex: " + out + ": the output must be named .obj or .ply\n");
  EXPECT_NE(::access(out.c_str(), F_OK), 0);
  const CliRun missing =
      Dispex("convert /nonexistent/in.obj " + out.substr(0, out.size() - 3) + "ply");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("/nonexistent/in.obj"), std::string::npos) << missing.err;
}

// make-sculpt writes the format its output's name asks for: the same sculpt as OBJ and as PLY.
TEST(ConvertCli, MakeSculptWritesPlyByName) {
  const std::string cage = Data("meshes/keenan_spot/spot_control_mesh.obj");
  const std::string stem =
      ::testing::TempDir() + "/dispex_make_sculpt_" + std::to_string(::getpid());
  for (const char* ext : {".obj", ".ply"}) {
    const CliRun run = Dispex("make-sculpt " + cage + " --levels 2 -q -o " + stem + ext);
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  const nlohmann::json obj = nlohmann::json::parse(Dispex("info --json " + stem + ".obj").out);
  const nlohmann::json ply = nlohmann::json::parse(Dispex("info --json " + stem + ".ply").out);
  EXPECT_EQ(ply["format"], "PLY");
  for (const char* key : {"vertices", "faces", "bounds", "median_edge_length"}) {
    EXPECT_EQ(obj[key], ply[key]) << key;
  }
  for (const char* ext : {".obj", ".ply"}) {
    std::remove((stem + ext).c_str());
    std::remove((stem + ext + ".truth").c_str());
  }
}
