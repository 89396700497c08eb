// PLY: the same meshes written as ASCII, binary little endian and binary big endian, with
// every property type name, extra scalar and list properties, and other elements around the
// vertex and face elements. The files are written here, value by value.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

enum class Fmt { kAscii, kLittle, kBig };

const char* FormatName(Fmt f) {
  return f == Fmt::kAscii    ? "ascii"
         : f == Fmt::kLittle ? "binary_little_endian"
                             : "binary_big_endian";
}

// Appends `value` as the PLY type `type` (any of its names) in format `f`.
void Put(std::string& out, Fmt f, const std::string& type, double value) {
  const bool real = type == "float" || type == "float32" || type == "double" || type == "float64";
  if (f == Fmt::kAscii) {
    out += real ? fmt::format("{:.9g} ", value) : fmt::format("{} ", static_cast<long long>(value));
    return;
  }
  unsigned char bytes[8];
  std::size_t size = 0;
  auto store = [&](auto v) {
    size = sizeof v;
    std::memcpy(bytes, &v, size);
  };
  if (type == "char" || type == "int8")
    store(static_cast<std::int8_t>(value));
  else if (type == "uchar" || type == "uint8")
    store(static_cast<std::uint8_t>(value));
  else if (type == "short" || type == "int16")
    store(static_cast<std::int16_t>(value));
  else if (type == "ushort" || type == "uint16")
    store(static_cast<std::uint16_t>(value));
  else if (type == "int" || type == "int32")
    store(static_cast<std::int32_t>(value));
  else if (type == "uint" || type == "uint32")
    store(static_cast<std::uint32_t>(value));
  else if (type == "float" || type == "float32")
    store(static_cast<float>(value));
  else
    store(value);
  const bool swap = (f == Fmt::kBig) == (std::endian::native == std::endian::little);
  for (std::size_t i = 0; i < size; ++i)
    out.push_back(static_cast<char>(bytes[swap ? size - 1 - i : i]));
}

void EndRecord(std::string& out, Fmt f) {
  if (f == Fmt::kAscii) {
    out.pop_back();  // the last value's blank
    out += '\n';
  }
}

struct Variant {
  std::string coordinate_type = "float";
  std::string count_type = "uchar";
  std::string index_type = "int";
  std::string index_name = "vertex_indices";
  bool extras = false;  // extra properties and elements everywhere
};

const std::vector<Float3> kPositions = {{0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}, {2, 2, 2}};
const std::vector<std::vector<int>> kFaces = {
    {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}, {0, 3, 2, 1}};

bool IsReal(const std::string& type) {
  return type == "float" || type == "float32" || type == "double" || type == "float64";
}

std::string WritePly(Fmt f, const Variant& v) {
  std::string h = fmt::format("ply\nformat {} 1.0\ncomment made by ply_reader_test\nobj_info x\n",
                              FormatName(f));
  if (v.extras) h += "element material 2\nproperty uchar id\nproperty list uchar char name\n";
  h += fmt::format("element vertex {}\n", kPositions.size());
  if (v.extras) h += "property float nx\n";
  for (const char* axis : {"x", "y", "z"})
    h += fmt::format("property {} {}\n", v.coordinate_type, axis);
  if (v.extras) h += "property list uchar int junk\nproperty uint8 red\n";
  h += fmt::format("element face {}\n", kFaces.size());
  if (v.extras) h += "property uchar flags\n";
  h += fmt::format("property list {} {} {}\n", v.count_type, v.index_type, v.index_name);
  if (v.extras)
    h += "property list uchar float uv\nelement edge 2\nproperty int vertex1\nproperty int "
         "vertex2\n";
  h += "end_header\n";
  std::string b;
  if (v.extras) {
    for (int i = 0; i < 2; ++i) {
      Put(b, f, "uchar", i);
      Put(b, f, "uchar", 3);
      for (int c = 0; c < 3; ++c) Put(b, f, "char", 'a' + c);
      EndRecord(b, f);
    }
  }
  const double offset = IsReal(v.coordinate_type) ? 0.25 : 0;  // fractions only for reals
  for (const Float3& p : kPositions) {
    if (v.extras) Put(b, f, "float", 0.5);
    Put(b, f, v.coordinate_type, p.x + offset);
    Put(b, f, v.coordinate_type, p.y + offset);
    Put(b, f, v.coordinate_type, p.z + offset);
    if (v.extras) {
      Put(b, f, "uchar", 2);
      Put(b, f, "int", 7);
      Put(b, f, "int", -7);
      Put(b, f, "uint8", 200);
    }
    EndRecord(b, f);
  }
  for (const auto& face : kFaces) {
    if (v.extras) Put(b, f, "uchar", 1);
    Put(b, f, v.count_type, static_cast<double>(face.size()));
    for (int i : face) Put(b, f, v.index_type, i);
    if (v.extras) {
      Put(b, f, "uchar", 1);
      Put(b, f, "float", 0.125);
    }
    EndRecord(b, f);
  }
  if (v.extras) {
    for (int i = 0; i < 2; ++i) {
      Put(b, f, "int", i);
      Put(b, f, "int", i + 1);
      EndRecord(b, f);
    }
  }
  return h + b;
}

