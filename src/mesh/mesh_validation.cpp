// ValidateMesh and RequireClean.
//
// Edges are found without hashing or a global sort: every face side (a, b) goes into the
// bucket of its smaller vertex (a counting sort, CSR like the faces), storing the larger
// vertex and the side's direction. Each bucket holds about a vertex's valence of entries, so
// sorting it is cheap, and equal neighbours in a sorted bucket are the uses of one edge:
// 1 use is a boundary edge, more than 2 a non-manifold edge, and 2 uses in the same
// direction an inconsistently wound edge. Buckets are filled in parallel (atomic cursors) and
// sorted, so the result does not depend on the thread count.
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/check.h"
#include "dispex/mesh.h"

namespace dispex {
namespace {

constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();

// A count and the smallest key (element id or packed edge) among the offenders.
struct Tally {
  std::size_t count = 0;
  std::uint64_t first = kNone;

  void Add(std::uint64_t key) {
    ++count;
    first = std::min(first, key);
  }
  void Merge(const Tally& other) {
    count += other.count;
    first = std::min(first, other.first);
  }
};

bool HasRepeatedVertex(std::span<const std::int32_t> face) {
  for (std::size_t i = 1; i < face.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (face[i] == face[j]) return true;
    }
  }
  return false;
}

// The faces that have the side (a, b) or (b, a), as "f1, f2, ..." (at most `limit`).
std::string FacesWithEdge(const Mesh& mesh, std::int32_t a, std::int32_t b, int limit = 4) {
  std::string out;
  int found = 0;
  for (std::size_t f = 0; f < mesh.num_faces() && found <= limit; ++f) {
    const auto face = mesh.face(f);
    for (std::size_t i = 0; i < face.size(); ++i) {
      const std::int32_t u = face[i], v = face[(i + 1) % face.size()];
      if ((u == a && v == b) || (u == b && v == a)) {
        if (found == limit) {
          out += ", ...";
        } else {
          out += fmt::format("{}{}", found > 0 ? ", " : "", f);
        }
        ++found;
        break;
      }
    }
  }
  return out;
}

struct EdgeTallies {
  Tally boundary, non_manifold, inconsistent;

  void Merge(const EdgeTallies& o) {
    boundary.Merge(o.boundary);
    non_manifold.Merge(o.non_manifold);
    inconsistent.Merge(o.inconsistent);
  }
};

std::uint64_t EdgeKey(std::uint32_t v0, std::uint32_t v1) {
  return (std::uint64_t{v0} << 32) | v1;
}

EdgeTallies AnalyseEdges(const Mesh& mesh) {
  const std::size_t num_vertices = mesh.num_vertices();
  const std::size_t num_faces = mesh.num_faces();
  // bucket_end[v + 1] counts, then (prefix sum) ends the bucket of vertex v.
  std::vector<std::uint32_t> bucket(num_vertices + 1, 0);
  auto for_each_side = [&](auto&& visit) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_faces, 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t f = r.begin(); f < r.end(); ++f) {
                          const auto face = mesh.face(f);
                          const std::size_t n = face.size();
                          for (std::size_t i = 0; i < n; ++i) {
                            const std::int32_t a = face[i], b = face[i + 1 < n ? i + 1 : 0];
                            if (a != b) visit(a, b);
                          }
                        }
                      });
  };
  for_each_side([&](std::int32_t a, std::int32_t b) {
    std::atomic_ref<std::uint32_t>(bucket[static_cast<std::size_t>(std::min(a, b)) + 1])
        .fetch_add(1, std::memory_order_relaxed);
  });
  for (std::size_t v = 1; v <= num_vertices; ++v) bucket[v] += bucket[v - 1];
  // Entry: larger vertex << 1 | direction (1 when the side runs from the larger vertex).
  std::vector<std::uint32_t> entries(bucket[num_vertices]);
  for_each_side([&](std::int32_t a, std::int32_t b) {
    const std::uint32_t lo = static_cast<std::uint32_t>(std::min(a, b));
    const std::uint32_t hi = static_cast<std::uint32_t>(std::max(a, b));
    const std::uint32_t slot =
        std::atomic_ref<std::uint32_t>(bucket[lo]).fetch_add(1, std::memory_order_relaxed);
    entries[slot] = (hi << 1) | (a > b ? 1u : 0u);
  });
  // Now bucket[v] is the end of v's entries and bucket[v - 1] (or 0) their start.
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, num_vertices, 1024), EdgeTallies{},
      [&](const tbb::blocked_range<std::size_t>& r, EdgeTallies t) {
        for (std::size_t v = r.begin(); v < r.end(); ++v) {
          const std::uint32_t begin = v == 0 ? 0 : bucket[v - 1];
          const std::uint32_t end = bucket[v];
          std::uint32_t* e = entries.data();
          std::sort(e + begin, e + end);
          for (std::uint32_t i = begin; i < end;) {
            std::uint32_t j = i + 1;
            while (j < end && (e[j] >> 1) == (e[i] >> 1)) ++j;
            const std::uint64_t key = EdgeKey(static_cast<std::uint32_t>(v), e[i] >> 1);
            const std::uint32_t uses = j - i;
            if (uses == 1) {
              t.boundary.Add(key);
            } else if (uses > 2) {
              t.non_manifold.Add(key);
            } else if ((e[i] & 1u) == (e[i + 1] & 1u)) {
              t.inconsistent.Add(key);
            }
            i = j;
          }
        }
        return t;
      },
      [](EdgeTallies a, const EdgeTallies& b) {
        a.Merge(b);
        return a;
      });
}

