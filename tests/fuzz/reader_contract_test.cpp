// The checks of fuzz/reader_contract.h must catch what they claim to catch: a fuzzer whose
// oracle never fires finds nothing. Each case breaks one promise by hand.
#include "fuzz/reader_contract.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "contract_meshes.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"

namespace dispex {
namespace {

using fuzz_test::Triangle;

TEST(ReaderContract, AcceptsAWellFormedMesh) {
  EXPECT_EQ(fuzz::CheckMesh(Triangle("t.obj"), "t.obj"), "");
  EXPECT_EQ(fuzz::CheckMeshResult(Triangle("t.obj"), "t.obj"), "");
}

TEST(ReaderContract, CatchesBrokenMeshes) {
  const std::string name = "t.obj";
  Mesh m = Triangle(name);
  m.face_indices[2] = 3;
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "index out of range";

  m = Triangle(name);
  m.positions[1].y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "NaN position";

  m = Triangle(name);
  m.face_offsets = {0, 2, 3};
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "faces of 2 and 1 corners";

  m = Triangle(name);
  m.face_offsets = {0};
  m.face_indices.clear();
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "no faces";

  m = Triangle(name);
  m.positions.shrink_to_fit();
  if (m.positions.capacity() == m.positions.size()) {
    EXPECT_NE(fuzz::CheckMesh(m, name), "") << "no spare capacity";
  }

  m = Triangle(name);
  m.face_groups = {1};
  m.group_names = {"a"};
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "group id out of range";

  m = Triangle(name);
  m.face_groups = {0};
  m.group_names = {"a", "unused"};
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "group without faces";

  m = Triangle(name);
  m.tags.creases.push_back({VertexId(0), VertexId(7), 1.0f});
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "crease vertex out of range";

  m = Triangle(name);
  m.tags.corners.push_back({VertexId(0), -1.0f});
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "negative sharpness";

  m = Triangle(name);
  m.tags.holes.push_back(BaseFaceId(1));
  EXPECT_NE(fuzz::CheckMesh(m, name), "") << "hole out of range";

  EXPECT_NE(fuzz::CheckMesh(Triangle("other.obj"), name), "") << "wrong source";
}

TEST(ReaderContract, CatchesBadErrorMessages) {
  const std::string name = "m.ply";
  EXPECT_EQ(fuzz::CheckErrorMessage(Status::Error("m.ply:3: bad"), name), "");
  EXPECT_NE(fuzz::CheckErrorMessage(Status::Ok(), name), "");
  EXPECT_NE(fuzz::CheckErrorMessage(Status::Error("m.ply:3: two\nlines"), name), "");
  EXPECT_NE(fuzz::CheckErrorMessage(Status::Error("m.ply: key '\r'"), name), "");
  EXPECT_NE(fuzz::CheckErrorMessage(Status::Error(std::string("m.ply: nul \0", 12)), name), "");
  EXPECT_NE(fuzz::CheckErrorMessage(Status::Error("m.ply: escape \x1b[31m"), name), "");
  EXPECT_NE(fuzz::CheckErrorMessage(Status::Error("other.ply: bad"), name), "");
  EXPECT_NE(fuzz::CheckErrorMessage(Status::Error("m.ply"), name), "");
  EXPECT_NE(fuzz::CheckErrorMessage(Status::Error("m.plyx: bad"), name), "");
  // Bytes above ASCII (a UTF-8 name) are no control bytes.
  EXPECT_EQ(fuzz::CheckErrorMessage(Status::Error("m.ply: caf\xc3\xa9"), name), "");
}

TEST(ReaderContract, ComparesResultsExactly) {
  const StatusOr<Mesh> a = Triangle("t.obj");
  EXPECT_EQ(fuzz::CompareMeshResults(a, Triangle("t.obj")), "");
  Mesh moved = Triangle("t.obj");
  moved.positions[2].z = -0.0f;  // equal as numbers, not as bits
  EXPECT_NE(fuzz::CompareMeshResults(a, moved), "");
  Mesh tagged = Triangle("t.obj");
  tagged.tags.ignored_tag_names = {"x"};
  EXPECT_NE(fuzz::CompareMeshResults(a, tagged), "");
  Mesh chaikin = Triangle("t.obj");
  chaikin.tags.crease_method = CreaseMethod::kChaikin;
  EXPECT_NE(fuzz::CompareMeshResults(a, chaikin), "");
  Mesh smooth = Triangle("t.obj");
  smooth.tags.triangles = TriangleSubdivision::kSmooth;
  EXPECT_NE(fuzz::CompareMeshResults(a, smooth), "");
  const StatusOr<Mesh> failed = Status::Error("t.obj:1: bad");
  EXPECT_NE(fuzz::CompareMeshResults(a, failed), "");
  EXPECT_EQ(fuzz::CompareMeshResults(failed, Status::Error("t.obj:1: bad")), "");
  EXPECT_NE(fuzz::CompareMeshResults(failed, Status::Error("t.obj:2: bad")), "");
}

// Garbage gives a failed Status that keeps the message contract: no violation reported.
TEST(ReaderContract, PtexExerciseAcceptsCleanErrors) {
  const std::string name = "x.ptx";
  EXPECT_EQ(fuzz::ExercisePtex("", name), "");
  EXPECT_EQ(fuzz::ExercisePtex("Ptex and then nothing", name), "");
  EXPECT_EQ(fuzz::ExercisePtex(std::string(200, '\0'), name), "");
}

}  // namespace
}  // namespace dispex
