#include "dispex/extract.h"

namespace dispex {

std::vector<PtexFaceInfo> PtexFaceTable(const LimitSurface& surface) {
  std::vector<PtexFaceInfo> faces(static_cast<std::size_t>(surface.num_ptex_faces()));
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    const PtexFaceId face(f);
    const PtexAdjacency& adjacency = surface.adjacency(face);
    PtexFaceInfo& info = faces[static_cast<std::size_t>(f)];
    for (std::size_t e = 0; e < 4; ++e) {
      info.adjfaces[e] = adjacency.faces[e].value;
      info.adjedges[e] = static_cast<std::uint8_t>(adjacency.edges[e]);
    }
    info.subface = surface.base_face_size(surface.base_face(face)) != 4;
  }
  return faces;
}

}  // namespace dispex
