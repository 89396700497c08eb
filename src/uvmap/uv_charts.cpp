// Per-Ptex-face corner UVs (see dispex/uv_charts.h).
#include "dispex/uv_charts.h"

#include <fmt/format.h>

#include <cmath>

namespace dispex {

StatusOr<PtexUvCharts> PtexUvCharts::Build(const Mesh& cage, const LimitSurface& surface) {
  if (!cage.has_uvs()) {
    if (cage.faces_without_uvs > 0) {
      return Status::Error(fmt::format(
          "{}: face {} has no texture coordinates (vt; {} of {} faces have none): UVs are "
          "needed on every face",
          cage.source, cage.first_face_without_uvs, cage.faces_without_uvs, cage.num_faces()));
    }
    return Status::Error(
        fmt::format("{}: the cage has no texture coordinates (vt on its faces)", cage.source));
  }
  if (static_cast<std::size_t>(surface.num_base_faces()) != cage.num_faces()) {
    return Status::Error(fmt::format("{}: the limit surface has {} faces, the cage {}", cage.source,
                                     surface.num_base_faces(), cage.num_faces()));
  }
  PtexUvCharts charts;
  charts.corners_.resize(8 * static_cast<std::size_t>(surface.num_ptex_faces()));
  for (int p = 0; p < surface.num_ptex_faces(); ++p) {
    const PtexFaceId ptex(p);
    const std::size_t f = static_cast<std::size_t>(surface.base_face(ptex).value);
    const int n = cage.face_size(f);
    const std::int32_t* uv_index = cage.face_uv_indices.data() + cage.face_offsets[f];
    auto corner = [&](int k, double out[2]) {
      const std::size_t i = 2 * static_cast<std::size_t>(uv_index[(k % n + n) % n]);
      out[0] = cage.uvs[i];
      out[1] = cage.uvs[i + 1];
    };
    double* c = &charts.corners_[8 * static_cast<std::size_t>(p)];
    if (n == 4) {
      for (int k = 0; k < 4; ++k) corner(k, c + 2 * k);
      continue;
    }
    const int k = surface.sub_face(ptex);
    double centroid[2] = {0, 0}, here[2], next[2], previous[2];
    for (int j = 0; j < n; ++j) {
      double uv[2];
      corner(j, uv);
      centroid[0] += uv[0];
      centroid[1] += uv[1];
    }
    corner(k, here);
    corner(k + 1, next);
    corner(k - 1, previous);
    c[0] = here[0];
    c[1] = here[1];
    c[2] = 0.5 * (here[0] + next[0]);
    c[3] = 0.5 * (here[1] + next[1]);
    c[4] = centroid[0] / n;
    c[5] = centroid[1] / n;
    c[6] = 0.5 * (here[0] + previous[0]);
    c[7] = 0.5 * (here[1] + previous[1]);
  }
  return charts;
}

int UdimOfUv(double u, double v) {
  const double tu = std::floor(u), tv = std::floor(v);
  if (!(tu >= 0 && tu <= 9 && tv >= 0 && tv <= 98)) return 0;
  return 1001 + static_cast<int>(tu) + 10 * static_cast<int>(tv);
}

}  // namespace dispex
