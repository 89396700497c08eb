// CountMeshElements: a mesh file's vertices, faces and corners without reading the mesh -- the
// PLY header's counts, or one parallel pass over an OBJ's lines.
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <cstring>
#include <string>
#include <string_view>

#include "core/mapped_file.h"
#include "dispex/mesh.h"
#include "mesh/ply_header.h"

namespace dispex {
namespace {

constexpr std::uint64_t kAssumedCornersPerFace = 4;  // sculpts are quads
constexpr std::size_t kChunkBytes = std::size_t{4} << 20;

bool IsBlank(char c) {
  return c == ' ' || c == '\t';
}

// The counts of the lines that start in [begin, end) of `text` (a line may run past `end`).
MeshSize CountObjLines(std::string_view text, std::size_t begin, std::size_t end) {
  MeshSize size;
  std::size_t at = begin;
  if (at > 0 && text[at - 1] != '\n') {  // inside a line that started before
    const void* nl = std::memchr(text.data() + at, '\n', end - at);
    if (nl == nullptr) return size;
    at = static_cast<std::size_t>(static_cast<const char*>(nl) - text.data()) + 1;
  }
  while (at < end) {
    const void* nl = std::memchr(text.data() + at, '\n', text.size() - at);
    const std::size_t line_end =
        nl == nullptr ? text.size()
                      : static_cast<std::size_t>(static_cast<const char*>(nl) - text.data());
    std::size_t c = at;
    while (c < line_end && IsBlank(text[c])) ++c;
    if (c + 1 < line_end && IsBlank(text[c + 1])) {
      if (text[c] == 'v') {
        ++size.vertices;
      } else if (text[c] == 'f') {
        ++size.faces;
        bool in_word = false;
        for (std::size_t k = c + 1; k < line_end; ++k) {
          const bool word = !IsBlank(text[k]) && text[k] != '\r';
          size.corners += word && !in_word;
          in_word = word;
        }
      }
    }
    at = line_end + 1;
  }
  return size;
}

MeshSize Add(MeshSize a, const MeshSize& b) {
  a.vertices += b.vertices;
  a.faces += b.faces;
  a.corners += b.corners;
  return a;
}

}  // namespace

StatusOr<MeshSize> CountMeshElements(const std::string& path) {
  const MeshFormat format = DetectMeshFormat(path);
  if (format == MeshFormat::kUnknown) {
    return Status::Error(
        fmt::format("{}: not an OBJ or PLY file (by its name and first bytes)", path));
  }
  DISPEX_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  const std::string_view text = file.view();
  if (format == MeshFormat::kPly) {
    DISPEX_ASSIGN_OR_RETURN(const mesh::Header header, mesh::ParseHeader(text, path));
    MeshSize size;
    for (const mesh::Element& element : header.elements) {
      if (element.name == "vertex") size.vertices = element.count;
      if (element.name == "face") size.faces = element.count;
    }
    size.corners = kAssumedCornersPerFace * size.faces;
    return size;
  }
  MeshSize size = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, text.size(), kChunkBytes), MeshSize{},
      [&](const tbb::blocked_range<std::size_t>& range, MeshSize sum) {
        return Add(sum, CountObjLines(text, range.begin(), range.end()));
      },
      Add);
  size.corners_counted = true;
  return size;
}

}  // namespace dispex
