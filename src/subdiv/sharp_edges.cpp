// Which Ptex face edges lie on infinitely sharp creases of the cage.
#include <algorithm>
#include <set>
#include <utility>

#include "dispex/subdiv.h"

namespace dispex {

std::vector<std::uint8_t> SharpCreaseEdges(const Mesh& base, const LimitSurface& surface) {
  std::set<std::pair<std::int32_t, std::int32_t>> sharp;
  for (const auto& crease : base.tags.creases) {
    if (crease.sharpness < 10) continue;
    sharp.insert(std::minmax(crease.v0.value, crease.v1.value));
  }
  std::vector<std::uint8_t> bits(static_cast<std::size_t>(surface.num_ptex_faces()), 0);
  if (sharp.empty()) return bits;
  auto is_sharp = [&](std::int32_t a, std::int32_t b) {
    return sharp.count(std::minmax(a, b)) > 0;
  };
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    const BaseFaceId base_face = surface.base_face(PtexFaceId(f));
    const auto verts = base.face(static_cast<std::size_t>(base_face.value));
    const int n = static_cast<int>(verts.size());
    auto vert = [&](int k) { return verts[static_cast<std::size_t>((k % n + n) % n)]; };
    std::uint8_t& b = bits[std::size_t(f)];
    if (n == 4) {
      for (int e = 0; e < 4; ++e) b |= std::uint8_t(is_sharp(vert(e), vert(e + 1)) << e);
    } else {
      const int q = surface.sub_face(PtexFaceId(f));
      b |= std::uint8_t(is_sharp(vert(q), vert(q + 1)) << 0);
      b |= std::uint8_t(is_sharp(vert(q - 1), vert(q)) << 3);
    }
  }
  return bits;
}

}  // namespace dispex