std::string EdgeWarning(const Mesh& mesh, const Tally& tally, const char* what) {
  const auto v0 = static_cast<std::int32_t>(tally.first >> 32);
  const auto v1 = static_cast<std::int32_t>(tally.first & 0xffffffffu);
  return fmt::format("{} {} (first: edge {}-{}, faces {})", tally.count, what, v0, v1,
                     FacesWithEdge(mesh, v0, v1));
}

}  // namespace

MeshValidation ValidateMesh(const Mesh& mesh) {
  MeshValidation result;
  const std::size_t num_vertices = mesh.num_vertices();
  const std::size_t num_faces = mesh.num_faces();

  // Unreferenced vertices.
  std::vector<std::uint8_t> used(num_vertices, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.face_indices.size(), 1 << 16),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i < r.end(); ++i) {
                        const auto v = static_cast<std::uint32_t>(mesh.face_indices[i]);
                        DISPEX_CHECK_LT(v, num_vertices);  // Mesh invariant, not file input
                        std::atomic_ref<std::uint8_t>(used[v]).store(1, std::memory_order_relaxed);
                      }
                    });
  Tally unreferenced;
  for (std::size_t v = 0; v < num_vertices; ++v) {
    if (!used[v]) unreferenced.Add(v);
  }
  result.unreferenced_vertices = unreferenced.count;

  // Degenerate faces.
  const Tally degenerate = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, num_faces, 4096), Tally{},
      [&](const tbb::blocked_range<std::size_t>& r, Tally t) {
        for (std::size_t f = r.begin(); f < r.end(); ++f) {
          if (HasRepeatedVertex(mesh.face(f))) t.Add(f);
        }
        return t;
      },
      [](Tally a, const Tally& b) {
        a.Merge(b);
        return a;
      });
  result.degenerate_faces = degenerate.count;

  const EdgeTallies edges = AnalyseEdges(mesh);
  result.non_manifold_edges = edges.non_manifold.count;
  result.inconsistent_edges = edges.inconsistent.count;
  result.boundary_edges = edges.boundary.count;

  if (unreferenced.count > 0) {
    result.warnings.push_back(fmt::format("{} unreferenced vertices (first: vertex {})",
                                          unreferenced.count, unreferenced.first));
  }
  if (degenerate.count > 0) {
    const auto face = mesh.face(degenerate.first);
    result.warnings.push_back(
        fmt::format("{} degenerate faces with a repeated vertex (first: "
                    "face {}: vertices {})",
                    degenerate.count, degenerate.first, fmt::join(face.begin(), face.end(), " ")));
  }
  if (edges.non_manifold.count > 0) {
    result.warnings.push_back(
        EdgeWarning(mesh, edges.non_manifold, "non-manifold edges used by more than two faces"));
  }
  if (edges.inconsistent.count > 0) {
    result.warnings.push_back(EdgeWarning(
        mesh, edges.inconsistent, "inconsistently wound edges (both faces run the same way)"));
  }
  return result;
}

Status RequireClean(const Mesh& mesh, const MeshValidation& validation) {
  if (validation.clean()) return Status::Ok();
  return Status::Error(
      fmt::format("{}: mesh is not clean: {}", mesh.source, fmt::join(validation.warnings, "; ")));
}

}  // namespace dispex
