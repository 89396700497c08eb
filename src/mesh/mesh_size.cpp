// CountMeshElements: a mesh file's vertices, faces and corners without reading the mesh -- the
// PLY header's counts, or the OBJ reader's counting pass.
#include <fmt/format.h>

#include <string>

#include "core/mapped_file.h"
#include "dispex/mesh.h"
#include "mesh/obj_reader.h"
#include "mesh/ply_header.h"

namespace dispex {

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
    size.corners = 4 * size.faces;  // sculpts are quads
    return size;
  }
  return CountObjElements(text);
}

}  // namespace dispex
