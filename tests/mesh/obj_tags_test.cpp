// OpenSubdiv `t` tags (semantics of regression/common/far_utils.h; see src/mesh/obj_tags.h).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

using testing::ObjError;
using testing::ObjOrDie;

// A cube: 8 vertices, 6 faces.
const char kCube[] =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n";

TEST(ObjTags, CreaseForms) {
  const Mesh mesh = ObjOrDie(std::string(kCube) +
                             "t crease 2/1/0 0 1 2.0\n"
                             "t crease 4/1/0 1 3 3 2 10\n"           // two edges, one sharpness
                             "t crease 6/3/0 4 5 5 7 7 6 1 2 3.5\n"  // one sharpness per edge
                             "t crease 2/1/0 2 0 -1.0\n");           // clamped at 0
  const auto& c = mesh.tags.creases;
  ASSERT_EQ(c.size(), 7u);
  EXPECT_EQ(c[0].v0.value, 0);
  EXPECT_EQ(c[0].v1.value, 1);
  EXPECT_EQ(c[0].sharpness, 2.0f);
  EXPECT_EQ(c[1].v0.value, 1);
  EXPECT_EQ(c[1].v1.value, 3);
  EXPECT_EQ(c[2].v0.value, 3);
  EXPECT_EQ(c[2].v1.value, 2);
  EXPECT_EQ(c[1].sharpness, 10.0f);
  EXPECT_EQ(c[2].sharpness, 10.0f);
  EXPECT_EQ(c[3].sharpness, 1.0f);
  EXPECT_EQ(c[4].sharpness, 2.0f);
  EXPECT_EQ(c[5].v0.value, 7);
  EXPECT_EQ(c[5].v1.value, 6);
  EXPECT_EQ(c[5].sharpness, 3.5f);
  EXPECT_EQ(c[6].sharpness, 0.0f);
}

TEST(ObjTags, CornersHolesBoundary) {
  const Mesh mesh = ObjOrDie(std::string(kCube) +
                             "t corner 1/1/0 0 0.7\n"
                             "t corner 2/2/0 3 4 1.0 2.0\n"
                             "t corner 2/1/0 5 6 4\n"
                             "t hole 2/0/0 1 5\n"
                             "t hole 0/0/0\n"
                             "t interpolateboundary 1/0/0 0\n");
  const auto& k = mesh.tags.corners;
  ASSERT_EQ(k.size(), 5u);
  EXPECT_EQ(k[0].vertex.value, 0);
  EXPECT_EQ(k[0].sharpness, 0.7f);
  EXPECT_EQ(k[1].vertex.value, 3);
  EXPECT_EQ(k[1].sharpness, 1.0f);
  EXPECT_EQ(k[2].vertex.value, 4);
  EXPECT_EQ(k[2].sharpness, 2.0f);
  EXPECT_EQ(k[4].sharpness, 4.0f);
  ASSERT_EQ(mesh.tags.holes.size(), 2u);
  EXPECT_EQ(mesh.tags.holes[0].value, 1);
  EXPECT_EQ(mesh.tags.holes[1].value, 5);
  EXPECT_EQ(mesh.tags.boundary, BoundaryInterpolation::kNone);
  EXPECT_TRUE(mesh.tags.boundary_from_file);
  EXPECT_FALSE(mesh.tags.empty());
}

TEST(ObjTags, InterpolateBoundaryValues) {
  const BoundaryInterpolation expected[] = {BoundaryInterpolation::kNone,
                                            BoundaryInterpolation::kEdgeAndCorner,
                                            BoundaryInterpolation::kEdgeOnly};
  for (int value = 0; value < 3; ++value) {
    const Mesh mesh = ObjOrDie(std::string(kCube) + "t interpolateboundary 1/0/0 " +
                               std::to_string(value) + "\n");
    EXPECT_EQ(mesh.tags.boundary, expected[value]) << value;
  }
  const Mesh none = ObjOrDie(kCube);
  EXPECT_EQ(none.tags.boundary, BoundaryInterpolation::kEdgeAndCorner);
  EXPECT_FALSE(none.tags.boundary_from_file);
  EXPECT_TRUE(none.tags.empty());
  // The last one in the file wins, also across chunks.
  ReadOptions options;
  options.threads = 2;
  options.chunk_bytes = 16;
  const Mesh last = ObjOrDie(std::string(kCube) + "t interpolateboundary 1/0/0 0\n" + kCube +
                                 "t interpolateboundary 1/0/0 2\n",
                             options);
  EXPECT_EQ(last.tags.boundary, BoundaryInterpolation::kEdgeOnly);
}

