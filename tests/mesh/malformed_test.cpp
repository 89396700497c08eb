// Broken inputs: every file in tests/data/malformed/ must give a Status whose message starts
// with the file name, is one line, and says what is wrong (the fragment in the table). Then
// random mutations of valid files: whatever the bytes, a mesh or a one-line error, never a
// crash (this suite also runs under AddressSanitizer and UndefinedBehaviorSanitizer).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

using testing::DataPath;

struct Case {
  const char* file;
  const char* fragment;  // expected in the message, after "<path>"
};

const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {
      {"not_a_mesh.stl", ": unknown mesh format"},
      {"obj_bad_face_token.obj", ":4: bad face vertex 'x'"},
      {"obj_bad_number.obj", ":1: bad vertex coordinate 'abc'"},
      {"obj_bad_texture_index.obj", ":4: bad face vertex '1/a'"},
      {"obj_crlf_error_line.obj", ":6: face index 9 out of range (3 vertices)"},
      {"obj_empty.obj", ": no faces (0 vertices)"},
      {"obj_error_after_continuation.obj", ":8: face index 7 out of range (3 vertices)"},
      {"obj_face_no_vertices.obj", ":4: face has 0 vertices (at least 3 needed)"},
      {"obj_face_two_vertices.obj", ":4: face has 2 vertices (at least 3 needed)"},
      {"obj_garbage_bytes.obj", ":1: line does not start with an OBJ keyword ('?PNG')"},
      {"obj_index_out_of_range.obj", ":4: face index 4 out of range (3 vertices)"},
      {"obj_index_too_many_digits.obj", ":4: bad face vertex '123456789012345678901234'"},
      {"obj_inf_coordinate.obj", ":4: vertex coordinate '-inf' is not a finite number"},
      {"obj_nan_coordinate.obj", ":4: vertex coordinate 'nan' is not a finite number"},
      {"obj_no_faces.obj", ": no faces (3 vertices)"},
      {"obj_overflow_coordinate.obj", ":4: vertex coordinate '1e39' is not a finite number"},
      {"obj_relative_index_before_start.obj",
       ":4: relative face index -5 out of range (3 vertices before it)"},
      {"obj_relative_texture_index_before_start.obj",
       ":5: relative face texture index -2 out of range (1 texture coordinates before it)"},
      {"obj_tag_bad_boundary.obj", ":5: interpolateboundary 7 is not 0 (none)"},
      {"obj_tag_bad_counts.obj", ":5: tag 'crease': bad argument counts '2/1'"},
      {"obj_tag_extra_arguments.obj", ":5: tag 'corner': unexpected '3.0' after its 1/1/0"},
      {"obj_tag_hole_out_of_range.obj", ":5: hole tag: face id 5 out of range (1 faces"},
      {"obj_tag_missing_float.obj", ":5: tag 'crease' ends after 0 of its 1 floats"},
      {"obj_tag_nan_sharpness.obj", ":5: tag 'corner': value 'nan' is not a finite number"},
      {"obj_tag_odd_crease.obj", ":5: crease tag needs pairs of vertex ids (got 3 integers)"},
      {"obj_tag_vertex_out_of_range.obj", ":5: crease tag: vertex id 9 out of range (3 vertices"},
      {"obj_texcoord_garbage.obj", ":4: unexpected 'x' after the texture coordinates"},
      {"obj_texcoord_nan.obj", ":4: texture coordinate 'nan' is not a finite number"},
      {"obj_texture_index_out_of_range.obj",
       ":7: face texture index 4 out of range (2 texture coordinates)"},
      {"obj_texture_index_without_vt.obj",
       ":4: face texture index 1 out of range (0 texture coordinates)"},
      {"obj_unterminated_continuation.obj", ":4: line continued with '\\' at the end of the file"},
      {"obj_vertex_trailing_garbage.obj", ":1: unexpected 'x' after the vertex coordinates"},
      {"obj_vertex_two_coordinates.obj", ":1: vertex has 2 coordinates (3 needed)"},
      {"obj_zero_index.obj", ":4: face index 0 (OBJ indices start at 1)"},
      {"ply_ascii_bad_number.ply", ":11: vertex 1: bad float value 'abc' for 'y'"},
      // Found by the PLY fuzzer: binary bytes in a name must not reach a message raw.
      {"ply_element_name_control_bytes.ply", ":3: element name 'ver?"},
      {"ply_ascii_count_does_not_fit.ply",
       ":13: face 0: value 300 of 'vertex_indices' does not fit its type uchar"},
      {"ply_ascii_ends_early.ply", ":15: face 1: file ends before its 'vertex_indices' value"},
      {"ply_ascii_face_two_vertices.ply", ":13: face 0: 2 vertices (at least 3 needed)"},
      {"ply_ascii_index_out_of_range.ply", ":13: face 0: vertex index 7 out of range (3 vertices)"},
      {"ply_ascii_inf_coordinate.ply", ":12: vertex 2: 'x' value 'inf' is not a finite number"},
      {"ply_ascii_more_data_than_counts.ply", ":14: unexpected '3' after the last element"},
      {"ply_bad_format.ply", ":2: unknown format 'binary_middle_endian'"},
      {"ply_bad_magic.ply", ": not a PLY file"},
      {"ply_bad_version.ply", ":2: unsupported PLY version '2.0'"},
      {"ply_big_endian_truncated_mid_face.ply", ": face 0: truncated"},
      {"ply_binary_nan_vertex.ply", ": vertex 1: coordinate nan is not a finite number"},
      {"ply_binary_negative_index.ply", ": face 0: vertex index -1 out of range (3 vertices)"},
      {"ply_binary_negative_list_count.ply", ": face 0: negative list size -3"},
      {"ply_binary_truncated_mid_face.ply", ": face 0: truncated"},
      {"ply_binary_truncated_mid_vertex.ply", ": vertex 2: truncated"},
      {"ply_element_without_properties.ply", ": element 'marker' has 5 records but no properties"},
      {"ply_float_index_type.ply", ": PLY face index type 'float' is not an integer type"},
      {"ply_huge_face_count.ply", ": header claims 4294967295 'face' elements but the 4 bytes"},
      {"ply_list_count_float.ply", ":8: list count type 'float' is not an integer type"},
      {"ply_missing_z.ply", ": PLY vertex element has no 'z' property"},
      {"ply_no_end_header.ply", ": PLY header has no end_header line"},
      {"ply_no_index_list.ply", ": PLY face element has no 'vertex_indices' list"},
      {"ply_no_vertex_element.ply", ": PLY has no 'vertex' element"},
      {"ply_property_before_element.ply", ":3: property line before any element line"},
      {"ply_tiny_huge_count.ply", ": header claims 4000000000 'face' elements but the 0 bytes"},
      {"ply_unknown_header_line.ply", ":9: unknown header line 'propertee'"},
      {"ply_unsupported_type.ply", ":4: unsupported property type 'int64'"},
      {"ply_zero_faces.ply", ": PLY has no faces"},
  };
  return cases;
}

