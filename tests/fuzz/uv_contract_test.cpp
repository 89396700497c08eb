// The reader contract's UV checks (fuzz/reader_contract.h, CheckMeshResult and
// CompareMeshResults) catch what they claim to catch, and the OBJ reader's UVs keep them on
// real and generated files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>

#include "contract_meshes.h"
#include "dispex/mesh.h"
#include "fuzz/reader_contract.h"

namespace dispex {
namespace {

using fuzz_test::TexturedTriangle;

std::string Check(const Mesh& mesh) {
  return fuzz::CheckMesh(mesh, mesh.source);
}

// The check fails, and for a reason that names the UVs.
::testing::AssertionResult CaughtAsUvProblem(const Mesh& mesh) {
  const std::string why = Check(mesh);
  if (why.empty()) return ::testing::AssertionFailure() << "not caught";
  if (why.find("uv") == std::string::npos) {
    return ::testing::AssertionFailure() << "caught for another reason: " << why;
  }
  return ::testing::AssertionSuccess() << why;
}

TEST(UvContract, AcceptsWellFormedUvs) {
  EXPECT_EQ(Check(TexturedTriangle("t.obj")), "");
  Mesh dropped = TexturedTriangle("t.obj");
  dropped.uvs.clear();
  dropped.face_uv_indices.clear();
  EXPECT_EQ(Check(dropped), "");
  dropped.faces_without_uvs = 0;
  Mesh two = std::move(dropped);  // two faces, one of them counted as without UVs: fine
  two.face_offsets = {0, 3, 6};
  two.face_indices = {0, 1, 2, 0, 2, 1};
  two.faces_without_uvs = 1;
  EXPECT_EQ(Check(two), "");
}

TEST(UvContract, CatchesBrokenUvs) {
  const std::string name = "t.obj";
  Mesh m = TexturedTriangle(name);
  m.face_uv_indices[1] = 3;
  EXPECT_TRUE(CaughtAsUvProblem(m)) << "uv index out of range";

  m = TexturedTriangle(name);
  m.face_uv_indices[0] = -1;
  EXPECT_TRUE(CaughtAsUvProblem(m)) << "negative uv index";

  m = TexturedTriangle(name);
  m.face_uv_indices.pop_back();
  EXPECT_TRUE(CaughtAsUvProblem(m)) << "fewer uv indices than corners";

  m = TexturedTriangle(name);
  m.uvs[3] = std::numeric_limits<float>::infinity();
  EXPECT_TRUE(CaughtAsUvProblem(m)) << "infinite uv";

  m = TexturedTriangle(name);
  m.uvs.push_back(0.5f);
  EXPECT_TRUE(CaughtAsUvProblem(m)) << "odd uv array";

  m = TexturedTriangle(name);
  m.face_uv_indices.clear();
  EXPECT_TRUE(CaughtAsUvProblem(m)) << "uvs without indices";

  m = TexturedTriangle(name);
  m.faces_without_uvs = 1;
  EXPECT_TRUE(CaughtAsUvProblem(m)) << "dropped count while UVs are kept";

  m = TexturedTriangle(name);
  m.uvs.clear();
  m.face_uv_indices.clear();
  m.faces_without_uvs = 1;
  EXPECT_TRUE(CaughtAsUvProblem(m)) << "every face counted as without";

  Mesh other = TexturedTriangle(name);
  other.uvs[4] = 0.5f;
  EXPECT_NE(fuzz::CompareMeshResults(TexturedTriangle(name), other), "") << "uv value";
  other = TexturedTriangle(name);
  other.face_uv_indices = {0, 2, 1};
  EXPECT_NE(fuzz::CompareMeshResults(TexturedTriangle(name), other), "") << "uv indices";
}

TEST(UvContract, ReaderKeepsItOnFilesWithUvs) {
  for (const char* file :
       {"meshes/keenan_spot/spot_control_mesh.obj", "meshes/opensubdiv/catmark_nonquads.obj",
        "image_pattern/wavy_plane.obj"}) {
    const std::string path = (std::filesystem::path(DISPEX_TEST_DATA_DIR) / file).string();
    StatusOr<Mesh> mesh = ReadObj(path);
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    EXPECT_TRUE(mesh->has_uvs()) << file;
    EXPECT_EQ(fuzz::CheckMeshResult(mesh, path), "") << file;
    EXPECT_EQ(fuzz::CompareMeshResults(mesh, ReadObj(path, ReadOptions{1, 64})), "") << file;
  }
}

}  // namespace
}  // namespace dispex