TEST(ObjTags, CreaseMethodAndTriangles) {
  const Mesh none = ObjOrDie(kCube);
  EXPECT_EQ(none.tags.crease_method, CreaseMethod::kUniform);
  EXPECT_FALSE(none.tags.crease_method_from_file);
  EXPECT_EQ(none.tags.triangles, TriangleSubdivision::kCatmark);
  EXPECT_FALSE(none.tags.triangles_from_file);

  const Mesh set = ObjOrDie(std::string(kCube) +
                            "t creasemethod 0/0/1 chaikin\n"
                            "t smoothtriangles 0/0/1 smooth\n");
  EXPECT_EQ(set.tags.crease_method, CreaseMethod::kChaikin);
  EXPECT_TRUE(set.tags.crease_method_from_file);
  EXPECT_EQ(set.tags.triangles, TriangleSubdivision::kSmooth);
  EXPECT_TRUE(set.tags.triangles_from_file);
  EXPECT_TRUE(set.tags.ignored_tag_names.empty());
  EXPECT_TRUE(set.tags.empty());

  // The last tag of a kind wins, as in far_utils.h's GetSdcOptions.
  const Mesh back = ObjOrDie(std::string(kCube) +
                             "t creasemethod 0/0/1 chaikin\n"
                             "t creasemethod 0/0/1 normal\n"
                             "t smoothtriangles 0/0/1 smooth\n"
                             "t smoothtriangles 0/0/1 catmark\n");
  EXPECT_EQ(back.tags.crease_method, CreaseMethod::kUniform);
  EXPECT_TRUE(back.tags.crease_method_from_file);
  EXPECT_EQ(back.tags.triangles, TriangleSubdivision::kCatmark);
  EXPECT_TRUE(back.tags.triangles_from_file);

  // Hbr's integer form: 2 is the smooth (edge) rule, 0 Catmull-Clark.
  EXPECT_EQ(ObjOrDie(std::string(kCube) + "t smoothtriangles 1/0/0 2\n").tags.triangles,
            TriangleSubdivision::kSmooth);
  const Mesh zero = ObjOrDie(std::string(kCube) + "t smoothtriangles 0/0/1 smooth\n" +
                             "t smoothtriangles 1/0/0 0\n");
  EXPECT_EQ(zero.tags.triangles, TriangleSubdivision::kCatmark);
}

TEST(ObjTags, SettingsAcrossChunksKeepTheLast) {
  ReadOptions options;
  options.threads = 2;
  options.chunk_bytes = 16;
  const Mesh mesh = ObjOrDie(std::string(kCube) + "t creasemethod 0/0/1 chaikin\n" +
                                 "t smoothtriangles 0/0/1 smooth\n" + kCube +
                                 "t facevaryingpropagatecorners 1/0/0 0\n" + kCube,
                             options);
  EXPECT_EQ(mesh.tags.crease_method, CreaseMethod::kChaikin);
  EXPECT_EQ(mesh.tags.triangles, TriangleSubdivision::kSmooth);
  EXPECT_EQ(mesh.tags.ignored_tag_names, std::vector<std::string>{"facevaryingpropagatecorners"});
  const Mesh last = ObjOrDie(std::string(kCube) + "t creasemethod 0/0/1 chaikin\n" + kCube +
                                 "t creasemethod 0/0/1 normal\n" + kCube,
                             options);
  EXPECT_EQ(last.tags.crease_method, CreaseMethod::kUniform);
  EXPECT_TRUE(last.tags.crease_method_from_file);
}

TEST(ObjTags, OtherTagsAreKeptByName) {
  const Mesh mesh = ObjOrDie(std::string(kCube) +
                             "t facevaryinginterpolateboundary 1/0/0 1\n"
                             "t facevaryingpropagatecorners 1/0/0 0\n"
                             "t somethingnew 1/1/1 3 0.5 text\n"
                             "t facevaryinginterpolateboundary 1/0/0 2\n");
  EXPECT_EQ(
      mesh.tags.ignored_tag_names,
      (std::vector<std::string>{"facevaryinginterpolateboundary", "facevaryingpropagatecorners",
                                "somethingnew", "facevaryinginterpolateboundary"}));
  EXPECT_TRUE(mesh.tags.empty());
  EXPECT_EQ(mesh.tags.crease_method, CreaseMethod::kUniform);
  EXPECT_EQ(mesh.tags.triangles, TriangleSubdivision::kCatmark);

  const std::vector<std::string> warnings = IgnoredTagWarnings(mesh);
  ASSERT_EQ(warnings.size(), 3u);
  EXPECT_EQ(warnings[0],
            "test.obj: tag 'facevaryinginterpolateboundary' (2 lines) ignored (face-varying data "
            "is not used)");
  EXPECT_EQ(warnings[1],
            "test.obj: tag 'facevaryingpropagatecorners' (1 line) ignored (face-varying data is "
            "not used)");
  EXPECT_EQ(warnings[2], "test.obj: tag 'somethingnew' (1 line) ignored: dispex does not know it");
  EXPECT_TRUE(IgnoredTagWarnings(ObjOrDie(kCube)).empty());

  // Names are kept printable; past 10 names one line counts the rest.
  std::string many = kCube;
  for (int i = 0; i < 12; ++i) many += "t unknown" + std::to_string(i) + " 0/0/0\n";
  many += "t bad\x01name 0/0/0\n";
  const Mesh lots = ObjOrDie(many);
  ASSERT_EQ(lots.tags.ignored_tag_names.size(), 13u);
  EXPECT_EQ(lots.tags.ignored_tag_names[12], "bad?name");
  const std::vector<std::string> capped = IgnoredTagWarnings(lots);
  ASSERT_EQ(capped.size(), 11u);
  EXPECT_EQ(capped[9], "test.obj: tag 'unknown9' (1 line) ignored: dispex does not know it");
  EXPECT_EQ(capped[10], "test.obj: 3 more tag names ignored");
}

