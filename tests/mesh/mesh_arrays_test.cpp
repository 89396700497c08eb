// CheckMeshArrays: a mesh built in memory held to the readers' contract, one case per rule, and
// every mesh a reader returns passing it. ReverseWinding.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

Mesh Quad() {
  return testing::ObjOrDie("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
}

std::string Error(const Mesh& mesh) {
  const Status s = CheckMeshArrays(mesh);
  EXPECT_FALSE(s.ok());
  return s.message();
}

TEST(CheckMeshArrays, ReadMeshesPass) {
  EXPECT_TRUE(CheckMeshArrays(Quad()).ok());
  for (const char* file :
       {"meshes/opensubdiv/catmark_cube_creases0.obj", "meshes/opensubdiv/catmark_hole_test1.obj",
        "meshes/opensubdiv/catmark_car.obj"}) {
    StatusOr<Mesh> mesh = ReadMesh(testing::DataPath(file));
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    EXPECT_TRUE(CheckMeshArrays(*mesh).ok()) << file << ": " << CheckMeshArrays(*mesh).message();
  }
}

TEST(CheckMeshArrays, EachRuleNamesTheElement) {
  Mesh m = Quad();
  m.positions[2].y = std::nanf("");
  EXPECT_EQ(Error(m), "test.obj: vertex 2 is not finite");

  m = Quad();
  m.face_indices[3] = 4;
  EXPECT_EQ(Error(m), "test.obj: face 0: vertex index 4 out of range (4 vertices)");

  m = Quad();
  m.face_offsets = {0, 2, 4};
  EXPECT_EQ(Error(m), "test.obj: face 0: fewer than 3 vertices");

  m = Quad();
  m.face_offsets = {0, 3};
  EXPECT_EQ(Error(m), "test.obj: face offsets run from 0 to 3, not from 0 to the 4 indices");

  m = Quad();
  m.face_offsets = {0};
  EXPECT_EQ(Error(m), "test.obj: no faces");

  m = Quad();
  m.tags.creases.push_back({VertexId(0), VertexId(7), 2});
  EXPECT_EQ(Error(m), "test.obj: crease 0: vertex index 7 out of range (4 vertices)");

  m = Quad();
  m.tags.corners.push_back({VertexId(1), -1});
  EXPECT_EQ(Error(m), "test.obj: corner 0: sharpness -1 is not a finite number >= 0");

  m = Quad();
  m.tags.holes.push_back(BaseFaceId(1));
  EXPECT_EQ(Error(m), "test.obj: hole 0: face index 1 out of range (1 faces)");

  m = Quad();
  m.face_groups = {1};
  m.group_names = {"a"};
  EXPECT_EQ(Error(m), "test.obj: face 0: group 1 out of range (1 group names)");

  m = Quad();
  m.face_uv_indices = {0, 1, 2, 3};
  m.uvs = {0, 0, 1, 0, 1, 1};
  EXPECT_EQ(Error(m),
            "test.obj: face corner 3: texture index 3 out of range (3 texture coordinates)");

  m = Quad();
  m.source.clear();
  m.positions[0].x = INFINITY;
  EXPECT_EQ(Error(m), "mesh: vertex 0 is not finite");
}

// Each face's corners after the first in reverse order, texture coordinates with them; twice
// is the mesh itself.
TEST(ReverseWinding, KeepsTheFirstCornerAndReversesTheRest) {
  const Mesh original = testing::ObjOrDie(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
      "f 1/1 2/2 3/3 4/4\nf 2/2 5/5 6/1 3/3\nf 1/1 2/2 4/4\n");
  Mesh mesh = original;
  ReverseWinding(mesh);
  EXPECT_EQ(mesh.face_indices, (std::vector<std::int32_t>{0, 3, 2, 1, 1, 2, 5, 4, 0, 3, 1}));
  EXPECT_EQ(mesh.face_uv_indices, (std::vector<std::int32_t>{0, 3, 2, 1, 1, 2, 0, 4, 0, 3, 1}));
  EXPECT_EQ(mesh.face_offsets, original.face_offsets);
  EXPECT_TRUE(CheckMeshArrays(mesh).ok());
  ReverseWinding(mesh);
  EXPECT_EQ(mesh.face_indices, original.face_indices);
  EXPECT_EQ(mesh.face_uv_indices, original.face_uv_indices);
}

}  // namespace
}  // namespace dispex
