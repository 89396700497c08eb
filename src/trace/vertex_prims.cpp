#include "trace/vertex_prims.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <limits>
#include <span>

namespace dispex::trace {

namespace {

Float3 Normal(const Float3* p, std::int32_t a, std::int32_t b, std::int32_t c) {
  const Float3 &pa = p[a], &pb = p[b], &pc = p[c];
  const Float3 e1{pb.x - pa.x, pb.y - pa.y, pb.z - pa.z}, e2{pc.x - pa.x, pc.y - pa.y, pc.z - pa.z};
  return {e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
}

float Dot(const Float3& a, const Float3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

// Whether two of the triangles around vertex v (of the primitives `around` it, the triangles
// that hold v) face against each other.
bool Folds(const VertexPrims& vp, std::int32_t v, std::span<const std::uint32_t> around,
           const std::int32_t* quads, const std::int32_t* triangles, const Float3* p) {
  constexpr std::size_t kMost = 64;  // triangles compared around one vertex
  Float3 normals[kMost];
  std::size_t count = 0;
  for (std::uint32_t g : around) {
    if (count + 2 > kMost) break;
    if (g < vp.num_quads) {
      // A quad's triangles (c0 c1 c3) and (c2 c3 c1): v is in the first unless it is c2, in
      // the second unless it is c0.
      const std::int32_t* c = quads + 4 * static_cast<std::size_t>(g);
      if (c[2] != v) normals[count++] = Normal(p, c[0], c[1], c[3]);
      if (c[0] != v) normals[count++] = Normal(p, c[2], c[3], c[1]);
    } else {
      const std::int32_t* c = triangles + 3 * (g - vp.num_quads);
      normals[count++] = Normal(p, c[0], c[1], c[2]);
    }
  }
  if (count < 2) return false;
  // Usually every normal is within 45 degrees of the first, so no two are 90 degrees apart.
  const Float3& first = normals[0];
  const float first_length2 = Dot(first, first);
  bool near = true;
  for (std::size_t i = 1; i < count && near; ++i) {
    const float d = Dot(normals[i], first);
    near = d > 0 && d * d > 0.5f * Dot(normals[i], normals[i]) * first_length2;
  }
  if (near) return false;
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t j = i + 1; j < count; ++j) {
      if (Dot(normals[i], normals[j]) < 0) return true;
    }
  }
  return false;
}

}  // namespace

Status CheckVertexPrimsFit(std::size_t num_quads, std::size_t num_triangles) {
  const std::size_t corners = 4 * num_quads + 3 * num_triangles;
  if (corners < std::numeric_limits<std::uint32_t>::max()) return Status::Ok();
  return Status::Error(fmt::format(
      "the sculpt's {} face corners are too many for the ray tracer's vertex table", corners));
}

VertexPrims BuildVertexPrims(const std::int32_t* quads, std::size_t num_quads,
                             const std::int32_t* triangles, std::size_t num_triangles,
                             const Float3* positions, std::size_t num_vertices) {
  const std::size_t corners = 4 * num_quads + 3 * num_triangles;
  VertexPrims out;
  out.num_quads = num_quads;
  out.offsets.assign(num_vertices + 1, 0);
  // Every primitive's corners, as (global primitive, vertex) through one index.
  auto for_each_corner = [&](auto&& visit) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_quads + num_triangles, 1 << 14),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t p = range.begin(); p != range.end(); ++p) {
                          const bool quad = p < num_quads;
                          const std::int32_t* ids =
                              quad ? quads + 4 * p : triangles + 3 * (p - num_quads);
                          for (int k = 0; k < (quad ? 4 : 3); ++k) {
                            visit(static_cast<std::uint32_t>(p), static_cast<std::size_t>(ids[k]));
                          }
                        }
                      });
  };
  for_each_corner([&](std::uint32_t, std::size_t v) {
    std::atomic_ref<std::uint32_t>(out.offsets[v + 1]).fetch_add(1, std::memory_order_relaxed);
  });
  for (std::size_t v = 0; v < num_vertices; ++v) out.offsets[v + 1] += out.offsets[v];
  out.prims.resize(corners);
  std::vector<std::uint32_t> cursor(out.offsets.begin(), out.offsets.end() - 1);
  for_each_corner([&](std::uint32_t p, std::size_t v) {
    const std::uint32_t at =
        std::atomic_ref<std::uint32_t>(cursor[v]).fetch_add(1, std::memory_order_relaxed);
    out.prims[at] = p;
  });
  out.folded.assign(num_quads + num_triangles, 0);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, num_vertices, 1 << 14),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t v = range.begin(); v != range.end(); ++v) {
          const auto vertex = static_cast<std::int32_t>(v);
          const auto around = out.around(vertex);
          if (!Folds(out, vertex, around, quads, triangles, positions)) continue;
          for (std::uint32_t g : around) {
            std::atomic_ref<std::uint8_t>(out.folded[g]).store(1, std::memory_order_relaxed);
          }
        }
      });
  return out;
}

}  // namespace dispex::trace