void ExpectPyramid(const Mesh& mesh, double offset) {
  ASSERT_EQ(mesh.num_vertices(), kPositions.size());
  for (std::size_t i = 0; i < kPositions.size(); ++i) {
    EXPECT_EQ(mesh.positions[i].x, kPositions[i].x + offset) << i;
    EXPECT_EQ(mesh.positions[i].y, kPositions[i].y + offset) << i;
    EXPECT_EQ(mesh.positions[i].z, kPositions[i].z + offset) << i;
  }
  ASSERT_EQ(mesh.num_faces(), kFaces.size());
  for (std::size_t f = 0; f < kFaces.size(); ++f) {
    const auto face = mesh.face(f);
    EXPECT_EQ(std::vector<int>(face.begin(), face.end()), kFaces[f]) << f;
  }
  EXPECT_GE(mesh.positions.capacity(), mesh.positions.size() + 1);
  EXPECT_TRUE(mesh.face_groups.empty());
  EXPECT_TRUE(mesh.tags.empty());
}

TEST(PlyReader, EveryFormatAndType) {
  const std::vector<Variant> variants = {
      {"float", "uchar", "int", "vertex_indices", false},
      {"float32", "uint8", "int32", "vertex_indices", true},
      {"double", "ushort", "uint", "vertex_index", false},
      {"float64", "uint16", "uint32", "vertex_indices", true},
      {"short", "int", "short", "vertex_indices", true},
      {"int16", "int32", "int16", "vertex_indices", false},
      {"char", "char", "uchar", "vertex_indices", true},
      {"int8", "int8", "ushort", "vertex_index", false},
      {"uchar", "uint", "char", "vertex_indices", false},
      {"ushort", "uint32", "uint16", "vertex_indices", true},
      {"int", "short", "int8", "vertex_indices", false},
      {"uint", "int16", "uint8", "vertex_indices", true},
  };
  for (const Variant& v : variants) {
    for (Fmt f : {Fmt::kAscii, Fmt::kLittle, Fmt::kBig}) {
      SCOPED_TRACE(fmt::format("{} coordinates {} count {} index {}{}", FormatName(f),
                               v.coordinate_type, v.count_type, v.index_type,
                               v.extras ? " with extras" : ""));
      const std::string bytes = WritePly(f, v);
      StatusOr<Mesh> mesh = ParsePly(bytes, "test.ply");
      ASSERT_TRUE(mesh.ok()) << mesh.status().message();
      ExpectPyramid(*mesh, IsReal(v.coordinate_type) ? 0.25 : 0.0);
    }
  }
}

TEST(PlyReader, CrlfHeaderAndAsciiBody) {
  std::string bytes = WritePly(Fmt::kAscii, Variant{});
  std::string crlf;
  for (char c : bytes) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  StatusOr<Mesh> mesh = ParsePly(crlf, "test.ply");
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ExpectPyramid(*mesh, 0.25);
}

TEST(PlyReader, FilesAndDetection) {
  const std::string ply = testing::TempPath(".ply");
  const std::string dat = testing::TempPath(".dat");  // PLY by content only
  const std::string bytes = WritePly(Fmt::kLittle, Variant{});
  for (const std::string& path : {ply, dat}) {
    std::ofstream(path, std::ios::binary) << bytes;
    EXPECT_EQ(DetectMeshFormat(path), MeshFormat::kPly) << path;
    StatusOr<Mesh> mesh = ReadMesh(path);
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    EXPECT_EQ(mesh->source, path);
    ExpectPyramid(*mesh, 0.25);
  }
  StatusOr<Mesh> direct = ReadPly(ply);
  ASSERT_TRUE(direct.ok()) << direct.status().message();
  ExpectPyramid(*direct, 0.25);
  std::remove(ply.c_str());
  std::remove(dat.c_str());
}

// A grid big enough for several parallel blocks (65536 vertices and faces each): the three
// encodings and both thread counts give the same mesh.
TEST(PlyReader, LargeGridAllEncodingsAgree) {
  const int n = 300;
  std::string header_tail = fmt::format(
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
      "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
      n * n, (n - 1) * (n - 1));
  std::vector<Mesh> meshes;
  for (Fmt f : {Fmt::kAscii, Fmt::kLittle, Fmt::kBig}) {
    std::string bytes = fmt::format("ply\nformat {} 1.0\n", FormatName(f)) + header_tail;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        Put(bytes, f, "float", i * 0.5);
        Put(bytes, f, "float", j * 0.25);
        Put(bytes, f, "float", (i * j) % 7);
        EndRecord(bytes, f);
      }
    }
    for (int j = 0; j + 1 < n; ++j) {
      for (int i = 0; i + 1 < n; ++i) {
        const int a = j * n + i;
        Put(bytes, f, "uchar", 4);
        for (int v : {a, a + 1, a + n + 1, a + n}) Put(bytes, f, "int", v);
        EndRecord(bytes, f);
      }
    }
    for (int threads : {1, 2}) {
      StatusOr<Mesh> mesh = ParsePly(bytes, "grid.ply", ReadOptions{threads, 0});
      ASSERT_TRUE(mesh.ok()) << mesh.status().message();
      meshes.push_back(std::move(mesh).value());
    }
  }
  const Mesh& m = meshes[0];
  ASSERT_EQ(m.num_vertices(), static_cast<std::size_t>(n * n));
  ASSERT_EQ(m.num_faces(), static_cast<std::size_t>((n - 1) * (n - 1)));
  EXPECT_TRUE(m.all_quads());
  EXPECT_EQ(m.positions[n * 7 + 3].x, 1.5f);
  EXPECT_EQ(m.positions[n * 7 + 3].y, 1.75f);
  EXPECT_EQ(m.positions[n * 7 + 3].z, 21 % 7);
  const auto last = m.face(m.num_faces() - 1);
  EXPECT_EQ(last[2], n * n - 1);
  for (std::size_t i = 1; i < meshes.size(); ++i) {
    EXPECT_TRUE(testing::SameMesh(meshes[i], m)) << i;
  }
}

