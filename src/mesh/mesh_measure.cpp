// ComputeBounds, BoundingBox::diagonal, MedianEdgeLength and MeshArea.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/default_init_allocator.h"
#include "core/vec3.h"
#include "dispex/mesh.h"

namespace dispex {
namespace {

// Median of at most about this many face sides; larger meshes are sampled with a fixed stride.
constexpr std::size_t kMaxMedianSamples = std::size_t{1} << 22;

bool IsPrime(std::size_t n) {
  if (n < 2) return false;
  for (std::size_t d = 2; d * d <= n; ++d) {
    if (n % d == 0) return false;
  }
  return true;
}

// Every side when there are few; else every `stride`-th side, with a prime stride of at least 5
// so that the sample does not alias with the corners of triangles and quads (a stride of 2 or
// 4 on a quad mesh would only ever see the same two sides of every face).
std::size_t SampleStride(std::size_t sides) {
  if (sides <= kMaxMedianSamples) return 1;
  std::size_t stride =
      std::max<std::size_t>(5, (sides + kMaxMedianSamples - 1) / kMaxMedianSamples);
  while (!IsPrime(stride)) ++stride;
  return stride;
}

}  // namespace

float BoundingBox::diagonal() const {
  const double dx = double{max.x} - min.x, dy = double{max.y} - min.y, dz = double{max.z} - min.z;
  return static_cast<float>(std::sqrt(dx * dx + dy * dy + dz * dz));
}

BoundingBox ComputeBounds(const Mesh& mesh) {
  if (mesh.positions.empty()) return BoundingBox{};
  const Float3 first = mesh.positions[0];
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.positions.size(), 1 << 16), BoundingBox{first, first},
      [&](const tbb::blocked_range<std::size_t>& r, BoundingBox box) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
          const Float3& p = mesh.positions[i];
          box.min = {std::min(box.min.x, p.x), std::min(box.min.y, p.y), std::min(box.min.z, p.z)};
          box.max = {std::max(box.max.x, p.x), std::max(box.max.y, p.y), std::max(box.max.z, p.z)};
        }
        return box;
      },
      [](BoundingBox a, const BoundingBox& b) {
        a.min = {std::min(a.min.x, b.min.x), std::min(a.min.y, b.min.y),
                 std::min(a.min.z, b.min.z)};
        a.max = {std::max(a.max.x, b.max.x), std::max(a.max.y, b.max.y),
                 std::max(a.max.z, b.max.z)};
        return a;
      });
}

double MedianEdgeLength(const Mesh& mesh) {
  const std::size_t sides = mesh.face_indices.size();
  if (sides == 0) return 0;
  const std::size_t stride = SampleStride(sides);
  const std::size_t samples = (sides + stride - 1) / stride;
  // Written in full by the loop below, which first touches its pages on every thread.
  std::vector<double, DefaultInitAllocator<double>> lengths(samples);
  // Side k runs from corner k to the next corner of the same face.
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, mesh.num_faces(), 4096),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t f = r.begin(); f < r.end(); ++f) {
          const std::size_t begin = mesh.face_offsets[f];
          const std::size_t end = mesh.face_offsets[f + 1];
          // The first sampled corner of this face.
          std::size_t k = (begin + stride - 1) / stride * stride;
          for (; k < end; k += stride) {
            const std::size_t next = k + 1 < end ? k + 1 : begin;
            const Float3& a = mesh.positions[static_cast<std::size_t>(mesh.face_indices[k])];
            const Float3& b = mesh.positions[static_cast<std::size_t>(mesh.face_indices[next])];
            const double dx = double{a.x} - b.x, dy = double{a.y} - b.y, dz = double{a.z} - b.z;
            lengths[k / stride] = std::sqrt(dx * dx + dy * dy + dz * dz);
          }
        }
      });
  const std::size_t mid = samples / 2;
  std::nth_element(lengths.begin(), lengths.begin() + static_cast<std::ptrdiff_t>(mid),
                   lengths.end());
  const double upper = lengths[mid];
  if (samples % 2 == 1) return upper;
  const double lower =
      *std::max_element(lengths.begin(), lengths.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

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
            // Sides in float, as the positions are stored, then the cross product in double.
            const Vec3d u{b.x - a.x, b.y - a.y, b.z - a.z};
            const Vec3d v{c.x - a.x, c.y - a.y, c.z - a.z};
            sum += 0.5 * Length(Cross(u, v));
          }
        }
        return sum;
      },
      [](double a, double b) { return a + b; });
}

}  // namespace dispex
