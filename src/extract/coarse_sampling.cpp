#include "extract/coarse_sampling.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>

#include "core/vec3.h"
#include "extract/parallel_errors.h"

namespace dispex::extract {

StatusOr<CoarseSampling> SampleCoarsely(const LimitSurface& surface) {
  const int n = surface.num_ptex_faces();
  constexpr int kGrid = CoarseSampling::kGrid;
  CoarseSampling out;
  out.face_areas.assign(static_cast<std::size_t>(n), 0.0);
  std::vector<float> pos(static_cast<std::size_t>(n) * kGrid * kGrid * 3, 0.0f);
  std::vector<float> nrm(pos.size(), 0.0f);
  std::vector<std::uint8_t> ok(static_cast<std::size_t>(n), 0);
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  FirstError error;
  tbb::parallel_for(0, n, [&](int f) {
    PtexFaceId face(f);
    if (surface.is_hole(face) || error.failed()) return;
    auto& evaluator = evaluators.local();
    if (!evaluator) evaluator.emplace(surface);
    std::span<float> p(pos.data() + static_cast<std::size_t>(f) * kGrid * kGrid * 3,
                       kGrid * kGrid * 3);
    std::span<float> q(nrm.data() + static_cast<std::size_t>(f) * kGrid * kGrid * 3,
                       kGrid * kGrid * 3);
    Status s = evaluator->EvaluateGrid(face, kGrid, kGrid, p, q);
    if (!s.ok()) return error.Record(f, s);
    // The 3x3 cells between sample centres cover (3/4)^2 of the face's parameter square.
    double area = 0;
    for (int j = 0; j + 1 < kGrid; ++j) {
      for (int i = 0; i + 1 < kGrid; ++i) {
        auto at = [&](int ii, int jj, int c) { return double(p[3 * (jj * kGrid + ii) + c]); };
        auto point = [&](int ii, int jj) {
          return Vec3d{at(ii, jj, 0), at(ii, jj, 1), at(ii, jj, 2)};
        };
        const Vec3d diagonal1 = point(i + 1, j + 1) - point(i, j);
        const Vec3d diagonal2 = point(i, j + 1) - point(i + 1, j);
        area += 0.5 * Length(Cross(diagonal1, diagonal2));
      }
    }
    out.face_areas[static_cast<std::size_t>(f)] = area / (0.75 * 0.75);
    ok[static_cast<std::size_t>(f)] = 1;
  });
  if (error.failed()) return error.status();
  // At most ~64K points for the search-distance estimate, spread over all faces.
  std::size_t total = static_cast<std::size_t>(n) * kGrid * kGrid;
  std::size_t stride = std::max<std::size_t>(1, total / 65536);
  for (std::size_t i = 0; i < total; i += stride) {
    if (!ok[i / (kGrid * kGrid)]) continue;
    out.points.push_back({pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]});
    out.normals.push_back({nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]});
    out.ids.push_back(static_cast<std::int64_t>(i));
  }
  return out;
}

}  // namespace dispex::extract