// The first bad index by face number is reported, whatever block finds it first.
TEST(PlyReader, FirstBadIndexAcrossBlocks) {
  const int faces = 200000;
  std::string bytes = fmt::format(
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
      faces);
  for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f})
    Put(bytes, Fmt::kLittle, "float", c);
  for (int f = 0; f < faces; ++f) {
    Put(bytes, Fmt::kLittle, "uchar", 3);
    const bool bad = f == 70000 || f == 150000 || f == 199999;
    for (int v : {0, 1, bad ? 3 : 2}) Put(bytes, Fmt::kLittle, "int", v);
  }
  for (int threads : {1, 2}) {
    StatusOr<Mesh> mesh = ParsePly(bytes, "bad.ply", ReadOptions{threads, 0});
    ASSERT_FALSE(mesh.ok());
    EXPECT_EQ(mesh.status().message(),
              "bad.ply: face 70000: vertex index 3 out of range (3 vertices)");
  }
}

// Binary faces are laid out as records of the first face's size when they all are; one face of
// another size anywhere (across blocks of faces) makes the reader walk them record by record,
// with the same mesh as the ASCII file and the same first error.
TEST(PlyReader, OneFaceOfAnotherSizeAmongUniformFaces) {
  const int faces = 200000;
  for (int odd : {0, 70000, faces - 1}) {
    for (int bad : {-1, 120000}) {
      std::vector<Mesh> meshes;
      std::vector<std::string> errors;
      for (Fmt f : {Fmt::kAscii, Fmt::kLittle, Fmt::kBig}) {
        std::string bytes = fmt::format(
            "ply\nformat {} 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nelement face {}\nproperty list uchar int vertex_indices\n"
            "end_header\n",
            FormatName(f), faces);
        for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 0.f}) {
          Put(bytes, f, "float", c);
        }
        EndRecord(bytes, f);
        for (int face = 0; face < faces; ++face) {
          const bool quad = face == odd;
          Put(bytes, f, "uchar", quad ? 4 : 3);
          for (int v : {0, 1, 2}) Put(bytes, f, "int", face == bad && v == 2 ? 4 : v);
          if (quad) Put(bytes, f, "int", 3);
          EndRecord(bytes, f);
        }
        for (int threads : {1, 2}) {
          StatusOr<Mesh> mesh = ParsePly(bytes, "odd.ply", ReadOptions{threads, 0});
          if (!mesh.ok()) {
            errors.push_back(mesh.status().message());
            continue;
          }
          meshes.push_back(std::move(mesh).value());
        }
      }
      if (bad >= 0) {
        ASSERT_EQ(errors.size(), 6u) << odd << " " << bad;
        const std::string what =
            fmt::format(": face {}: vertex index 4 out of range (4 vertices)", bad);
        for (std::size_t i = 0; i < errors.size(); ++i) {  // ASCII names the line too
          EXPECT_EQ(errors[i], (i < 2 ? fmt::format("odd.ply:{}", bad + 11) : "odd.ply") + what);
        }
        continue;
      }
      ASSERT_EQ(meshes.size(), 6u) << odd;
      EXPECT_EQ(meshes[0].face(static_cast<std::size_t>(odd)).size(), 4u);
      EXPECT_EQ(meshes[0].face_offsets.back(), static_cast<std::uint32_t>(3 * faces + 1));
      for (std::size_t i = 1; i < meshes.size(); ++i) {
        EXPECT_TRUE(testing::SameMesh(meshes[i], meshes[0])) << odd << " " << i;
      }
    }
  }
}

TEST(PlyReader, AsciiErrorsNameLineAndElement) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  StatusOr<Mesh> mesh = ParsePly(header + "0 0 0\n1 0 0\n0 1 0 \n3 0 1 2.5\n", "a.ply");
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), "a.ply:13: face 0: bad int value '2.5' for 'vertex_indices'");
  mesh = ParsePly(header + "0 0 0\n1 0 0\n0 1 1e39\n3 0 1 2\n", "a.ply");
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), "a.ply:12: vertex 2: 'z' value '1e39' is not a finite number");
}

}  // namespace
}  // namespace dispex
