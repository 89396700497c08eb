// Shapes: splitting a mesh by its o/g groups, the shapes' file names, pairing base and sculpt
// shapes by name.
#include "dispex/shapes.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

using testing::ObjOrDie;
using testing::SameMesh;
using testing::TempPath;

// A folder of OBJ files for one test, removed at the end.
class ObjFolder {
 public:
  ObjFolder() : dir_(TempPath("_dir")) { std::filesystem::create_directories(dir_); }
  ~ObjFolder() { std::filesystem::remove_all(dir_); }

  Mesh Read(const std::string& name, const std::string& text) const {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path, std::ios::binary) << text;
    StatusOr<Mesh> mesh = ReadMesh(path);
    EXPECT_TRUE(mesh.ok()) << mesh.status().message();
    return mesh.ok() ? std::move(mesh).value() : Mesh{};
  }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
};

std::vector<MeshShape> SplitOrDie(const Mesh& mesh, bool require_disjoint) {
  StatusOr<std::vector<MeshShape>> shapes = SplitShapes(mesh, require_disjoint);
  EXPECT_TRUE(shapes.ok()) << shapes.status().message();
  return shapes.ok() ? std::move(shapes).value() : std::vector<MeshShape>{};
}

std::string SplitError(const Mesh& mesh, bool require_disjoint) {
  StatusOr<std::vector<MeshShape>> shapes = SplitShapes(mesh, require_disjoint);
  EXPECT_FALSE(shapes.ok()) << "split without error";
  return shapes.ok() ? std::string() : shapes.status().message();
}

std::vector<std::int32_t> Face(const Mesh& mesh, std::size_t f) {
  const auto face = mesh.face(f);
  return {face.begin(), face.end()};
}

// Three objects whose vertices interleave in the file; object "a" comes back after "c", and
// vertex 11 belongs to none.
const char kThreeObjects[] =
    "v 0 0 0\n"  // 1 a
    "v 1 0 0\n"  // 2 a
    "v 5 0 0\n"  // 3 b
    "v 1 1 0\n"  // 4 a
    "v 6 0 0\n"  // 5 b
    "v 6 1 0\n"  // 6 b
    "v 0 1 0\n"  // 7 a
    "v 9 9 9\n"  // 8 c
    "v 9 8 9\n"  // 9 c
    "v 8 9 9\n"  // 10 c
    "v 7 7 7\n"  // 11 unused
    "o a\nf 1 2 4 7\n"
    "o b\nf 6 3 5\n"
    "o c\nf 8 9 10\nf 10 9 8\n"
    "o a\nf 7 4 2\n";

