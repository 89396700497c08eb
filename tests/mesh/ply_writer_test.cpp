// WritePly and WriteMesh: what ReadPly / ReadMesh read back is the mesh written, bit for bit;
// names decide the format; a name of neither format writes nothing.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "dispex/mesh.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

using testing::TempPath;

// A triangle, a quad and a pentagon over values a text round trip would be likely to bend:
// -0, a subnormal, the largest float, a value with all 24 mantissa bits.
Mesh MixedMesh() {
  Mesh mesh;
  mesh.positions = {{0.0f, -0.0f, 1.0f},
                    {std::numeric_limits<float>::denorm_min(), 2.0f, 3.0f},
                    {std::numeric_limits<float>::max(), -1e-30f, 0.1f},
                    {16777215.0f, 0.333333343f, -7.5f},
                    {1.0f, 1.0f, 1.0f},
                    {2.0f, 0.5f, -0.25f}};
  mesh.face_offsets = {0, 3, 7, 12};
  mesh.face_indices = {0, 1, 2, 2, 1, 3, 4, 5, 4, 3, 0, 2};
  return mesh;
}

void ExpectSameMesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.num_vertices(), b.num_vertices());
  for (std::size_t v = 0; v < a.num_vertices(); ++v) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.positions[v].x),
              std::bit_cast<std::uint32_t>(b.positions[v].x))
        << "vertex " << v;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.positions[v].y),
              std::bit_cast<std::uint32_t>(b.positions[v].y))
        << "vertex " << v;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.positions[v].z),
              std::bit_cast<std::uint32_t>(b.positions[v].z))
        << "vertex " << v;
  }
  EXPECT_EQ(a.face_offsets, b.face_offsets);
  EXPECT_EQ(a.face_indices, b.face_indices);
}

TEST(PlyWriter, ReadsBackBitForBit) {
  const std::string path = TempPath(".ply");
  const Mesh mesh = MixedMesh();
  ASSERT_TRUE(WritePly(path, mesh, "made by a test\nwith a line end").ok());
  StatusOr<Mesh> back = ReadMesh(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ExpectSameMesh(mesh, *back);
  std::ifstream in(path, std::ios::binary);
  std::string header(200, '\0');
  in.read(header.data(), 200);
  EXPECT_NE(
      header.find("format binary_little_endian 1.0\ncomment made by a test with a line end\n"),
      std::string::npos)
      << header;
  EXPECT_NE(header.find("property list uchar int vertex_indices"), std::string::npos) << header;
  std::filesystem::remove(path);
}

TEST(PlyWriter, FacesOfMoreThan255CornersCountInUint) {
  Mesh mesh;
  constexpr int kCorners = 300;
  for (int i = 0; i < kCorners; ++i) {
    const double a = 2 * M_PI * i / kCorners;
    mesh.positions.push_back({static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0});
    mesh.face_indices.push_back(i);
  }
  mesh.face_offsets = {0, kCorners};
  const std::string path = TempPath(".ply");
  ASSERT_TRUE(WritePly(path, mesh).ok());
  StatusOr<Mesh> back = ReadPly(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ExpectSameMesh(mesh, *back);
  std::filesystem::remove(path);
}

// WritePly goes through PlyStreamWriter; what it refuses is written nowhere.
TEST(PlyStreamWriter, WritesOnlyTheCountsItDeclared) {
  const Mesh mesh = MixedMesh();
  const std::string path = TempPath(".ply");
  {
    auto out = PlyStreamWriter::Create(path, mesh.num_vertices(), mesh.num_faces(), 5, "");
    ASSERT_TRUE(out.ok());
    for (std::size_t v = 0; v + 1 < mesh.num_vertices(); ++v) {
      const Float3 p = mesh.positions[v];
      ASSERT_TRUE(out->AddVertex(p.x, p.y, p.z).ok());
    }
    const Status early = out->AddFace(mesh.face(0));
    EXPECT_NE(early.message().find("face 0 added before the last of the 6 vertices (5 so far)"),
              std::string::npos)
        << early.message();
    const Float3 last = mesh.positions.back();
    ASSERT_TRUE(out->AddVertex(last.x, last.y, last.z).ok());
    const Status extra = out->AddVertex(last.x, last.y, last.z);
    EXPECT_NE(extra.message().find("more than the 6 vertices declared"), std::string::npos)
        << extra.message();
    ASSERT_TRUE(out->AddFace(mesh.face(0)).ok());
    const Status short_by_two = out->Commit();
    EXPECT_NE(short_by_two.message().find("6 vertices and 1 faces written of the 6 and 3"),
              std::string::npos)
        << short_by_two.message();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(WriteMesh, TheNameChoosesTheFormat) {
  const Mesh mesh = MixedMesh();
  const std::string ply = TempPath(".PLY");
  const std::string obj = TempPath(".obj");
  ASSERT_TRUE(WriteMesh(ply, mesh, "upper-case extension").ok());
  ASSERT_TRUE(WriteMesh(obj, mesh, "an OBJ").ok());
  EXPECT_EQ(DetectMeshFormat(ply), MeshFormat::kPly);
  std::ifstream obj_in(obj);
  std::string first_line;
  std::getline(obj_in, first_line);
  EXPECT_EQ(first_line, "# an OBJ");
  for (const std::string& path : {ply, obj}) {
    StatusOr<Mesh> back = ReadMesh(path);
    ASSERT_TRUE(back.ok()) << back.status().message();
    ExpectSameMesh(mesh, *back);
    std::filesystem::remove(path);
  }
}

TEST(WriteMesh, AnUnknownNameIsAnErrorAndWritesNothing) {
  const std::string path = TempPath(".stl");
  const Status status = WriteMesh(path, MixedMesh());
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), path + ": unknown mesh format (the name must end in .obj or .ply)");
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_EQ(MeshFormatOfName(path), MeshFormat::kUnknown);
}

}  // namespace
}  // namespace dispex