TEST(ObjTags, ContinuedTagLine) {
  const Mesh mesh = ObjOrDie(std::string(kCube) + "t crease 4/1/0 0 1 \\\n 1 3 \\\n 5.0\n");
  ASSERT_EQ(mesh.tags.creases.size(), 2u);
  EXPECT_EQ(mesh.tags.creases[1].sharpness, 5.0f);
}

TEST(ObjTags, Errors) {
  const std::string cube = kCube;  // 14 lines
  EXPECT_EQ(ObjError(cube + "t crease 2/1/0 0 8 1.0\n"),
            "test.obj:15: crease tag: vertex id 8 out of range (8 vertices; tag ids are 0-based)");
  EXPECT_EQ(ObjError(cube + "t corner 1/1/0 -1 1.0\n"),
            "test.obj:15: corner tag: vertex id -1 out of range (8 vertices; tag ids are 0-based)");
  EXPECT_EQ(ObjError(cube + "t hole 1/0/0 6\n"),
            "test.obj:15: hole tag: face id 6 out of range (6 faces; tag ids are 0-based)");
  EXPECT_EQ(ObjError(cube + "t crease 4/3/0 0 1 1 3 1 2 3\n"),
            "test.obj:15: crease tag needs 1 or 2 sharpness values (got 3)");
  EXPECT_EQ(ObjError(cube + "t crease 2/1/0 3 3 1\n"),
            "test.obj:15: crease tag: edge 3-3 joins a vertex to itself");
  EXPECT_EQ(ObjError(cube + "t corner 0/1/0 1.0\n"), "test.obj:15: corner tag without vertex ids");
  EXPECT_EQ(ObjError(cube + "t interpolateboundary 2/0/0 1 1\n"),
            "test.obj:15: interpolateboundary tag needs 1 integer (got 2)");
  EXPECT_EQ(ObjError(cube + "t crease 2/1/0 0 1.5 1\n"),
            "test.obj:15: tag 'crease': bad integer '1.5'");
  EXPECT_EQ(ObjError(cube + "t crease\n"),
            "test.obj:15: tag 'crease' without its <nint>/<nfloat>/<nstring> counts");
  EXPECT_EQ(ObjError(cube + "t\n"), "test.obj:15: tag line without a tag name");
  EXPECT_EQ(ObjError(cube + "t crease 2/1/-1 0 1 1\n"),
            "test.obj:15: tag 'crease': bad argument counts '2/1/-1' (expected "
            "<nint>/<nfloat>/<nstring>)");
  EXPECT_EQ(ObjError(cube + "t crease 4000000000/1/0 0 1\n"),
            "test.obj:15: tag 'crease' ends after 2 of its 4000000000 integers");
  EXPECT_EQ(ObjError(cube + "t smoothtriangles 0/0/1\n"),
            "test.obj:15: tag 'smoothtriangles' ends after 0 of its 1 strings");
  EXPECT_EQ(ObjError(cube + "t creasemethod 0/0/1 uniform\n"),
            "test.obj:15: creasemethod 'uniform' is not normal or chaikin");
  EXPECT_EQ(ObjError(cube + "t creasemethod 1/0/0 1\n"),
            "test.obj:15: creasemethod tag needs 1 string, normal or chaikin (got 1/0/0)");
  EXPECT_EQ(ObjError(cube + "t creasemethod 0/0/2 chaikin normal\n"),
            "test.obj:15: creasemethod tag needs 1 string, normal or chaikin (got 0/0/2)");
  EXPECT_EQ(ObjError(cube + "t smoothtriangles 0/0/1 loop\n"),
            "test.obj:15: smoothtriangles 'loop' is not catmark or smooth");
  EXPECT_EQ(ObjError(cube + "t smoothtriangles 1/0/0 1\n"),
            "test.obj:15: smoothtriangles 1 (Hbr's older face rule) is not in OpenSubdiv 3; use "
            "2 or 0/0/1 smooth (the edge rule)");
  EXPECT_EQ(ObjError(cube + "t smoothtriangles 1/0/0 3\n"),
            "test.obj:15: smoothtriangles 3 is not 0 (catmark) or 2 (smooth)");
  EXPECT_EQ(ObjError(cube + "t smoothtriangles 1/0/1 2 smooth\n"),
            "test.obj:15: smoothtriangles tag needs 1 string, catmark or smooth (got 1/0/1)");
  EXPECT_EQ(ObjError(cube + "t smoothtriangles 0/0/0\n"),
            "test.obj:15: smoothtriangles tag needs 1 string, catmark or smooth (got 0/0/0)");
  EXPECT_EQ(ObjError(cube + "t crease 2/1/0 0 1 \\\n inf\n"),
            "test.obj:16: tag 'crease': value 'inf' is not a finite number");
}

}  // namespace
}  // namespace dispex