TEST(SplitShapes, ThreeObjectsEqualSeparateFiles) {
  const ObjFolder folder;
  const Mesh mesh = folder.Read("asset.obj", kThreeObjects);
  const std::vector<MeshShape> shapes = SplitOrDie(mesh, /*require_disjoint=*/true);
  ASSERT_EQ(shapes.size(), 3u);

  const Mesh a = folder.Read("a.obj",
                             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                             "f 1 2 3 4\nf 4 3 2\n");
  const Mesh b = folder.Read("b.obj", "v 5 0 0\nv 6 0 0\nv 6 1 0\nf 3 1 2\n");
  const Mesh c = folder.Read("c.obj", "v 9 9 9\nv 9 8 9\nv 8 9 9\nf 1 2 3\nf 3 2 1\n");
  EXPECT_EQ(shapes[0].name, "a");
  EXPECT_EQ(shapes[1].name, "b");
  EXPECT_EQ(shapes[2].name, "c");
  EXPECT_TRUE(SameMesh(shapes[0].mesh, a));
  EXPECT_TRUE(SameMesh(shapes[1].mesh, b));
  EXPECT_TRUE(SameMesh(shapes[2].mesh, c));
  // Spelled out for one shape, in case the reader and the split agree on a mistake.
  EXPECT_EQ(shapes[0].mesh.face_offsets, (std::vector<std::uint32_t>{0, 4, 7}));
  EXPECT_EQ(shapes[0].mesh.face_indices, (std::vector<std::int32_t>{0, 1, 2, 3, 3, 2, 1}));
  ASSERT_EQ(shapes[0].mesh.positions.size(), 4u);
  EXPECT_EQ(shapes[0].mesh.positions[3].y, 1.0f);

  const std::string path = folder.dir() + "/asset.obj";
  for (const MeshShape& shape : shapes) {
    EXPECT_EQ(shape.file_name, shape.name);
    EXPECT_EQ(shape.mesh.source, path + " shape '" + shape.name + "'");
    EXPECT_GT(shape.mesh.positions.capacity(), shape.mesh.positions.size());
    EXPECT_TRUE(shape.mesh.face_groups.empty());
    EXPECT_TRUE(shape.mesh.group_names.empty());
  }
  // Sculpt mode gives the same shapes when nothing is shared.
  const std::vector<MeshShape> sculpt = SplitOrDie(mesh, /*require_disjoint=*/false);
  ASSERT_EQ(sculpt.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_TRUE(SameMesh(sculpt[i].mesh, shapes[i].mesh));
}

// Two strips of two quads whose vertices interleave: "left" owns the odd vertices (1-based),
// "right" the even ones. Tag ids are 0-based.
const char kTwoStrips[] =
    "v 0 0 0\nv 10 0 0\nv 1 0 0\nv 11 0 0\nv 2 0 0\nv 12 0 0\n"
    "v 0 1 0\nv 10 1 0\nv 1 1 0\nv 11 1 0\nv 2 1 0\nv 12 1 0\n"
    "g left\nf 1 3 9 7\n"
    "g right\nf 2 4 10 8\n"
    "g left\nf 3 5 11 9\n"
    "g right\nf 4 6 12 10\n"
    "t crease 2/1/0 2 8 3.0\n"  // left: local 1 4
    "t crease 2/1/0 3 9 2.0\n"  // right: local 1 4
    "t corner 1/1/0 5 1.5\n"    // right: local 2
    "t corner 1/1/0 10 2.5\n"   // left: local 5
    "t hole 2/0/0 3 0\n"        // right's second face, left's first
    "t interpolateboundary 1/0/0 2\n"
    "t creasemethod 0/0/1 chaikin\n"
    "t facevaryinginterpolateboundary 1/0/0 1\n";
const char kStripSettings[] =
    "t interpolateboundary 1/0/0 2\n"
    "t creasemethod 0/0/1 chaikin\n"
    "t facevaryinginterpolateboundary 1/0/0 1\n";

TEST(SplitShapes, TagsRenumberedLikeSeparateFiles) {
  const ObjFolder folder;
  const Mesh mesh = folder.Read("strips.obj", kTwoStrips);
  const std::vector<MeshShape> shapes = SplitOrDie(mesh, /*require_disjoint=*/true);
  ASSERT_EQ(shapes.size(), 2u);
  const Mesh left =
      folder.Read("left.obj", std::string("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
                                          "f 1 2 5 4\nf 2 3 6 5\n"
                                          "t crease 2/1/0 1 4 3.0\n"
                                          "t corner 1/1/0 5 2.5\n"
                                          "t hole 1/0/0 0\n") +
                                  kStripSettings);
  const Mesh right = folder.Read("right.obj", std::string("v 10 0 0\nv 11 0 0\nv 12 0 0\n"
                                                          "v 10 1 0\nv 11 1 0\nv 12 1 0\n"
                                                          "f 1 2 5 4\nf 2 3 6 5\n"
                                                          "t crease 2/1/0 1 4 2.0\n"
                                                          "t corner 1/1/0 2 1.5\n"
                                                          "t hole 1/0/0 1\n") +
                                                  kStripSettings);
  EXPECT_EQ(shapes[0].name, "left");
  EXPECT_EQ(shapes[1].name, "right");
  EXPECT_TRUE(SameMesh(shapes[0].mesh, left));
  EXPECT_TRUE(SameMesh(shapes[1].mesh, right));
  const SubdivTags& tags = shapes[1].mesh.tags;
  ASSERT_EQ(tags.creases.size(), 1u);
  EXPECT_EQ(tags.creases[0].v0.value, 1);
  EXPECT_EQ(tags.creases[0].v1.value, 4);
  ASSERT_EQ(tags.corners.size(), 1u);
  EXPECT_EQ(tags.corners[0].vertex.value, 2);
  ASSERT_EQ(tags.holes.size(), 1u);
  EXPECT_EQ(tags.holes[0].value, 1);
  EXPECT_EQ(tags.boundary, BoundaryInterpolation::kEdgeOnly);
  EXPECT_TRUE(tags.boundary_from_file);
  EXPECT_EQ(tags.crease_method, CreaseMethod::kChaikin);
  EXPECT_EQ(tags.ignored_tag_names, std::vector<std::string>{"facevaryinginterpolateboundary"});
}

TEST(SplitShapes, CreaseBetweenShapes) {
  // Vertex 0 (0-based) is left's, vertex 1 right's.
  const Mesh mesh = ObjOrDie(std::string(kTwoStrips) + "t crease 2/1/0 0 1 4.0\n");
  EXPECT_EQ(SplitError(mesh, /*require_disjoint=*/true),
            "test.obj: a crease joins vertex 1 of shape 'left' and vertex 2 of shape 'right'; a "
            "crease must lie within one shape");
  const std::vector<MeshShape> shapes = SplitOrDie(mesh, /*require_disjoint=*/false);
  ASSERT_EQ(shapes.size(), 2u);
  EXPECT_EQ(shapes[0].mesh.tags.creases.size(), 1u);  // dropped, not in either
  EXPECT_EQ(shapes[1].mesh.tags.creases.size(), 1u);
}

// Shapes a, b, c: c shares vertex 3 with a and vertex 6 with b.
const char kSharing[] =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 2 0 0\nv 3 0 0\nv 3 1 0\nv 2 2 0\n"
    "o a\nf 1 2 3\n"
    "o b\nf 4 5 6\n"
    "o c\nf 6 7 3\n";

TEST(SplitShapes, SharedVertexIsAnErrorForBaseCages) {
  StatusOr<Mesh> mesh = ParseObj(kSharing, "base.obj");
  ASSERT_TRUE(mesh.ok());
  EXPECT_EQ(SplitError(*mesh, /*require_disjoint=*/true),
            "base.obj: shapes 'a' and 'c' share vertex 3; a shape's faces must not share "
            "vertices with another shape's (give the whole surface one o/g name)");
  // Only b and c share, at vertex 6: the 1-based id of the file.
  StatusOr<Mesh> later = ParseObj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 2 0 0\nv 3 0 0\nv 3 1 0\nv 2 2 0\n"
      "o a\nf 1 2 3\no b\nf 4 5 6\no c\nf 6 7 5\n",
      "base.obj");
  ASSERT_TRUE(later.ok());
  EXPECT_EQ(SplitError(*later, /*require_disjoint=*/true),
            "base.obj: shapes 'b' and 'c' share vertex 5; a shape's faces must not share "
            "vertices with another shape's (give the whole surface one o/g name)");
}

