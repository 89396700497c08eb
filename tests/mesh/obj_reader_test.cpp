// OBJ syntax: index forms, relative indices, n-gons, groups, comments, CRLF, continuations,
// ignored statements, numbers; and the line numbers of errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

using testing::ObjError;
using testing::ObjOrDie;

std::vector<std::int32_t> Face(const Mesh& mesh, std::size_t f) {
  const auto face = mesh.face(f);
  return {face.begin(), face.end()};
}

const char kFourVertices[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

TEST(ObjReader, AllIndexForms) {
  const Mesh mesh = ObjOrDie(std::string(kFourVertices) +
                             "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
                             "f 1 2 3\n"
                             "f 1/1 2/2 3/3\n"
                             "f 1//1 2//1 4//1\n"
                             "f 1/1/1 3/3/1 4/2/1\n"
                             "f -4 -3 -2 -1\n"
                             "f -4/-3/-1 2/-2 -2//1\n");
  ASSERT_EQ(mesh.num_faces(), 6u);
  EXPECT_EQ(Face(mesh, 0), (std::vector<std::int32_t>{0, 1, 2}));
  EXPECT_EQ(Face(mesh, 1), (std::vector<std::int32_t>{0, 1, 2}));
  EXPECT_EQ(Face(mesh, 2), (std::vector<std::int32_t>{0, 1, 3}));
  EXPECT_EQ(Face(mesh, 3), (std::vector<std::int32_t>{0, 2, 3}));
  EXPECT_EQ(Face(mesh, 4), (std::vector<std::int32_t>{0, 1, 2, 3}));
  EXPECT_EQ(Face(mesh, 5), (std::vector<std::int32_t>{0, 1, 2}));
  EXPECT_EQ(mesh.face_offsets, (std::vector<std::uint32_t>{0, 3, 6, 9, 12, 16, 19}));
  // Faces 1 and 3 name a texture coordinate at every corner, the others do not (face 5 only
  // at two corners): the mesh keeps no UVs and says how many faces lacked them.
  EXPECT_FALSE(mesh.has_uvs());
  EXPECT_TRUE(mesh.uvs.empty());
  EXPECT_EQ(mesh.faces_without_uvs, 4u);
}

TEST(ObjReader, TextureCoordinatesInEveryFaceForm) {
  const Mesh mesh = ObjOrDie(std::string(kFourVertices) +
                             "vt 0.25 0.5\n"
                             "vt 1 0 0.5\n"         // w ignored
                             "vt 0.75\n"            // v defaults to 0
                             "vt -1.5 2.5e1 0 7\n"  // further numbers ignored
                             "vn 0 0 1\n"
                             "f 1/1 2/2 3/3\n"
                             "f 1/4/1 3/3/1 4/2/1\n"
                             "f -4/-4 -3/-3/-1 -2/-2 -1/-1\n"
                             "vt 0.5 0.5\n"
                             "f 1/-1 2/5 3/-5\n");  // relative to the 5 vt lines before it
  ASSERT_EQ(mesh.num_faces(), 4u);
  ASSERT_TRUE(mesh.has_uvs());
  EXPECT_EQ(mesh.faces_without_uvs, 0u);
  EXPECT_EQ(mesh.uvs, (std::vector<float>{0.25f, 0.5f, 1, 0, 0.75f, 0, -1.5f, 25, 0.5f, 0.5f}));
  EXPECT_EQ(mesh.num_uvs(), 5u);
  EXPECT_EQ(mesh.face_uv_indices,
            (std::vector<std::int32_t>{0, 1, 2, 3, 2, 1, 0, 1, 2, 3, 4, 4, 0}));
  ASSERT_EQ(mesh.face_uv_indices.size(), mesh.face_indices.size());
}

// Texture indices, like vertex indices, may point forward to vt lines later in the file.
TEST(ObjReader, TextureIndicesMayPointForward) {
  const Mesh mesh =
      ObjOrDie(std::string(kFourVertices) + "f 1/3 2/2 3/1\nvt 0 0\nvt 1 0\nvt 1 1\n");
  ASSERT_TRUE(mesh.has_uvs());
  EXPECT_EQ(mesh.face_uv_indices, (std::vector<std::int32_t>{2, 1, 0}));
}

TEST(ObjReader, UvsDroppedWhenSomeFacesHaveNone) {
  // A face without vt among faces with: the mesh is kept, the UVs are not.
  const Mesh some = ObjOrDie(std::string(kFourVertices) +
                             "vt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\nf 1 3 4\nf 1/1 3/3 4/2\n");
  EXPECT_EQ(some.num_faces(), 3u);
  EXPECT_FALSE(some.has_uvs());
  EXPECT_TRUE(some.uvs.empty());
  EXPECT_EQ(some.faces_without_uvs, 1u);
  // A face that names texture coordinates at some corners only counts as without.
  const Mesh corner =
      ObjOrDie(std::string(kFourVertices) + "vt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\nf 1/1 3 4/2\n");
  EXPECT_FALSE(corner.has_uvs());
  EXPECT_EQ(corner.faces_without_uvs, 1u);
  // vt lines that no face uses: no UVs, and nothing was dropped.
  const Mesh unused = ObjOrDie(std::string(kFourVertices) + "vt 0 0\nvt 1 0\nf 1 2 3\n");
  EXPECT_FALSE(unused.has_uvs());
  EXPECT_TRUE(unused.uvs.empty());
  EXPECT_EQ(unused.faces_without_uvs, 0u);
}

TEST(ObjReader, TextureIndexErrorsNameTheLine) {
  const std::string vertices = std::string(kFourVertices) + "vt 0 0\nvt 1 1\n";  // 6 lines
  EXPECT_EQ(ObjError(vertices + "f 1/1 2/3 3/1\n"),
            "test.obj:7: face texture index 3 out of range (2 texture coordinates)");
  EXPECT_EQ(ObjError(vertices + "f 1/1 2/0 3/1\n"),
            "test.obj:7: face texture index 0 (OBJ indices start at 1)");
  EXPECT_EQ(ObjError(vertices + "f 1/1 2/-3/1 3/1\n"),
            "test.obj:7: relative face texture index -3 out of range (2 texture coordinates "
            "before it)");
  // The vertex index of a corner is checked before its texture index.
  EXPECT_EQ(ObjError(vertices + "f 1/1 9/9 3/1\n"),
            "test.obj:7: face index 9 out of range (4 vertices)");
  EXPECT_EQ(ObjError(vertices + "f 1/1 2/ 3/1\n"), "test.obj:7: bad face vertex '2/'");
  EXPECT_EQ(ObjError(vertices + "vt\nf 1/1 2/1 3/1\n"),
            "test.obj:7: texture has 0 coordinates (1 needed)");
  EXPECT_EQ(ObjError(vertices + "vt 1 inf\nf 1/1 2/1 3/1\n"),
            "test.obj:7: texture coordinate 'inf' is not a finite number");
  EXPECT_EQ(ObjError(vertices + "vt 1 0.5.5\nf 1/1 2/1 3/1\n"),
            "test.obj:7: bad texture coordinate '0.5.5'");
  // Normal indices are only checked for syntax.
  const Mesh dangling_normal = ObjOrDie(vertices + "f 1/1/7 2/2/8 3/1/9\n");
  EXPECT_TRUE(dangling_normal.has_uvs());
}

// A relative index counts back from the vertices defined so far, not from the file's end.
TEST(ObjReader, RelativeIndicesCountFromTheLine) {
  const Mesh mesh =
      ObjOrDie("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nv 6 6 6\nf -1 -2 -4 1\n");
  EXPECT_EQ(Face(mesh, 0), (std::vector<std::int32_t>{0, 1, 2}));
  EXPECT_EQ(Face(mesh, 1), (std::vector<std::int32_t>{4, 3, 1, 0}));
}

TEST(ObjReader, PositionsAndNumberForms) {
  const Mesh mesh = ObjOrDie(
      "v 1.5 -2.25 +3\n"
      "v\t1e2\t-1.5E-1\t.5\n"
      "v 0.1 -0 7. 1.0\n"         // with a w coordinate
      "v 1 2 3 0.5 0.25 0.125\n"  // with a colour
      "f 1 2 3 4\n");
  ASSERT_EQ(mesh.num_vertices(), 4u);
  EXPECT_EQ(mesh.positions[0].x, 1.5f);
  EXPECT_EQ(mesh.positions[0].y, -2.25f);
  EXPECT_EQ(mesh.positions[0].z, 3.0f);
  EXPECT_EQ(mesh.positions[1].x, 100.0f);
  EXPECT_EQ(mesh.positions[1].y, -0.15f);
  EXPECT_EQ(mesh.positions[1].z, 0.5f);
  EXPECT_EQ(mesh.positions[2].x, 0.1f);  // the float nearest to 0.1, rounded once
  EXPECT_EQ(mesh.positions[2].z, 7.0f);
  EXPECT_EQ(mesh.positions[3].z, 3.0f);
  EXPECT_GE(mesh.positions.capacity(), 5u);  // Embree's 16-byte read past the last vertex
}

TEST(ObjReader, NgonsKeepTheirWinding) {
  const Mesh mesh = ObjOrDie(
      "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 2 0\nv -1 1 0\nv -1 0.5 0\n"
      "f 1 2 3 4 5 6 7\nf 7 6 5 4 3\n");
  EXPECT_EQ(mesh.face_size(0), 7);
  EXPECT_EQ(Face(mesh, 1), (std::vector<std::int32_t>{6, 5, 4, 3, 2}));
  EXPECT_FALSE(mesh.all_quads());
}

TEST(ObjReader, ForwardReferencesAreAllowed) {
  const Mesh mesh = ObjOrDie("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
  EXPECT_EQ(Face(mesh, 0), (std::vector<std::int32_t>{0, 1, 2}));
}

TEST(ObjReader, Groups) {
  const Mesh mesh = ObjOrDie(std::string(kFourVertices) +
                             "f 1 2 3\n"  // before any group: "default"
                             "o body\n"
                             "f 1 2 3\nf 2 3 4\n"
                             "g  left   arm \n"  // names keep their words, blanks collapse
                             "f 1 2 3\n"
                             "g empty\n"  // no faces: not listed
                             "g body\n"   // same name again: same group
                             "f 1 3 4\n"
                             "g\n"  // no name: the default group
                             "f 1 2 4\n");
  EXPECT_EQ(mesh.group_names, (std::vector<std::string>{"default", "body", "left arm"}));
  EXPECT_EQ(mesh.face_groups, (std::vector<std::int32_t>{0, 1, 1, 2, 1, 0}));
}

TEST(ObjReader, NoGroupLinesNoGroups) {
  const Mesh mesh = ObjOrDie(std::string(kFourVertices) + "f 1 2 3\n");
  EXPECT_TRUE(mesh.face_groups.empty());
  EXPECT_TRUE(mesh.group_names.empty());
}

TEST(ObjReader, CommentsBlankLinesAndIgnoredStatements) {
  const Mesh mesh = ObjOrDie(
      "# header comment\n"
      "mtllib missing.mtl\n"
      "\n   \n\t\n"
      "v 0 0 0 # trailing comment\n"
      "v 1 0 0\n"
      "v 0 1 0\n"
      "vt 0 0\nvn 0 0 1\nvp 0.5\n"
      "usemtl skin\n"
      "s off\ns 1\n"
      "l 1 2\np 1\n"
      "cstype bspline\ndeg 3\n"
      "f 1 2 3 # a triangle\n"
      "#f 1 2 3\n");
  EXPECT_EQ(mesh.num_vertices(), 3u);
  EXPECT_EQ(mesh.num_faces(), 1u);
}

TEST(ObjReader, CrlfReadsLikeLf) {
  const std::string lf = std::string(kFourVertices) + "o a\nf 1 2 3 4\nt corner 1/1/0 2 1.5\n";
  std::string crlf;
  for (char c : lf) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  EXPECT_TRUE(testing::SameMesh(ObjOrDie(crlf), ObjOrDie(lf)));
  // And the line numbers of errors are the same.
  EXPECT_EQ(ObjError(crlf + "f 1 2 9\r\n"), "test.obj:8: face index 9 out of range (4 vertices)");
}

TEST(ObjReader, ContinuationLines) {
  const Mesh joined = ObjOrDie(std::string(kFourVertices) + "f 1 2 3 4\n");
  EXPECT_TRUE(testing::SameMesh(ObjOrDie("v 0 0 0\nv 1 \\\n0 0\nv 1 1 0\nv 0 1 0\n"
                                         "f 1 \\\n  2 \\\r\n  3\\\n 4\n"),
                                joined));
  // A continuation before the keyword, and one after it.
  EXPECT_TRUE(testing::SameMesh(ObjOrDie("v 0 0 0\nv 1 0 0\n\\\nv 1 1 0\nv\\\n 0 1 0\nf 1 2 3 4\n"),
                                joined));
  // Physical lines are still counted across continuations.
  EXPECT_EQ(ObjError(std::string(kFourVertices) + "f 1 \\\n 2 \\\n 3 \\\n 99\n"),
            "test.obj:8: face index 99 out of range (4 vertices)");
}

TEST(ObjReader, NoFinalNewline) {
  const Mesh mesh = ObjOrDie("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3");
  EXPECT_EQ(mesh.num_faces(), 1u);
}

TEST(ObjReader, FirstErrorInFileOrderWins) {
  // Two errors: the earlier line is reported, whatever the chunking.
  std::string text = std::string(kFourVertices);
  for (int i = 0; i < 200; ++i) text += "f 1 2 3\n";
  text += "f 1 2 0\n";  // line 205
  for (int i = 0; i < 200; ++i) text += "f 1 2 3\n";
  text += "v 1 2 x\n";  // line 406
  for (std::size_t chunk : {std::size_t{0}, std::size_t{1}, std::size_t{16}, std::size_t{999}}) {
    ReadOptions options;
    options.threads = 2;
    options.chunk_bytes = chunk;
    EXPECT_EQ(ObjError(text, options), "test.obj:205: face index 0 (OBJ indices start at 1)");
  }
}

TEST(ObjReader, ErrorMessagesNameTheFileAndLine) {
  EXPECT_EQ(ObjError("v 0 0 0\nv 1 0 0\nf 1 2 3\n"),
            "test.obj:3: face index 3 out of range (2 vertices)");
  EXPECT_EQ(ObjError("v 0 0 0\n\n# c\nv 1 0 0 junk\n"),
            "test.obj:4: unexpected 'junk' after the vertex coordinates");
  EXPECT_EQ(ObjError("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 3 4.5\n"),
            "test.obj:4: bad face vertex '4.5'");
  EXPECT_EQ(ObjError("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 3\n3 4 5\n"),
            "test.obj:5: line does not start with an OBJ keyword ('3')");
  EXPECT_EQ(ObjError("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 3 \\\r"),
            "test.obj:4: line continued with '\\' at the end of the file");
  EXPECT_EQ(ObjError("v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 3 \\  \n"),
            "test.obj:4: bad face vertex '\\'");  // a '\\' must end its line
  EXPECT_EQ(ObjError("v 1 2 3\n"), "test.obj: no faces (1 vertices): not a polygon mesh");
}

TEST(ObjReader, ReadObjFromFile) {
  const std::string path = testing::TempPath(".obj");
  {
    std::ofstream out(path, std::ios::binary);
    out << kFourVertices << "g quad\nf 1 2 3 4\n";
  }
  StatusOr<Mesh> mesh = ReadObj(path);
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->source, path);
  EXPECT_EQ(mesh->group_names, std::vector<std::string>{"quad"});
  StatusOr<Mesh> via_read_mesh = ReadMesh(path);
  ASSERT_TRUE(via_read_mesh.ok());
  EXPECT_TRUE(testing::SameMesh(*mesh, *via_read_mesh));
  EXPECT_EQ(DetectMeshFormat(path), MeshFormat::kObj);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace dispex
