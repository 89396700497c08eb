// The standard Ptex mesh meta data: the base mesh stored in the map, for viewers.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dispex/ptex.h"

namespace dispex {

Status AddMeshMetaData(PtexWriter& writer, const Mesh& mesh) {
  const std::size_t nfaces = mesh.num_faces();
  std::vector<std::int32_t> counts(nfaces);
  for (std::size_t f = 0; f < nfaces; ++f) counts[f] = mesh.face_size(f);
  std::vector<float> positions;
  positions.reserve(mesh.num_vertices() * 3);
  for (const Float3& p : mesh.positions) {
    positions.push_back(p.x);
    positions.push_back(p.y);
    positions.push_back(p.z);
  }
  if (nfaces == 0 || positions.empty()) {
    return Status::Error((mesh.source.empty() ? std::string("mesh") : mesh.source) +
                         ": no faces or vertices to store as Ptex mesh meta data");
  }
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("PtexFaceVertCounts", std::span<const std::int32_t>(counts)));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("PtexFaceVertIndices", std::span<const std::int32_t>(mesh.face_indices)));
  return writer.AddMetaData("PtexVertPositions", std::span<const float>(positions));
}

}  // namespace dispex