TEST(SplitShapes, SculptsCopySharedVertices) {
  const Mesh mesh = ObjOrDie(kSharing);
  const std::vector<MeshShape> shapes = SplitOrDie(mesh, /*require_disjoint=*/false);
  ASSERT_EQ(shapes.size(), 3u);
  EXPECT_TRUE(SameMesh(shapes[0].mesh, ObjOrDie("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")));
  EXPECT_TRUE(SameMesh(shapes[1].mesh, ObjOrDie("v 2 0 0\nv 3 0 0\nv 3 1 0\nf 1 2 3\n")));
  // c: vertices 3, 6, 7 of the file.
  EXPECT_TRUE(SameMesh(shapes[2].mesh, ObjOrDie("v 1 1 0\nv 3 1 0\nv 2 2 0\nf 2 3 1\n")));
  EXPECT_EQ(Face(shapes[2].mesh, 0), (std::vector<std::int32_t>{1, 2, 0}));
}

TEST(SplitShapes, SculptTagsAtSharedVerticesGoToEveryShape) {
  // a and b share the edge 1-3 (0-based 0 2).
  const Mesh mesh = ObjOrDie(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "g a\nf 1 2 3\ng b\nf 1 3 4\n"
      "t crease 2/1/0 0 2 5.0\n"  // in both
      "t crease 2/1/0 1 3 1.0\n"  // vertex 1 only in a, 3 only in b: dropped
      "t corner 1/1/0 2 0.5\n");  // in both
  const std::vector<MeshShape> shapes = SplitOrDie(mesh, /*require_disjoint=*/false);
  ASSERT_EQ(shapes.size(), 2u);
  EXPECT_TRUE(SameMesh(shapes[0].mesh, ObjOrDie("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n"
                                                "t crease 2/1/0 0 2 5.0\n"
                                                "t corner 1/1/0 2 0.5\n")));
  EXPECT_TRUE(SameMesh(shapes[1].mesh, ObjOrDie("v 0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\n"
                                                "t crease 2/1/0 0 1 5.0\n"
                                                "t corner 1/1/0 1 0.5\n")));
  EXPECT_EQ(SplitError(mesh, /*require_disjoint=*/true),
            "test.obj: shapes 'a' and 'b' share vertex 1; a shape's faces must not share "
            "vertices with another shape's (give the whole surface one o/g name)");
}

