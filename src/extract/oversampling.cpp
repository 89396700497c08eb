#include "extract/oversampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <bit>
#include <cmath>

namespace dispex::extract {

namespace {

int Log2Of(int power_of_two) {
  return std::countr_zero(static_cast<unsigned>(power_of_two));
}

// The L for which `sculpt_faces` equals the face count of the base subdivided L times, or -1.
int SubdivisionLevel(const LimitSurface& surface, const Mesh& sculpt) {
  if (!sculpt.all_quads()) return -1;
  std::uint64_t quads = 0, ngon_corners = 0;
  for (int f = 0; f < surface.num_base_faces(); ++f) {
    BaseFaceId face(f);
    if (surface.is_hole(surface.first_ptex_face(face))) continue;
    int n = surface.base_face_size(face);
    if (n == 4) {
      ++quads;
    } else {
      ngon_corners += static_cast<std::uint64_t>(n);
    }
  }
  for (int level = 1; level <= 8; ++level) {
    std::uint64_t per_quad = 1ull << (2 * level);
    std::uint64_t expected = quads * per_quad + ngon_corners * (per_quad / 4);
    if (expected == sculpt.num_faces()) return level;
  }
  return -1;
}

}  // namespace

OversamplingPlan PlanOversampling(const LimitSurface& surface, const Mesh& sculpt,
                                  const std::vector<double>& face_areas, int fixed, int min_samples,
                                  int max_samples) {
  OversamplingPlan plan;
  const int num_faces = surface.num_ptex_faces();
  plan.log2.assign(static_cast<std::size_t>(num_faces), 0);
  const int min_log2 = Log2Of(min_samples), max_log2 = Log2Of(max_samples);
  for (double a : face_areas) plan.base_area += a;
  if (fixed > 0) {
    for (int f = 0; f < num_faces; ++f) {
      if (!surface.is_hole(PtexFaceId(f))) plan.log2[f] = static_cast<std::uint8_t>(Log2Of(fixed));
    }
    return plan;
  }
  plan.subdivision_level = SubdivisionLevel(surface, sculpt);
  // The sculpt's density, which only a sculpt that is not the base refined needs (a pass over
  // every sculpt face).
  if (plan.subdivision_level < 0) {
    plan.sculpt_area = MeshArea(sculpt);
    for (std::size_t f = 0; f < sculpt.num_faces(); ++f) {
      plan.sculpt_quads += 0.5 * (sculpt.face_size(f) - 2);
    }
  }
  const double density = plan.sculpt_area > 0 ? plan.sculpt_quads / plan.sculpt_area : 0;
  for (int f = 0; f < num_faces; ++f) {
    PtexFaceId face(f);
    if (surface.is_hole(face)) continue;
    int log2;
    if (plan.subdivision_level >= 0) {
      bool subface = surface.base_face_size(surface.base_face(face)) != 4;
      log2 = plan.subdivision_level + (subface ? 0 : 1);
    } else {
      double quads = density * face_areas[static_cast<std::size_t>(f)];
      double side = 2.0 * std::sqrt(std::max(quads, 0.0));
      log2 = side > 1 ? static_cast<int>(std::ceil(std::log2(side) - 0.25)) : 0;
    }
    plan.log2[f] = static_cast<std::uint8_t>(std::clamp(log2, min_log2, max_log2));
  }
  return plan;
}

}  // namespace dispex::extract
