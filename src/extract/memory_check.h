// The memory checks of an extraction (step 1, extract_inputs.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "dispex/extract.h"
#include "dispex/status.h"

namespace dispex::extract {

// Memory an extraction is estimated to need, in bytes: before reading, from the input file
// sizes (mesh arrays take about half an OBJ's bytes); once the sculpt is read, from its arrays,
// the correspondence's peak where a method matches it, a BVH over it (about 80 bytes per
// primitive at medium quality, with its build) and the output's compressed blocks. A check
// fails with a message giving the estimate and the limit; `given`: the limit is max_memory's,
// else what the machine has available. Before reading, a PLY sculpt is also checked by its
// header's counts.
Status CheckMemoryBeforeReading(const ExtractOptions& options, std::uint64_t limit);
// Whether the run's method matches the sculpt to the base (counting the correspondence's peak).
bool MatchesSculpt(const ExtractOptions& options);
// Reading's peak as CheckMemoryBeforeReading estimates it, from the files' sizes.
std::uint64_t ReadPeakBytes(const ExtractOptions& options);

struct MemoryNeed {
  std::uint64_t arrays = 0;       // the sculpt's vertex and face arrays
  std::uint64_t vertex_map = 0;   // renumbering and flags to take a part of it (SculptPart)
  std::uint64_t match = 0;        // the correspondence at its peak (0: the method does not match)
  std::uint64_t bvh = 0;          // a BVH of the whole sculpt
  std::uint64_t compact_bvh = 0;  // the same built compact at medium quality
  std::uint64_t output = 0;       // the map's blocks at most
};
// The most texels an output estimate counts (EstimateMemory's max_texels).
inline constexpr std::uint64_t kMaxEstimatedTexels = std::uint64_t{1} << 31;
MemoryNeed EstimateMemory(std::size_t sculpt_vertices, std::size_t sculpt_faces,
                          std::size_t sculpt_indices, std::uint64_t max_texels, bool matches);

// What every plan needs (arrays, the match, the output): over `limit` (0: none), an error.
Status CheckMemoryForSculpt(const MemoryNeed& need, std::size_t sculpt_faces, std::uint64_t limit,
                            bool given);

// How a rays extraction keeps within `limit` (0: none): the whole sculpt's BVH when it fits
// (parts = 1), else the same built compact when that fits (compact_bvh: medium quality, about
// half the memory, the same hits), else the faces traced in runs, one BVH of the sculpt within
// reach of a run at a time, each of at most part_faces sculpt faces (about `parts` of them).
// Over the limit even with kMaxSculptParts, an error. `*estimate`: the plan's need.
inline constexpr int kMaxSculptParts = 64;
struct SculptParts {
  int parts = 1;
  std::size_t part_faces = 0;
  bool compact_bvh = false;
};
StatusOr<SculptParts> SculptPartsWithin(const MemoryNeed& need, std::size_t sculpt_faces,
                                        std::uint64_t limit, bool given, std::uint64_t* estimate);

}  // namespace dispex::extract