TEST(SplitShapes, NoGroupsIsOneShapeNamedAfterTheFile) {
  StatusOr<Mesh> mesh = ParseObj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 5 5 5\nf 1 2 3\n"
      "t corner 1/1/0 3 1.0\n",
      "/a/b/bunny.obj");
  ASSERT_TRUE(mesh.ok());
  const std::vector<MeshShape> shapes = SplitOrDie(*mesh, /*require_disjoint=*/true);
  ASSERT_EQ(shapes.size(), 1u);
  EXPECT_EQ(shapes[0].name, "bunny");
  EXPECT_EQ(shapes[0].file_name, "bunny");
  EXPECT_EQ(shapes[0].mesh.source, "/a/b/bunny.obj");
  EXPECT_TRUE(SameMesh(shapes[0].mesh, *mesh));  // the unused vertex 4 stays
  EXPECT_GT(shapes[0].mesh.positions.capacity(), shapes[0].mesh.positions.size());

  StatusOr<Mesh> odd = ParseObj("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n", "/a/my bunny.v2.obj");
  ASSERT_TRUE(odd.ok());
  const std::vector<MeshShape> odd_shapes = SplitOrDie(*odd, /*require_disjoint=*/false);
  ASSERT_EQ(odd_shapes.size(), 1u);
  EXPECT_EQ(odd_shapes[0].name, "my bunny.v2");
  EXPECT_EQ(odd_shapes[0].file_name, "my_bunny.v2-d55eb262");
}

TEST(SplitShapes, OneGroupIsTheWholeMesh) {
  const Mesh mesh = ObjOrDie("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 5 5 5\ng head\nf 1 2 3\nf 3 2 1\n");
  const std::vector<MeshShape> shapes = SplitOrDie(mesh, /*require_disjoint=*/true);
  ASSERT_EQ(shapes.size(), 1u);
  EXPECT_EQ(shapes[0].name, "head");
  EXPECT_EQ(shapes[0].mesh.source, "test.obj");
  EXPECT_TRUE(shapes[0].mesh.face_groups.empty());
  EXPECT_TRUE(shapes[0].mesh.group_names.empty());
  EXPECT_EQ(shapes[0].mesh.positions.size(), 4u);
  EXPECT_EQ(shapes[0].mesh.face_indices, mesh.face_indices);
}

