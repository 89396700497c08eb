// PlyStreamWriter, WritePly and WriteMesh (dispex/mesh.h): binary little-endian PLY, written
// atomically.
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

constexpr std::size_t kFlushBytes = 1 << 20;

}  // namespace

struct PlyStreamWriter::Impl {
  Status Flush() {
    Status written = out.Write(buffer.data(), buffer.size());
    buffer.clear();
    return written;
  }

  AtomicOutput out;
  std::size_t vertices = 0, faces = 0;  // declared
  std::size_t vertices_added = 0, faces_added = 0;
  bool byte_counts = true;
  std::vector<char> buffer;
};

PlyStreamWriter::PlyStreamWriter() : impl_(std::make_unique<Impl>()) {}
PlyStreamWriter::PlyStreamWriter(PlyStreamWriter&&) noexcept = default;
PlyStreamWriter& PlyStreamWriter::operator=(PlyStreamWriter&&) noexcept = default;
PlyStreamWriter::~PlyStreamWriter() = default;

StatusOr<PlyStreamWriter> PlyStreamWriter::Create(const std::string& path, std::size_t vertices,
                                                  std::size_t faces, int largest_face,
                                                  std::string_view comment) {
  PlyStreamWriter writer;
  Impl& w = *writer.impl_;
  w.vertices = vertices;
  w.faces = faces;
  w.byte_counts = largest_face <= 255;
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
      vertices, faces, w.byte_counts ? "uchar" : "uint");
  DISPEX_ASSIGN_OR_RETURN(w.out, AtomicOutput::Create(path));
  DISPEX_RETURN_IF_ERROR(w.out.Write(header.data(), header.size()));
  w.buffer.reserve(kFlushBytes + 4096);
  return writer;
}

Status PlyStreamWriter::AddVertex(float x, float y, float z) {
  Impl& w = *impl_;
  if (w.vertices_added == w.vertices) {
    return Status::Error(
        fmt::format("{}: more than the {} vertices declared", w.out.target(), w.vertices));
  }
  ++w.vertices_added;
  Append(w.buffer, x);
  Append(w.buffer, y);
  Append(w.buffer, z);
  return w.buffer.size() >= kFlushBytes ? w.Flush() : Status::Ok();
}

Status PlyStreamWriter::AddFace(std::span<const std::int32_t> corners) {
  Impl& w = *impl_;
  if (w.vertices_added != w.vertices) {
    return Status::Error(
        fmt::format("{}: face {} added before the last of the {} vertices ({} so far)",
                    w.out.target(), w.faces_added, w.vertices, w.vertices_added));
  }
  if (w.faces_added == w.faces) {
    return Status::Error(
        fmt::format("{}: more than the {} faces declared", w.out.target(), w.faces));
  }
  ++w.faces_added;
  const auto size = static_cast<std::uint32_t>(corners.size());
  if (w.byte_counts) {
    Append(w.buffer, static_cast<std::uint8_t>(size));
  } else {
    Append(w.buffer, size);
  }
  for (std::int32_t v : corners) Append(w.buffer, v);
  return w.buffer.size() >= kFlushBytes ? w.Flush() : Status::Ok();
}

Status PlyStreamWriter::Commit() {
  Impl& w = *impl_;
  if (w.vertices_added != w.vertices || w.faces_added != w.faces) {
    return Status::Error(
        fmt::format("{}: {} vertices and {} faces written of the {} and {} declared",
                    w.out.target(), w.vertices_added, w.faces_added, w.vertices, w.faces));
  }
  DISPEX_RETURN_IF_ERROR(w.Flush());
  return w.out.Commit();
}

Status WritePly(const std::string& path, const Mesh& mesh, std::string_view comment) {
  int largest_face = 0;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    largest_face = std::max(largest_face, mesh.face_size(f));
  }
  DISPEX_ASSIGN_OR_RETURN(
      PlyStreamWriter out,
      PlyStreamWriter::Create(path, mesh.num_vertices(), mesh.num_faces(), largest_face, comment));
  for (const Float3& p : mesh.positions) DISPEX_RETURN_IF_ERROR(out.AddVertex(p.x, p.y, p.z));
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    DISPEX_RETURN_IF_ERROR(out.AddFace(mesh.face(f)));
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
