#include "extract/faces_around.h"

namespace dispex::extract {

std::vector<std::uint8_t> WithFacesAround(const ExtractInputs& inputs,
                                          std::vector<std::uint8_t> flags) {
  const LimitSurface& surface = inputs.surface;
  const Mesh& base = inputs.base;
  std::vector<std::uint8_t> vertex(base.num_vertices(), 0);
  for (std::size_t f = 0; f < flags.size(); ++f) {
    if (!flags[f]) continue;
    const auto b =
        static_cast<std::size_t>(surface.base_face(PtexFaceId(static_cast<int>(f))).value);
    for (std::int32_t v : base.face(b)) vertex[static_cast<std::size_t>(v)] = 1;
  }
  for (std::size_t f = 0; f < flags.size(); ++f) {
    if (flags[f]) continue;
    const auto b =
        static_cast<std::size_t>(surface.base_face(PtexFaceId(static_cast<int>(f))).value);
    for (std::int32_t v : base.face(b)) flags[f] |= vertex[static_cast<std::size_t>(v)];
  }
  return flags;
}

}  // namespace dispex::extract