TEST(SplitShapes, FacesBeforeTheFirstGroupAreDefault) {
  const Mesh mesh = ObjOrDie(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 4 0 0\nv 5 0 0\nv 5 1 0\n"
      "f 4 5 6\ng body\nf 1 2 3\n");
  const std::vector<MeshShape> shapes = SplitOrDie(mesh, /*require_disjoint=*/true);
  ASSERT_EQ(shapes.size(), 2u);
  EXPECT_EQ(shapes[0].name, "default");
  EXPECT_EQ(shapes[0].mesh.source, "test.obj shape 'default'");
  EXPECT_EQ(shapes[1].name, "body");
  EXPECT_TRUE(SameMesh(shapes[0].mesh, ObjOrDie("v 4 0 0\nv 5 0 0\nv 5 1 0\nf 1 2 3\n")));
  EXPECT_TRUE(SameMesh(shapes[1].mesh, ObjOrDie("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")));
}

TEST(SplitShapes, UvsCompacted) {
  const ObjFolder folder;
  // UV 2 (1-based) is used by both shapes: copied into each, also for base cages.
  const Mesh mesh = folder.Read("uv.obj",
                                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 5 0 0\nv 6 0 0\nv 6 1 0\n"
                                "vt 0.5 0.5\nvt 0.25 0\nvt 0.75 1\nvt 0 1\nvt 1 1\n"
                                "o a\nf 1/3 2/2 3/3\n"
                                "o b\nf 4/5 5/2 6/1\n");
  ASSERT_TRUE(mesh.has_uvs());
  const std::vector<MeshShape> shapes = SplitOrDie(mesh, /*require_disjoint=*/true);
  ASSERT_EQ(shapes.size(), 2u);
  EXPECT_TRUE(SameMesh(shapes[0].mesh, folder.Read("a.obj",
                                                   "v 0 0 0\nv 1 0 0\nv 1 1 0\n"
                                                   "vt 0.25 0\nvt 0.75 1\n"
                                                   "f 1/2 2/1 3/2\n")));
  EXPECT_TRUE(SameMesh(shapes[1].mesh, folder.Read("b.obj",
                                                   "v 5 0 0\nv 6 0 0\nv 6 1 0\n"
                                                   "vt 0.5 0.5\nvt 0.25 0\nvt 1 1\n"
                                                   "f 1/3 2/2 3/1\n")));
  EXPECT_EQ(shapes[1].mesh.uvs, (std::vector<float>{0.5f, 0.5f, 0.25f, 0, 1, 1}));
  EXPECT_EQ(shapes[1].mesh.face_uv_indices, (std::vector<std::int32_t>{2, 1, 0}));

  // Without UVs on some faces the parent has none, and every shape carries its count.
  const Mesh partial = ObjOrDie(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 5 0 0\nv 6 0 0\nv 6 1 0\nvt 0 0\n"
      "o a\nf 1/1 2/1 3/1\no b\nf 4 5 6\n");
  const std::vector<MeshShape> partial_shapes = SplitOrDie(partial, /*require_disjoint=*/true);
  ASSERT_EQ(partial_shapes.size(), 2u);
  for (const MeshShape& shape : partial_shapes) {
    EXPECT_FALSE(shape.mesh.has_uvs());
    EXPECT_EQ(shape.mesh.faces_without_uvs, 1u);
  }
}

TEST(SplitShapes, BadGroupsAreErrors) {
  const Mesh good = ObjOrDie(kThreeObjects);
  Mesh short_groups = good;
  short_groups.face_groups.pop_back();
  EXPECT_EQ(SplitError(short_groups, false), "test.obj: 4 face group ids for 5 faces");
  Mesh bad_id = good;
  bad_id.face_groups[3] = 3;
  EXPECT_EQ(SplitError(bad_id, false), "test.obj: face 4 has group id 3 (3 groups)");
  bad_id.face_groups[3] = -1;
  EXPECT_EQ(SplitError(bad_id, false), "test.obj: face 4 has group id -1 (3 groups)");
  Mesh no_names = good;
  no_names.group_names.clear();
  EXPECT_EQ(SplitError(no_names, false), "test.obj: 0 group names for grouped faces");
  Mesh same_names = good;
  same_names.group_names[2] = "a";
  EXPECT_EQ(SplitError(same_names, false), "test.obj: two groups named 'a'");
  Mesh empty_group = good;
  empty_group.group_names.push_back("cape");
  EXPECT_EQ(SplitError(empty_group, false), "test.obj: group 'cape' has no faces");
  // Indices a reader would have refused.
  Mesh bad_vertex = good;
  bad_vertex.face_indices[5] = 11;
  EXPECT_EQ(SplitError(bad_vertex, false), "test.obj: face 2 uses vertex 12 (11 in the mesh)");
  Mesh bad_hole = good;
  bad_hole.tags.holes.push_back(BaseFaceId(5));
  EXPECT_EQ(SplitError(bad_hole, false), "test.obj: hole tag face 5 out of range (5 faces)");
}

