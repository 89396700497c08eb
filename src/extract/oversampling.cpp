#include "extract/oversampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <bit>
#include <cmath>

namespace dispex {

namespace {

int Log2Of(int power_of_two) { return std::countr_zero(static_cast<unsigned>(power_of_two)); }

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

double MeshArea(const Mesh& mesh) {
  const std::size_t n = mesh.num_faces();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double sum) {
        for (std::size_t f = range.begin(); f < range.end(); ++f) {
          auto face = mesh.face(f);
          const Float3& a = mesh.positions[static_cast<std::size_t>(face[0])];
          for (std::size_t k = 1; k + 1 < face.size(); ++k) {
            const Float3& b = mesh.positions[static_cast<std::size_t>(face[k])];
            const Float3& c = mesh.positions[static_cast<std::size_t>(face[k + 1])];
            double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
            double vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
            double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
            sum += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
          }
        }
        return sum;
      },
      [](double a, double b) { return a + b; });
}

OversamplingPlan PlanOversampling(const LimitSurface& surface, const Mesh& sculpt,
                                  const std::vector<double>& face_areas, int fixed,
                                  int min_samples, int max_samples) {
  OversamplingPlan plan;
  const int num_faces = surface.num_ptex_faces();
  plan.log2.assign(static_cast<std::size_t>(num_faces), 0);
  const int min_log2 = Log2Of(min_samples), max_log2 = Log2Of(max_samples);
  for (double a : face_areas) plan.base_area += a;
  plan.sculpt_area = MeshArea(sculpt);
  for (std::size_t f = 0; f < sculpt.num_faces(); ++f) {
    plan.sculpt_quads += 0.5 * (sculpt.face_size(f) - 2);
  }
  if (fixed > 0) {
    for (int f = 0; f < num_faces; ++f) {
      if (!surface.is_hole(PtexFaceId(f))) plan.log2[f] = static_cast<std::uint8_t>(Log2Of(fixed));
    }
    return plan;
  }
  plan.subdivision_level = SubdivisionLevel(surface, sculpt);
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

}  // namespace dispex