class Malformed : public ::testing::TestWithParam<Case> {};

TEST_P(Malformed, ClearOneLineError) {
  const Case& c = GetParam();
  const std::string path = DataPath(std::string("malformed/") + c.file);
  for (int threads : {1, 2}) {
    ReadOptions options;
    options.threads = threads;
    options.chunk_bytes = threads == 1 ? 0 : 8;  // many tiny chunks for the parallel parse
    StatusOr<Mesh> mesh = ReadMesh(path, options);
    ASSERT_FALSE(mesh.ok()) << c.file << " read without error";
    const std::string& message = mesh.status().message();
    EXPECT_EQ(message.find(path), 0u) << message;
    EXPECT_NE(message.find(c.fragment), std::string::npos)
        << "message: " << message << "\nexpected: " << c.fragment;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

INSTANTIATE_TEST_SUITE_P(Files, Malformed, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           std::string name = param.param.file;
                           std::replace(name.begin(), name.end(), '.', '_');
                           return name;
                         });

TEST(MalformedFolder, EveryFileHasACase) {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(DataPath("malformed"))) {
    const std::string name = entry.path().filename();
    if (name != "README.md") files.push_back(name);
  }
  std::vector<std::string> listed;
  for (const Case& c : Cases()) listed.push_back(c.file);
  std::sort(files.begin(), files.end());
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(files, listed);
  EXPECT_GE(files.size(), 30u);
}