std::vector<MeshShape> Named(const std::vector<std::string>& names) {
  std::vector<MeshShape> shapes(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) shapes[i].name = names[i];
  return shapes;
}

std::vector<std::string> FileNames(const std::vector<std::string>& names) {
  return ShapeFileNames(names);
}

TEST(ShapeFileNames, SafeNamesUnchanged) {
  EXPECT_EQ(FileNames({"head", "Body.001", "left-arm_2", "x"}),
            (std::vector<std::string>{"head", "Body.001", "left-arm_2", "x"}));
  EXPECT_TRUE(FileNames({}).empty());
}

TEST(ShapeFileNames, UnsafeNamesGetTheirCrc) {
  EXPECT_EQ(FileNames({"a/b", "a_b"}), (std::vector<std::string>{"a_b-07f4401c", "a_b"}));
  EXPECT_EQ(FileNames({""}), std::vector<std::string>{"shape-00000000"});
  EXPECT_EQ(FileNames({".hidden"}), std::vector<std::string>{"_hidden-3b71d5a1"});
  EXPECT_EQ(FileNames({"t\xc3\xaate"}), std::vector<std::string>{"t__te-0cec0169"});
  EXPECT_EQ(FileNames({std::string(150, 'x')}),
            std::vector<std::string>{std::string(100, 'x') + "-7096bba4"});
  EXPECT_EQ(FileNames({std::string(100, 'x')}), std::vector<std::string>{std::string(100, 'x')});
}

TEST(ShapeFileNames, CaseInsensitiveCollisions) {
  EXPECT_EQ(FileNames({"Head", "head", "body"}),
            (std::vector<std::string>{"Head-07c159a2", "head-a7f3f69c", "body"}));
  // A safe name equal to another's suffixed name gets its own suffix.
  EXPECT_EQ(FileNames({"a/b", "A_B-07f4401c"}),
            (std::vector<std::string>{"a_b-07f4401c", "A_B-07f4401c-f96521ed"}));
}

TEST(ShapeFileNames, SameCrcGetsNumbers) {
  EXPECT_EQ(FileNames({"a/b", "a/b", "a/b"}),
            (std::vector<std::string>{"a_b-07f4401c", "a_b-07f4401c-2", "a_b-07f4401c-3"}));
  EXPECT_EQ(FileNames({"x", "x"}), (std::vector<std::string>{"x-8cdc1683", "x-8cdc1683-2"}));
  // A number another name already has is skipped.
  EXPECT_EQ(FileNames({"x", "x", "x-8cdc1683-2"}),
            (std::vector<std::string>{"x-8cdc1683", "x-8cdc1683-3", "x-8cdc1683-2"}));
}

StatusOr<ShapeMatch> Match(const std::vector<std::string>& base,
                           const std::vector<std::string>& sculpt,
                           const std::vector<std::string>& selected = {}) {
  return MatchShapes(Named(base), Named(sculpt), selected, "base.obj", "sculpt.obj");
}

std::string MatchError(const std::vector<std::string>& base, const std::vector<std::string>& sculpt,
                       const std::vector<std::string>& selected = {}) {
  StatusOr<ShapeMatch> match = Match(base, sculpt, selected);
  EXPECT_FALSE(match.ok());
  return match.ok() ? std::string() : match.status().message();
}

using Indices = std::vector<std::size_t>;

