#include "trace/sculpt_check.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dispex::trace {
namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

enum class FaceProblem : std::uint8_t { kOk, kOffsets, kTooFewVertices, kIndexRange };

// Result of scanning a range of faces: primitive counts and the first bad face.
struct FaceScan {
  SculptCounts counts;
  std::size_t bad_face = kNone;
  FaceProblem problem = FaceProblem::kOk;
  int corner = 0;

  void Join(const FaceScan& other) {
    counts.quads += other.counts.quads;
    counts.triangles += other.counts.triangles;
    counts.triangle_faces += other.counts.triangle_faces;
    if (other.bad_face < bad_face) {
      bad_face = other.bad_face;
      problem = other.problem;
      corner = other.corner;
    }
  }
};

bool Finite(const Float3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

std::string Source(const Mesh& mesh) {
  return mesh.source.empty() ? "sculpt" : mesh.source;
}

FaceScan ScanFaces(const Mesh& mesh) {
  const std::size_t num_faces = mesh.num_faces();
  const auto num_vertices = static_cast<std::int64_t>(mesh.num_vertices());
  const std::uint32_t* offsets = mesh.face_offsets.data();
  const std::int32_t* indices = mesh.face_indices.data();
  const std::size_t num_indices = mesh.face_indices.size();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, num_faces, 1 << 14), FaceScan{},
      [&](const tbb::blocked_range<std::size_t>& range, FaceScan scan) {
        for (std::size_t f = range.begin(); f != range.end() && f < scan.bad_face; ++f) {
          const std::uint32_t begin = offsets[f], end = offsets[f + 1];
          if (end < begin || end > num_indices) {
            scan.bad_face = f;
            scan.problem = FaceProblem::kOffsets;
            break;
          }
          const std::uint32_t size = end - begin;
          if (size < 3) {
            scan.bad_face = f;
            scan.problem = FaceProblem::kTooFewVertices;
            break;
          }
          for (std::uint32_t k = 0; k < size; ++k) {
            const std::int32_t v = indices[begin + k];
            if (v < 0 || v >= num_vertices) {
              scan.bad_face = f;
              scan.problem = FaceProblem::kIndexRange;
              scan.corner = static_cast<int>(k);
              break;
            }
          }
          if (scan.bad_face == f) break;
          if (size == 4) {
            ++scan.counts.quads;
          } else {
            scan.counts.triangles += size - 2;
            scan.counts.triangle_faces += size == 3 ? 1 : 0;
          }
        }
        return scan;
      },
      [](FaceScan a, const FaceScan& b) {
        a.Join(b);
        return a;
      });
}

// Lowest index of a vertex with a non-finite coordinate, or kNone.
std::size_t FirstNonFiniteVertex(const Mesh& mesh) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.num_vertices(), 1 << 16), kNone,
      [&](const tbb::blocked_range<std::size_t>& range, std::size_t first) {
        for (std::size_t v = range.begin(); v != range.end() && v < first; ++v) {
          if (!Finite(mesh.positions[v])) return v;
        }
        return first;
      },
      [](std::size_t a, std::size_t b) { return a < b ? a : b; });
}

// The lowest face using a non-finite vertex, and that vertex; kNone when no face uses one.
std::pair<std::size_t, std::int32_t> FirstFaceWithNonFiniteVertex(const Mesh& mesh) {
  using Found = std::pair<std::size_t, std::int32_t>;
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.num_faces(), 1 << 14), Found{kNone, -1},
      [&](const tbb::blocked_range<std::size_t>& range, Found found) {
        for (std::size_t f = range.begin(); f != range.end() && f < found.first; ++f) {
          for (const std::int32_t v : mesh.face(f)) {
            if (!Finite(mesh.positions[static_cast<std::size_t>(v)])) return Found{f, v};
          }
        }
        return found;
      },
      [](const Found& a, const Found& b) { return a.first <= b.first ? a : b; });
}

}  // namespace

Status CheckSculpt(const Mesh& mesh, SculptCounts* counts) {
  const std::string source = Source(mesh);
  const std::size_t num_faces = mesh.num_faces();
  if (num_faces == 0) return Status::Error(fmt::format("{}: the sculpt has no faces", source));
  if (mesh.face_offsets.front() != 0) {
    return Status::Error(fmt::format("{}: sculpt face offsets start at {}, not 0", source,
                                     mesh.face_offsets.front()));
  }
  if (mesh.face_offsets.back() != mesh.face_indices.size()) {
    return Status::Error(
        fmt::format("{}: sculpt face offsets end at {} but there are {} face "
                    "indices",
                    source, mesh.face_offsets.back(), mesh.face_indices.size()));
  }
  if (num_faces > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return Status::Error(fmt::format("{}: the sculpt has {} faces; at most 2^31 - 1 are supported",
                                     source, num_faces));
  }

  const FaceScan scan = ScanFaces(mesh);
  const std::size_t f = scan.bad_face;
  switch (scan.problem) {
    case FaceProblem::kOk:
      break;
    case FaceProblem::kOffsets:
      return Status::Error(fmt::format(
          "{}: sculpt face {} has malformed offsets ({} to {}, {} face indices)", source, f,
          mesh.face_offsets[f], mesh.face_offsets[f + 1], mesh.face_indices.size()));
    case FaceProblem::kTooFewVertices:
      return Status::Error(
          fmt::format("{}: sculpt face {} has {} vertices; a face needs at least 3", source, f,
                      mesh.face_size(f)));
    case FaceProblem::kIndexRange:
      return Status::Error(fmt::format(
          "{}: sculpt face {} corner {} uses vertex {}, but the sculpt has {} vertices", source, f,
          scan.corner, mesh.face(f)[static_cast<std::size_t>(scan.corner)], mesh.num_vertices()));
  }

  constexpr auto kMaxPrims = static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  if (scan.counts.triangles > kMaxPrims) {
    return Status::Error(fmt::format(
        "{}: the sculpt has {} triangles after fan-triangulating its n-gons; at most 2^31 - 1 are "
        "supported",
        source, scan.counts.triangles));
  }

  if (FirstNonFiniteVertex(mesh) != kNone) {
    const auto [face, v] = FirstFaceWithNonFiniteVertex(mesh);
    if (face != kNone) {
      const Float3& p = mesh.positions[static_cast<std::size_t>(v)];
      return Status::Error(fmt::format(
          "{}: sculpt vertex {} (used by face {}) has a non-finite position ({}, {}, {})", source,
          v, face, p.x, p.y, p.z));
    }
    // Only unused vertices are non-finite: no primitive reads them, so they are harmless.
  }

  *counts = scan.counts;
  return Status::Ok();
}

}  // namespace dispex::trace
