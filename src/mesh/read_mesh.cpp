// ReadMesh: picks the reader from the file's first bytes and its extension.
// MeshFormatOfName: the format a file's name asks for.
#include <fstream>
#include <string>

#include "core/mapped_file.h"
#include "dispex/mesh.h"

namespace dispex {
namespace {

std::string LowerExtension(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return ext;
}

// A PLY file starts with "ply" and a line end.
bool HasPlyMagic(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[5] = {};
  in.read(magic, 5);
  const std::streamsize n = in.gcount();
  return n >= 4 && magic[0] == 'p' && magic[1] == 'l' && magic[2] == 'y' &&
         (magic[3] == '\n' || (n == 5 && magic[3] == '\r' && magic[4] == '\n'));
}

}  // namespace

MeshFormat MeshFormatOfName(const std::string& path) {
  const std::string ext = LowerExtension(path);
  if (ext == "ply") return MeshFormat::kPly;
  if (ext == "obj") return MeshFormat::kObj;
  return MeshFormat::kUnknown;
}

MeshFormat DetectMeshFormat(const std::string& path) {
  return HasPlyMagic(path) ? MeshFormat::kPly : MeshFormatOfName(path);
}

namespace {

StatusOr<Mesh> ReadMeshFile(const std::string& path, const ReadOptions& options) {
  DISPEX_RETURN_IF_ERROR(CheckReadableFile(path));
  switch (DetectMeshFormat(path)) {
    case MeshFormat::kPly:
      return ReadPly(path, options);
    case MeshFormat::kObj:
      return ReadObj(path, options);
    case MeshFormat::kUnknown:
      break;
  }
  return Status::Error(path + ": unknown mesh format (expected an .obj file or a PLY file)");
}

}  // namespace

StatusOr<Mesh> ReadMesh(const std::string& path, const ReadOptions& options) {
  StatusOr<Mesh> mesh = ReadMeshFile(path, options);
  if (!mesh.ok()) return mesh.status().WithCode(StatusCode::kBadInput).WithPath(path);
  return mesh;
}

}  // namespace dispex
