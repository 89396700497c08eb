// WritePly and WriteMesh (dispex/mesh.h): binary little-endian PLY, written atomically.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <vector>

#include "core/atomic_output.h"
#include "dispex/mesh.h"

namespace dispex {
namespace {

template <class T>
void Append(std::vector<char>& out, T value) {
  if constexpr (std::endian::native == std::endian::big) {
    auto bytes = std::bit_cast<std::array<char, sizeof(T)>>(value);
    std::reverse(bytes.begin(), bytes.end());
    value = std::bit_cast<T>(bytes);
  }
  const std::size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &value, sizeof(T));
}

}  // namespace

Status WritePly(const std::string& path, const Mesh& mesh, std::string_view comment) {
  int largest_face = 0;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    largest_face = std::max(largest_face, mesh.face_size(f));
  }
  const bool byte_counts = largest_face <= 255;
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  if (!comment.empty()) {
    std::string line(comment);
    std::replace_if(
        line.begin(), line.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    header += fmt::format("comment {}\n", line);
  }
  header += fmt::format(
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
      "element face {}\nproperty list {} int vertex_indices\nend_header\n",
      mesh.num_vertices(), mesh.num_faces(), byte_counts ? "uchar" : "uint");

  DISPEX_ASSIGN_OR_RETURN(AtomicOutput out, AtomicOutput::Create(path));
  DISPEX_RETURN_IF_ERROR(out.Write(header.data(), header.size()));
  constexpr std::size_t kChunk = 1 << 16;
  std::vector<char> buffer;
  for (std::size_t begin = 0; begin < mesh.num_vertices(); begin += kChunk) {
    buffer.clear();
    const std::size_t end = std::min(mesh.num_vertices(), begin + kChunk);
    for (std::size_t v = begin; v < end; ++v) {
      Append(buffer, mesh.positions[v].x);
      Append(buffer, mesh.positions[v].y);
      Append(buffer, mesh.positions[v].z);
    }
    DISPEX_RETURN_IF_ERROR(out.Write(buffer.data(), buffer.size()));
  }
  for (std::size_t begin = 0; begin < mesh.num_faces(); begin += kChunk) {
    buffer.clear();
    const std::size_t end = std::min(mesh.num_faces(), begin + kChunk);
    for (std::size_t f = begin; f < end; ++f) {
      const auto size = static_cast<std::uint32_t>(mesh.face_size(f));
      if (byte_counts) {
        Append(buffer, static_cast<std::uint8_t>(size));
      } else {
        Append(buffer, size);
      }
      for (std::int32_t v : mesh.face(f)) Append(buffer, v);
    }
    DISPEX_RETURN_IF_ERROR(out.Write(buffer.data(), buffer.size()));
  }
  return out.Commit();
}

Status WriteMesh(const std::string& path, const Mesh& mesh, std::string_view comment) {
  switch (MeshFormatOfName(path)) {
    case MeshFormat::kPly:
      return WritePly(path, mesh, comment);
    case MeshFormat::kObj:
      return WriteObj(path, mesh, comment.empty() ? "" : fmt::format("# {}\n", comment));
    case MeshFormat::kUnknown:
      break;
  }
  return Status::Error(
      fmt::format("{}: unknown mesh format (the name must end in .obj or .ply)", path));
}

}  // namespace dispex