TEST(MatchShapes, ByNameInBaseOrder) {
  StatusOr<ShapeMatch> all = Match({"head", "body", "cape"}, {"cape", "head", "body"});
  ASSERT_TRUE(all.ok()) << all.status().message();
  EXPECT_EQ(all->base_index, (Indices{0, 1, 2}));
  EXPECT_EQ(all->sculpt_index, (Indices{1, 2, 0}));
  EXPECT_TRUE(all->warnings.empty());
  // The selection's order does not matter.
  for (const auto& selected :
       {std::vector<std::string>{"cape", "head"}, std::vector<std::string>{"head", "cape"}}) {
    StatusOr<ShapeMatch> some = Match({"head", "body", "cape"}, {"cape", "head", "body"}, selected);
    ASSERT_TRUE(some.ok()) << some.status().message();
    EXPECT_EQ(some->base_index, (Indices{0, 2}));
    EXPECT_EQ(some->sculpt_index, (Indices{1, 0}));
    EXPECT_TRUE(some->warnings.empty());  // body is a base shape, only not selected
  }
}

TEST(MatchShapes, OneAndOnePairWhateverTheirNames) {
  StatusOr<ShapeMatch> match = Match({"bunny"}, {"bunny_sculpted"});
  ASSERT_TRUE(match.ok()) << match.status().message();
  EXPECT_EQ(match->base_index, Indices{0});
  EXPECT_EQ(match->sculpt_index, Indices{0});
  EXPECT_TRUE(match->warnings.empty());
  EXPECT_TRUE(Match({"bunny"}, {"other"}, {"bunny"}).ok());
  EXPECT_EQ(MatchError({"bunny"}, {"other"}, {"other"}),
            "selected shape 'other' is not in base.obj (its shapes: 'bunny')");
}

TEST(MatchShapes, SelectionErrors) {
  EXPECT_EQ(MatchError({"head", "body", "cape"}, {"head", "body", "cape"}, {"body", "x"}),
            "selected shape 'x' is not in base.obj (its shapes: 'head', 'body', 'cape')");
  EXPECT_EQ(MatchError({"head", "body"}, {"head", "body"}, {"Head"}),
            "selected shape 'Head' is not in base.obj (its shapes: 'head', 'body'); shape names "
            "must match exactly: 'head' differs from 'Head' only in letter case or blanks");
  EXPECT_EQ(MatchError({"head", "body"}, {"head", "body"}, {"head", "body", "head"}),
            "shape 'head' is selected twice");
}

TEST(MatchShapes, MissingSculptShape) {
  EXPECT_EQ(MatchError({"head", "belt"}, {"Belt ", "head"}),
            "sculpt.obj has no shape 'belt' (its shapes: 'Belt ', 'head'); shape names must "
            "match exactly: 'Belt ' differs from 'belt' only in letter case or blanks");
  EXPECT_EQ(MatchError({"head", "belt"}, {"head", "cape"}),
            "sculpt.obj has no shape 'belt' (its shapes: 'head', 'cape')");
  // Not selected: no error.
  EXPECT_TRUE(Match({"head", "belt"}, {"head", "cape"}, {"head"}).ok());
  // One shape against several, either way round.
  EXPECT_EQ(MatchError({"bunny"}, {"head", "body"}),
            "sculpt.obj has no shape 'bunny' (its shapes: 'head', 'body')");
  EXPECT_EQ(MatchError({"head", "body"}, {"sculpt"}),
            "sculpt.obj has no shape 'head' (its shapes: 'sculpt')");
  // The list stops after 10 names.
  std::vector<std::string> many;
  for (int i = 1; i <= 12; ++i) many.push_back(fmt::format("s{}", i));
  EXPECT_EQ(MatchError({"head", "s1"}, many),
            "sculpt.obj has no shape 'head' (its shapes: 's1', 's2', 's3', 's4', 's5', 's6', "
            "'s7', 's8', 's9', 's10', ...)");
}

