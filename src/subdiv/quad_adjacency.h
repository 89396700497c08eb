// Edge adjacency of an all-quad mesh (a sculpt that may be a refined cage), by half-edges.
//
// Half-edge 4 f + k runs from corner k of quad f to corner k + 1 (mod 4); it starts at vertex
// mesh.face_indices[4 f + k]. Built in parallel from the half-edges bucketed by start vertex
// (no map per edge), each vertex's edges resolved from its own bucket, a pass of vertices at a
// time: 16 bytes per quad, 11 per vertex and one pass's bucket at the peak (at most 128 MB by
// default), 16 per quad and 7 per vertex after.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/default_init_allocator.h"
#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex::subdiv {

inline constexpr std::uint32_t kNoHalfEdge = std::numeric_limits<std::uint32_t>::max();

struct QuadAdjacency {
  // Per half-edge: the half-edge of the neighbouring quad that runs the same edge the other
  // way, or kNoHalfEdge on a boundary.
  std::vector<std::uint32_t, DefaultInitAllocator<std::uint32_t>> opposite;
  // Per vertex: the lowest half-edge starting there, the number of quads using it (at most
  // 65535: larger counts are clamped) and whether a boundary edge ends there.
  std::vector<std::uint32_t> first_half_edge;
  std::vector<std::uint16_t> valence;
  std::vector<std::uint8_t> boundary;

  // The half-edges of a quad: the next and previous one around it.
  static std::uint32_t Next(std::uint32_t h) { return (h & ~3u) | ((h + 1) & 3u); }
  static std::uint32_t Prev(std::uint32_t h) { return (h & ~3u) | ((h + 3) & 3u); }
};

// The most half-edges bucketed at once by default (128 MB).
inline constexpr std::size_t kAdjacencyBucketEntries = std::size_t{1} << 25;

// Requires mesh.all_quads(), indices in range and fewer than 2^30 faces. Fails with one line
// starting with mesh.source, naming the lowest offending element, when a quad repeats a
// vertex, a vertex is used by no face, an edge has more than two faces, or two faces run an
// edge the same way (opposite windings). Deterministic for any thread count and any
// `bucket_entries` (> 0): each pass of vertices buckets at most that many half-edges, and reads
// every quad once more.
StatusOr<QuadAdjacency> BuildQuadAdjacency(const Mesh& mesh,
                                           std::size_t bucket_entries = kAdjacencyBucketEntries);

// Connected components of the quads through shared edges: per quad the component's index,
// components numbered in the order of their lowest quad. Deterministic for any thread count.
std::vector<std::uint32_t> QuadComponents(const QuadAdjacency& adjacency,
                                          std::uint32_t& num_components);

}  // namespace dispex::subdiv