// Missing files and directories are errors too, not crashes.
TEST(MalformedFolder, NotAFile) {
  StatusOr<Mesh> missing = ReadMesh(DataPath("malformed/does_not_exist.obj"));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("no such file"), std::string::npos);
  StatusOr<Mesh> directory = ReadObj(DataPath("malformed"));
  ASSERT_FALSE(directory.ok());
  EXPECT_NE(directory.status().message().find("is a directory"), std::string::npos);
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Random damage to valid files: flipped bytes, inserted syntax characters, truncation.
void Mutate(std::string& bytes, std::mt19937& rng) {
  static const char kSpecial[] = "\n\r\\/#- 0123456789.eE+ftvgo\x00\xff";
  std::uniform_int_distribution<int> kind(0, 3);
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits && !bytes.empty(); ++e) {
    const std::size_t at = rng() % bytes.size();
    switch (kind(rng)) {
      case 0:
        bytes[at] = static_cast<char>(rng());
        break;
      case 1:
        bytes[at] = kSpecial[rng() % (sizeof(kSpecial) - 1)];
        break;
      case 2:
        bytes.insert(at, 1, kSpecial[rng() % (sizeof(kSpecial) - 1)]);
        break;
      default:
        bytes.resize(at);
        break;
    }
  }
}

void ExpectMeshOrOneLineError(const StatusOr<Mesh>& mesh, const std::string& name) {
  if (!mesh.ok()) {
    const std::string& message = mesh.status().message();
    EXPECT_EQ(message.find(name), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    return;
  }
  EXPECT_GT(mesh->num_faces(), 0u);
  EXPECT_EQ(mesh->face_offsets.back(), mesh->face_indices.size());
  for (std::int32_t v : mesh->face_indices) {
    ASSERT_GE(v, 0);
    ASSERT_LT(static_cast<std::size_t>(v), mesh->num_vertices());
  }
}

TEST(Mutations, ObjNeverCrashes) {
  const std::string original = ReadBytes(DataPath("meshes/opensubdiv/catmark_hole_test2.obj"));
  std::mt19937 rng(12345);
  for (int i = 0; i < 1500; ++i) {
    std::string bytes = original;
    Mutate(bytes, rng);
    ReadOptions options;
    options.chunk_bytes = 1 + rng() % 512;
    options.threads = 2;
    StatusOr<Mesh> parallel = ParseObj(bytes, "m.obj", options);
    ExpectMeshOrOneLineError(parallel, "m.obj");
    // The chunked parse and a one-chunk parse agree, error or not.
    StatusOr<Mesh> single = ParseObj(bytes, "m.obj", ReadOptions{1, std::size_t{1} << 30});
    ASSERT_EQ(parallel.ok(), single.ok());
    if (single.ok()) {
      EXPECT_TRUE(testing::SameMesh(*parallel, *single));
    } else {
      EXPECT_EQ(parallel.status().message(), single.status().message());
    }
  }
}

TEST(Mutations, PlyNeverCrashes) {
  // A small binary and a small ASCII PLY built here.
  std::string ascii =
      "ply\nformat ascii 1.0\ncomment x\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nelement face 2\nproperty list uchar int "
      "vertex_indices\nproperty list uchar float uv\nend_header\n0 0 0 1\n1 0 0 2\n1 1 0 3\n"
      "0 1 0 4\n3 0 1 2 2 0.5 0.5\n3 0 2 3 0\n";
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const float xyz[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  binary.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  const std::int32_t faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (const auto& f : faces) {
    binary.push_back(3);
    binary.append(reinterpret_cast<const char*>(f), sizeof f);
  }
  ASSERT_TRUE(ParsePly(ascii, "a.ply").ok());
  ASSERT_TRUE(ParsePly(binary, "b.ply").ok());
  std::mt19937 rng(777);
  for (int i = 0; i < 1500; ++i) {
    std::string a = ascii;
    std::string b = binary;
    Mutate(a, rng);
    Mutate(b, rng);
    ExpectMeshOrOneLineError(ParsePly(a, "a.ply"), "a.ply");
    ExpectMeshOrOneLineError(ParsePly(b, "b.ply"), "b.ply");
  }
}

}  // namespace
}  // namespace dispex
