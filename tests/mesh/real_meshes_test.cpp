// Every mesh in tests/data/meshes: counts, faces by size, tags, groups, bounding box, median
// edge length and validation counts, against values computed independently of dispex:
// V/F/face sizes/tags/topology from the data set's README (see tests/data/README.md),
// bounding boxes and median edge lengths from a Python script over the file text (float()
// on each coordinate; all face sides, median of the middle two for an even count),
// validation counts from a Python edge count over the file text.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

using testing::DataPath;

struct Expected {
  const char* path;  // under tests/data/meshes/
  std::size_t vertices;
  std::size_t faces;
  std::map<int, std::size_t> face_sizes;
  Float3 min, max;
  double median_edge;
  // boundary edges, non-manifold edges, inconsistent edges, degenerate faces, unreferenced
  // vertices. catmark_nonman_edges: the README lists 11 non-manifold edges because it also
  // counts the zero-length sides (v, v) of its degenerate faces as edges; dispex does not.
  std::size_t topology[5];
  // creases, corners, hole faces, interpolateboundary value in the file (-1: none), ignored
  // tag lines
  int tags[5];
  const char* group;  // the only group name, or "" when the file has no o/g line
};

const std::vector<Expected>& Table() {
  static const std::vector<Expected> table = {
      {"dispex/chaikin_box.obj",
       56,
       54,
       {{4, 54}},
       {-1.5, -1.5, -1.5},
       {1.5, 1.5, 1.5},
       1.0,
       {0, 0, 0, 0, 0},
       {4, 0, 0, -1, 0},
       ""},
      {"jerry_the_ogre/controlmesh.obj",
       1329,
       1308,
       {{3, 92}, {4, 1114}, {5, 76}, {6, 24}, {7, 2}},
       {-0.579677, -0.666079, -0.467935},
       {0.579677, 0.548407, 0.837581},
       0.048289533644051696,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"keenan_blub/blub_control_mesh.obj",
       112,
       112,
       {{3, 8}, {4, 100}, {5, 4}},
       {-0.782132, -0.996428, -2.30803},
       {0.782132, 1.12117, 1.04},
       0.30362567929112977,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"keenan_spot/spot_control_mesh.obj",
       188,
       180,
       {{3, 4}, {4, 160}, {5, 16}},
       {-0.585967, -0.759125, -0.696223},
       {0.585967, 0.984026, 1.07776},
       0.1971283776071016,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"keenan_spot/spot_quadrangulated.obj",
       2930,
       2928,
       {{4, 2928}},
       {-0.471552, -0.736784, -0.668909},
       {0.471552, 0.953646, 1.049},
       0.04382137977048525,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"nefertiti/nefertiti_quadriflow_1000.obj",
       943,
       941,
       {{4, 941}},
       {-118.673141, -243.915802, -171.438721},
       {116.986206, 247.221634, 181.056396},
       19.42038389644883,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       "nefertiti"},
      {"opensubdiv/catmark_car.obj",
       1642,
       1575,
       {{4, 1575}},
       {-0.194142, -3.763515, -0.046434},
       {1.432553, -0.00025, 0.723681},
       0.06904702827783396,
       {60, 0, 0, 0, 0},
       {314, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_cube.obj",
       8,
       6,
       {{4, 6}},
       {-1.414214, -1.414214, -1.0},
       {1.414214, 1.414214, 1.0},
       2.0000006188979045,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_cube_corner0.obj",
       8,
       6,
       {{4, 6}},
       {-1.414214, -1.414214, -1.0},
       {1.414214, 1.414214, 1.0},
       2.0000006188979045,
       {0, 0, 0, 0, 0},
       {0, 1, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_cube_creases0.obj",
       8,
       6,
       {{4, 6}},
       {-1.414214, -1.414214, -1.0},
       {1.414214, 1.414214, 1.0},
       2.0000006188979045,
       {0, 0, 0, 0, 0},
       {2, 0, 0, 2, 0},
       ""},
      {"opensubdiv/catmark_cube_creases1.obj",
       8,
       6,
       {{4, 6}},
       {-1.414214, -1.414214, -1.0},
       {1.414214, 1.414214, 1.0},
       2.0000006188979045,
       {0, 0, 0, 0, 0},
       {12, 0, 0, 2, 0},
       ""},
      {"opensubdiv/catmark_cubes_infsharp.obj",
       32,
       24,
       {{4, 24}},
       {-1.25, -0.5, -1.25},
       {1.25, 0.5, 1.25},
       1.0,
       {0, 0, 0, 0, 0},
       {18, 1, 0, 2, 1},
       ""},
      {"opensubdiv/catmark_cubes_semisharp.obj",
       32,
       24,
       {{4, 24}},
       {-1.25, -0.5, -1.25},
       {1.25, 0.5, 1.25},
       1.0,
       {0, 0, 0, 0, 0},
       {14, 2, 0, 2, 1},
       ""},
      {"opensubdiv/catmark_edgecorner.obj",
       52,
       28,
       {{4, 28}},
       {-1.25, -0.25, -1.25},
       {1.25, 0.0, 1.25},
       0.3340000000000001,
       {40, 0, 0, 0, 0},
       {0, 0, 0, 1, 0},
       ""},
      {"opensubdiv/catmark_fan.obj",
       22,
       13,
       {{4, 13}},
       {-1.5, -0.5, -1.0},
       {1.5, 0.5, 1.0},
       0.7071067811865476,
       {20, 4, 0, 0, 0},
       {0, 0, 0, 1, 0},
       ""},
      {"opensubdiv/catmark_flap.obj",
       8,
       3,
       {{4, 3}},
       {-0.110026, 1.79114, -1.71797},
       {0.119883, 1.95726, -1.54412},
       0.1178375049370671,
       {8, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_gregory_test8.obj",
       9,
       6,
       {{4, 4}, {5, 2}},
       {-1.0, -0.5, -0.5},
       {1.0, 1.0, 1.0},
       1.0,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_helmet.obj",
       72,
       58,
       {{4, 58}},
       {-0.766045, -1.048138, -0.9164},
       {0.766044, -0.321394, 0.9164},
       0.2610523602153406,
       {26, 0, 0, 0, 0},
       {38, 0, 0, 1, 0},
       ""},
      {"opensubdiv/catmark_hole_test1.obj",
       8,
       6,
       {{4, 6}},
       {-1.414214, -1.414214, -1.0},
       {1.414214, 1.414214, 1.0},
       2.0000006188979045,
       {0, 0, 0, 0, 0},
       {0, 0, 1, -1, 0},
       ""},
      {"opensubdiv/catmark_hole_test2.obj",
       25,
       16,
       {{4, 16}},
       {-1.0, -0.5, -1.0},
       {1.0, -0.0, 1.0},
       0.5,
       {16, 0, 0, 0, 0},
       {1, 0, 4, 1, 0},
       ""},
      {"opensubdiv/catmark_lefthanded.obj",
       436,
       434,
       {{4, 434}},
       {-0.337421, -0.21025, -0.012886},
       {0.344042, 0.190106, 0.016472},
       0.030886863596740994,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       "bottomPanel panels AC_A Geom AirConditioner"},
      {"opensubdiv/catmark_nonman_edges.obj",
       142,
       85,
       {{3, 1}, {4, 84}},
       {-1.75, -0.6, -1.75},
       {1.75, 0.5, 1.75},
       0.34,
       {122, 9, 6, 14, 0},
       {0, 0, 0, 1, 0},
       ""},
      {"opensubdiv/catmark_nonman_verts.obj",
       49,
       20,
       {{3, 1}, {4, 19}},
       {-1.25, -0.5, -1.25},
       {1.25, 0.5, 1.25},
       0.5,
       {49, 0, 0, 0, 1},
       {0, 0, 0, 1, 0},
       ""},
      {"opensubdiv/catmark_nonquads.obj",
       33,
       17,
       {{3, 7}, {4, 7}, {5, 1}, {6, 2}},
       {-1.25, -0.5, -1.35},
       {1.25, 0.15, 1.25},
       0.25000000000000006,
       {26, 0, 0, 0, 0},
       {0, 0, 0, 1, 0},
       ""},
      {"opensubdiv/catmark_pawn.obj",
       601,
       588,
       {{4, 588}},
       {1.593519, -1.428143, 0.025851},
       {1.900038, -1.121624, 0.524901},
       0.02625351850704957,
       {24, 0, 0, 0, 0},
       {120, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_pole64.obj",
       129,
       128,
       {{3, 64}, {4, 64}},
       {-0.7849, -1.0, -0.7849},
       {0.7849, -0.7836, 0.7849},
       0.2616082949755225,
       {64, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_pole8.obj",
       17,
       16,
       {{3, 8}, {4, 8}},
       {-0.8684, -1.0, -0.8684},
       {0.8684, -0.7836, 0.8684},
       0.2895,
       {8, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_pyramid.obj",
       5,
       5,
       {{3, 4}, {4, 1}},
       {-2.0, -2.0, 0.0},
       {2.0, 2.0, 2.0},
       2.8284271247461903,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_single_crease.obj",
       105,
       80,
       {{4, 80}},
       {-2.0, -0.5, -0.5},
       {2.0, -0.0, 0.5},
       0.3366775981349759,
       {48, 0, 0, 0, 0},
       {36, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_smoothtris0.obj",
       42,
       80,
       {{3, 80}},
       {-1.0, -1.0, -1.0},
       {1.0, 1.0, 1.0},
       1.0000002220212008,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},  // smoothtriangles is understood (catmark)
       ""},
      {"opensubdiv/catmark_tent.obj",
       16,
       9,
       {{4, 9}},
       {-1.697056, -1.697056, 0.0},
       {1.697056, 1.697056, 0.8},
       0.800000106138118,
       {12, 0, 0, 0, 0},
       {0, 0, 0, 2, 0},
       ""},
      {"opensubdiv/catmark_torus.obj",
       32,
       32,
       {{4, 32}},
       {-1.25052, -0.353553, -1.25052},
       {1.25052, 0.353553, 1.25052},
       0.7071061581548241,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_torus_creases0.obj",
       32,
       32,
       {{4, 32}},
       {-1.25052, -0.353553, -1.25052},
       {1.25052, 0.353553, 1.25052},
       0.7071061581548241,
       {0, 0, 0, 0, 0},
       {8, 0, 0, -1, 0},
       ""},
      {"opensubdiv/catmark_val2_interior.obj",
       103,
       56,
       {{4, 50}, {5, 4}, {6, 2}},
       {-1.75, -1.0, -1.75},
       {1.75, 0.5, 1.75},
       0.5,
       {66, 0, 0, 0, 0},
       {7, 0, 0, 1, 0},
       ""},
      {"opensubdiv/catmark_xord_boundary.obj",
       44,
       18,
       {{4, 18}},
       {-1.320634, -0.48, -0.75},
       {1.329556, 0.0, 1.35},
       0.5036948587494604,
       {44, 0, 0, 0, 0},
       {0, 0, 0, 1, 0},
       ""},
      {"opensubdiv/catmark_xord_interior.obj",
       151,
       71,
       {{4, 71}},
       {-1.85, -0.48, -1.85},
       {1.829556, 0.0, 1.85},
       0.5428271498132486,
       {142, 0, 0, 0, 0},
       {0, 0, 0, 1, 0},
       ""},
      {"stanford_bunny/bun_zipper_quadriflow_1000.obj",
       1034,
       1032,
       {{4, 1032}},
       {-0.09427, 0.033235, -0.06094},
       {0.060774, 0.185558, 0.058149},
       0.007485395511163621,
       {0, 0, 0, 0, 0},
       {0, 0, 0, -1, 0},
       "bun_zipper"},
      {"stanford_bunny/bun_zipper.ply",
       35947,
       69451,
       {{3, 69451}},
       {-0.0946899, 0.0329874, -0.0618736},
       {0.0610091, 0.187321, 0.0587997},
       0.0014670207735407127,
       {223, 0, 0, 0, 1113},
       {0, 0, 0, -1, 0},
       ""},
  };
  return table;
}

class RealMesh : public ::testing::TestWithParam<Expected> {};

TEST_P(RealMesh, MatchesIndependentCounts) {
  const Expected& e = GetParam();
  StatusOr<Mesh> read = ReadMesh(DataPath(std::string("meshes/") + e.path));
  ASSERT_TRUE(read.ok()) << read.status().message();
  const Mesh& mesh = *read;
  EXPECT_EQ(mesh.num_vertices(), e.vertices);
  EXPECT_EQ(mesh.num_faces(), e.faces);
  EXPECT_GE(mesh.positions.capacity(), mesh.positions.size() + 1);
  std::map<int, std::size_t> sizes;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) ++sizes[mesh.face_size(f)];
  EXPECT_EQ(sizes, e.face_sizes);
  // Counted without reading: the same counts, and an OBJ's corners.
  StatusOr<MeshSize> counted = CountMeshElements(DataPath(std::string("meshes/") + e.path));
  ASSERT_TRUE(counted.ok()) << counted.status().message();
  EXPECT_EQ(counted->vertices, e.vertices);
  EXPECT_EQ(counted->faces, e.faces);
  std::size_t corners = 0;
  for (const auto& [size, count] : e.face_sizes) corners += static_cast<std::size_t>(size) * count;
  const bool ply = std::string(e.path).ends_with(".ply");
  EXPECT_EQ(counted->corners_counted, !ply);
  EXPECT_EQ(counted->corners, ply ? 4 * e.faces : corners);
  ASSERT_EQ(mesh.face_offsets.front(), 0u);
  ASSERT_EQ(mesh.face_offsets.back(), mesh.face_indices.size());
  for (std::int32_t v : mesh.face_indices) {
    ASSERT_GE(v, 0);
    ASSERT_LT(static_cast<std::size_t>(v), mesh.num_vertices());
  }

  const BoundingBox box = ComputeBounds(mesh);
  auto near = [](float actual, double expected) {
    EXPECT_NEAR(actual, expected, 1e-6 * (1 + std::abs(expected)));
  };
  near(box.min.x, e.min.x);
  near(box.min.y, e.min.y);
  near(box.min.z, e.min.z);
  near(box.max.x, e.max.x);
  near(box.max.y, e.max.y);
  near(box.max.z, e.max.z);
  EXPECT_NEAR(MedianEdgeLength(mesh), e.median_edge, 1e-6 * e.median_edge);

  const MeshValidation v = ValidateMesh(mesh);
  EXPECT_EQ(v.boundary_edges, e.topology[0]);
  EXPECT_EQ(v.non_manifold_edges, e.topology[1]);
  EXPECT_EQ(v.inconsistent_edges, e.topology[2]);
  EXPECT_EQ(v.degenerate_faces, e.topology[3]);
  EXPECT_EQ(v.unreferenced_vertices, e.topology[4]);
  const std::size_t problems = (v.non_manifold_edges > 0) + (v.inconsistent_edges > 0) +
                               (v.degenerate_faces > 0) + (v.unreferenced_vertices > 0);
  EXPECT_EQ(v.warnings.size(), problems);
  EXPECT_EQ(v.clean(), problems == 0);
  EXPECT_EQ(RequireClean(mesh, v).ok(), problems == 0);

  EXPECT_EQ(mesh.tags.creases.size(), static_cast<std::size_t>(e.tags[0]));
  EXPECT_EQ(mesh.tags.corners.size(), static_cast<std::size_t>(e.tags[1]));
  EXPECT_EQ(mesh.tags.holes.size(), static_cast<std::size_t>(e.tags[2]));
  EXPECT_EQ(mesh.tags.boundary_from_file, e.tags[3] >= 0);
  const BoundaryInterpolation boundary[] = {BoundaryInterpolation::kNone,
                                            BoundaryInterpolation::kEdgeAndCorner,
                                            BoundaryInterpolation::kEdgeOnly};
  EXPECT_EQ(mesh.tags.boundary,
            e.tags[3] < 0 ? BoundaryInterpolation::kEdgeAndCorner : boundary[e.tags[3]]);
  EXPECT_EQ(static_cast<int>(mesh.tags.ignored_tag_names.size()), e.tags[4]);

  if (std::string(e.group).empty()) {
    EXPECT_TRUE(mesh.group_names.empty());
    EXPECT_TRUE(mesh.face_groups.empty());
  } else {
    ASSERT_EQ(mesh.group_names, std::vector<std::string>{e.group});
    EXPECT_EQ(mesh.face_groups, std::vector<std::int32_t>(mesh.num_faces(), 0));
  }
}

INSTANTIATE_TEST_SUITE_P(Data, RealMesh, ::testing::ValuesIn(Table()),
                         [](const ::testing::TestParamInfo<Expected>& param) {
                           std::string name = std::filesystem::path(param.param.path).stem();
                           if (std::string(param.param.path).ends_with(".ply")) name += "_ply";
                           std::replace_if(
                               name.begin(), name.end(), [](char c) { return !std::isalnum(c); },
                               '_');
                           return name;
                         });

// Every mesh file in the data folder has a row above.
// An OBJ of several of CountMeshElements' 4 MiB chunks, lines cut anywhere by them, with the
// lines its count must tell apart: indented, CRLF, vt/vn, comments, faces of 3 to 5 corners.
TEST(RealMeshes, CountsAnObjAcrossChunks) {
  const std::string path = testing::TempPath(".obj");
  std::size_t vertices = 0, faces = 0, corners = 0;
  {
    std::ofstream out(path, std::ios::binary);
    for (int i = 0; i < 400000; ++i) {
      out << (i % 7 == 0 ? "  v " : "v ") << i << ".5 0.25 -1" << (i % 5 == 0 ? "\r\n" : "\n");
      ++vertices;
      if (i % 3 == 0) out << "vt 0.5 0.5\nvn 0 0 1\n# v 1 2 3\n";
      if (i >= 5) {
        const int n = 3 + i % 3;
        out << (i % 4 == 0 ? "\tf" : "f");
        for (int k = 0; k < n; ++k) out << ' ' << (i - k) << "/1/1";
        out << (i % 6 == 0 ? " \r\n" : "\n");
        ++faces;
        corners += static_cast<std::size_t>(n);
      }
    }
  }
  ASSERT_GT(std::filesystem::file_size(path), std::size_t{12} << 20);
  StatusOr<MeshSize> counted = CountMeshElements(path);
  ASSERT_TRUE(counted.ok()) << counted.status().message();
  EXPECT_EQ(counted->vertices, vertices);
  EXPECT_EQ(counted->faces, faces);
  EXPECT_EQ(counted->corners, corners);
  StatusOr<Mesh> read = ReadMesh(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->num_vertices(), vertices);
  EXPECT_EQ(read->face_indices.size(), corners);
  std::filesystem::remove(path);
  EXPECT_NE(CountMeshElements(path).status().message().find(path), std::string::npos);
}

TEST(RealMeshes, TableCoversTheDataFolder) {
  std::vector<std::string> files;
  const std::string root = DataPath("meshes");
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    const std::string ext = entry.path().extension();
    if (ext == ".obj" || ext == ".ply") {
      files.push_back(std::filesystem::relative(entry.path(), root).string());
    }
  }
  std::vector<std::string> listed;
  for (const Expected& e : Table()) listed.push_back(e.path);
  std::sort(files.begin(), files.end());
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(files, listed);
}

// Tag values, checked line by line against the files' `t` lines.
TEST(RealMeshes, TagValues) {
  StatusOr<Mesh> creases = ReadObj(DataPath("meshes/opensubdiv/catmark_cube_creases0.obj"));
  ASSERT_TRUE(creases.ok()) << creases.status().message();
  ASSERT_EQ(creases->tags.creases.size(), 2u);
  EXPECT_EQ(creases->tags.creases[0].v0.value, 0);
  EXPECT_EQ(creases->tags.creases[0].v1.value, 1);
  EXPECT_EQ(creases->tags.creases[0].sharpness, 2.0f);
  EXPECT_EQ(creases->tags.creases[1].v0.value, 1);
  EXPECT_EQ(creases->tags.creases[1].v1.value, 3);
  EXPECT_EQ(creases->tags.boundary, BoundaryInterpolation::kEdgeOnly);

  StatusOr<Mesh> corner = ReadObj(DataPath("meshes/opensubdiv/catmark_cube_corner0.obj"));
  ASSERT_TRUE(corner.ok()) << corner.status().message();
  ASSERT_EQ(corner->tags.corners.size(), 1u);
  EXPECT_EQ(corner->tags.corners[0].vertex.value, 0);
  EXPECT_EQ(corner->tags.corners[0].sharpness, 0.7f);

  StatusOr<Mesh> holes = ReadObj(DataPath("meshes/opensubdiv/catmark_hole_test2.obj"));
  ASSERT_TRUE(holes.ok()) << holes.status().message();
  std::vector<std::int32_t> hole_ids;
  for (BaseFaceId f : holes->tags.holes) hole_ids.push_back(f.value);
  EXPECT_EQ(hole_ids, (std::vector<std::int32_t>{5, 6, 9, 10}));
  ASSERT_EQ(holes->tags.creases.size(), 1u);
  EXPECT_EQ(holes->tags.creases[0].v0.value, 6);
  EXPECT_EQ(holes->tags.creases[0].v1.value, 7);
  EXPECT_EQ(holes->tags.creases[0].sharpness, 7.5f);
  EXPECT_EQ(holes->tags.boundary, BoundaryInterpolation::kEdgeAndCorner);

  StatusOr<Mesh> semisharp = ReadObj(DataPath("meshes/opensubdiv/catmark_cubes_semisharp.obj"));
  ASSERT_TRUE(semisharp.ok()) << semisharp.status().message();
  ASSERT_EQ(semisharp->tags.corners.size(), 2u);
  EXPECT_EQ(semisharp->tags.corners[1].vertex.value, 16);
  EXPECT_EQ(semisharp->tags.corners[1].sharpness, 3.0f);
  EXPECT_EQ(semisharp->tags.creases[2].sharpness, 0.1f);  // t crease 2/1/0 24 25 0.1
  EXPECT_EQ(semisharp->tags.ignored_tag_names,
            std::vector<std::string>{"facevaryinginterpolateboundary"});

  StatusOr<Mesh> tris = ReadObj(DataPath("meshes/opensubdiv/catmark_smoothtris0.obj"));
  ASSERT_TRUE(tris.ok()) << tris.status().message();
  EXPECT_EQ(tris->tags.triangles, TriangleSubdivision::kCatmark);  // 0/0/1 catmark
  EXPECT_TRUE(tris->tags.triangles_from_file);

  StatusOr<Mesh> chaikin = ReadObj(DataPath("meshes/dispex/chaikin_box.obj"));
  ASSERT_TRUE(chaikin.ok()) << chaikin.status().message();
  EXPECT_EQ(chaikin->tags.crease_method, CreaseMethod::kChaikin);
  ASSERT_EQ(chaikin->tags.creases.size(), 4u);
  EXPECT_EQ(chaikin->tags.creases[3].sharpness, 3.0f);  // t crease 2/1/0 23 21 3
}

// The ogre cage writes `f v/vt/vn` with no `vn` lines: the dangling normal indices are ignored.
TEST(RealMeshes, OgreFaceCornersAreVertexIndices) {
  StatusOr<Mesh> ogre = ReadObj(DataPath("meshes/jerry_the_ogre/controlmesh.obj"));
  ASSERT_TRUE(ogre.ok()) << ogre.status().message();
  // First face line: "f 80/152/80 211/361/211 192/342/192 214/366/214".
  const auto face = ogre->face(0);
  EXPECT_EQ(std::vector<std::int32_t>(face.begin(), face.end()),
            (std::vector<std::int32_t>{79, 210, 191, 213}));
}

// UVs of every OBJ in tests/data/meshes against a naive line-by-line parse written here
// (std::strtof on each vt value, the second field of each face corner; these files have no
// continuation lines): the same values bit for bit, the same index per corner, and UVs present
// exactly when every face has them. 32 of the 36 files have UVs on every face; catmark_pole8,
// catmark_pole64 and the two QuadriFlow cages have no vt at all.
TEST(RealMeshes, UvsMatchANaiveParse) {
  const std::string root = DataPath("meshes");
  int with_uvs = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    if (entry.path().extension() != ".obj") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    std::ifstream in(path, std::ios::binary);
    std::vector<float> uvs;
    std::vector<std::int32_t> indices;
    std::size_t faces = 0, textured_faces = 0;
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      ASSERT_TRUE(line.empty() || line.back() != '\\') << "continuation lines: not naive";
      std::istringstream tokens(line);
      std::string keyword;
      tokens >> keyword;
      if (keyword == "vt") {
        std::string u, v;
        tokens >> u >> v;
        uvs.push_back(std::strtof(u.c_str(), nullptr));
        uvs.push_back(v.empty() ? 0.0f : std::strtof(v.c_str(), nullptr));
      } else if (keyword == "f") {
        ++faces;
        std::vector<std::int32_t> face;
        std::string corner;
        while (tokens >> corner) {
          const std::size_t slash = corner.find('/');
          if (slash == std::string::npos || slash + 1 >= corner.size() ||
              corner[slash + 1] == '/') {
            face.clear();
            break;
          }
          const long t = std::strtol(corner.c_str() + slash + 1, nullptr, 10);
          face.push_back(
              static_cast<std::int32_t>(t > 0 ? t - 1 : static_cast<long>(uvs.size() / 2) + t));
        }
        if (!face.empty()) ++textured_faces;
        indices.insert(indices.end(), face.begin(), face.end());
      }
    }
    StatusOr<Mesh> mesh = ReadObj(path);
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    if (textured_faces == faces) {
      ++with_uvs;
      ASSERT_TRUE(mesh->has_uvs());
      EXPECT_EQ(mesh->uvs, uvs);
      EXPECT_EQ(mesh->face_uv_indices, indices);
    } else {
      EXPECT_FALSE(mesh->has_uvs());
      EXPECT_EQ(mesh->faces_without_uvs, textured_faces == 0 ? 0 : faces - textured_faces);
    }
  }
  EXPECT_EQ(with_uvs, 32);
}

}  // namespace
}  // namespace dispex