TEST(MatchShapes, UnusedSculptShapesWarn) {
  StatusOr<ShapeMatch> match = Match({"head", "body"}, {"hat", "body", "head", "cane"}, {"head"});
  ASSERT_TRUE(match.ok()) << match.status().message();
  EXPECT_EQ(match->base_index, Indices{0});
  EXPECT_EQ(match->sculpt_index, Indices{2});
  EXPECT_EQ(match->warnings,
            (std::vector<std::string>{
                "sculpt.obj: shape 'hat' has no base shape of that name; not used",
                "sculpt.obj: shape 'cane' has no base shape of that name; not used"}));
}

TEST(MatchShapes, DuplicateOrNoShapes) {
  EXPECT_EQ(MatchError({"head", "head"}, {"head"}), "base.obj: two shapes named 'head'");
  EXPECT_EQ(MatchError({"head"}, {"a", "a"}), "sculpt.obj: two shapes named 'a'");
  EXPECT_EQ(MatchError({}, {"a"}), "base.obj: no shapes");
}

// A grid of 1000 x 1000 quads in bands of 20 rows (50 shapes, neighbours share a row of
// vertices), or with faces dealt round-robin (every vertex in up to 4 shapes).
Mesh Grid(bool round_robin) {
  constexpr int kSide = 1000, kShapes = 50;
  Mesh mesh;
  mesh.source = "grid.obj";
  mesh.positions.reserve((kSide + 1) * (kSide + 1) + 1);
  for (int y = 0; y <= kSide; ++y) {
    for (int x = 0; x <= kSide; ++x) {
      mesh.positions.push_back({static_cast<float>(x), static_cast<float>(y), 0});
    }
  }
  mesh.face_offsets.push_back(0);
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      const int v = y * (kSide + 1) + x;
      for (const int i : {v, v + 1, v + kSide + 2, v + kSide + 1}) mesh.face_indices.push_back(i);
      mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
      const int f = y * kSide + x;
      mesh.face_groups.push_back(round_robin ? f % kShapes : y / (kSide / kShapes));
    }
  }
  for (int g = 0; g < kShapes; ++g) mesh.group_names.push_back(fmt::format("band{}", g));
  return mesh;
}

TEST(SplitShapes, MillionFacesFiftyShapes) {
  const Mesh bands = Grid(/*round_robin=*/false);
  EXPECT_EQ(SplitError(bands, /*require_disjoint=*/true),
            "grid.obj: shapes 'band0' and 'band1' share vertex 20021; a shape's faces must not "
            "share vertices with another shape's (give the whole surface one o/g name)");
  const std::vector<MeshShape> shapes = SplitOrDie(bands, /*require_disjoint=*/false);
  ASSERT_EQ(shapes.size(), 50u);
  for (const MeshShape& shape : shapes) {
    ASSERT_EQ(shape.mesh.num_faces(), 20000u);
    ASSERT_EQ(shape.mesh.num_vertices(), 21u * 1001u);
  }
  // Band 1 starts at row 20: its first face is the file's face 20000.
  EXPECT_EQ(shapes[1].mesh.positions[0].y, 20.0f);
  EXPECT_EQ(Face(shapes[1].mesh, 0), (std::vector<std::int32_t>{0, 1, 1002, 1001}));

  const Mesh dealt = Grid(/*round_robin=*/true);
  const std::vector<MeshShape> dealt_shapes = SplitOrDie(dealt, /*require_disjoint=*/false);
  ASSERT_EQ(dealt_shapes.size(), 50u);
  std::size_t corners = 0;
  for (const MeshShape& shape : dealt_shapes) {
    ASSERT_EQ(shape.mesh.num_faces(), 20000u);
    corners += shape.mesh.face_indices.size();
  }
  EXPECT_EQ(corners, dealt.face_indices.size());
  // Shape 1 holds faces 1, 51, 101, ... of row 0 first: face 1 uses vertices 2, 3 (1-based)
  // and 1003, 1004; the shape's lowest vertex is the file's vertex 2.
  EXPECT_EQ(dealt_shapes[1].mesh.positions[0].x, 1.0f);
  EXPECT_EQ(Face(dealt_shapes[1].mesh, 0), (std::vector<std::int32_t>{0, 1, 41, 40}));
}

}  // namespace
}  // namespace dispex
