// Sheets beyond the rings. The rings (mapping_trace.h) decide a sample from the sculpt quads
// around its own cell; another part of the sculpt -- the other side of a thin part, a fold
// farther away, two parts that come close -- can cross its ray window nearer than the hit
// they found. This check finds every decided sample whose window could meet sculpt outside
// the blocks near it and leaves it undecided, for the BVH fallback to answer:
//
// - the window: [-|t|, |t|] for a hit under HitPolicy::kNearest (nothing nearer may exist),
//   [-d, d] (d the query's distance) for a miss or the other policies; its box, o -+ w |n| per
//   axis, widened by float rounding;
// - the sculpt's blocks of 4 x 4 cells per Ptex face (SculptBlocks: exact boxes of their
//   corners, a uniform grid over them);
// - per block of the face's samples (those over one block of cells), the box of their windows
//   against the grid; a block whose box meets it and is not near (the sample block's own and
//   the 8 blocks around it, continued across Ptex face edges and extraordinary corners as the
//   rings are) is a candidate; a sample whose own window meets a candidate's box and crosses
//   one of its quads (tested as the rings test them, the window widened by rounding) is
//   undecided. The window is tested against the box first, four samples at a time, then as a
//   segment against the box and the boxes of the block's quarters (2 x 2 cells), and only the
//   quads of the quarters it meets are tested (a triangle with no plane counts as crossed
//   there). Boxes alone send samples beside thin parts and curved sheets to the BVH (980,159
//   of the Blub head benchmark asset's, bench/make-assets, against 0).
//
// Near blocks (the sample's own 3 x 3 blocks: its cell's rings and 1 to 7 cells beyond them)
// are trusted to the rings and MarkFolds: a sheet that comes back over a sample within them
// without a quad turned over against the limit normal is the one case the check does not see.
// The same for any thread count: each face's samples and the blocks are all it reads.
#pragma once

#include <cstdint>
#include <span>

#include "dispex/trace.h"
#include "extract/mapping/mapping_trace.h"

namespace dispex::extract {

// Samples of `face`'s n x n grid (`samples`, or all when empty) that TraceMapped decided
// (undecided[k] == 0, answers in `out`): those whose windows cross a quad of a sculpt block
// that is not near get undecided[k] = 1. `sculpt` is the matched mesh. Returns how many.
std::uint64_t CheckFarSheets(const SculptMapping& mapping, const Mesh& sculpt, int face, int n,
                             std::span<const std::int32_t> samples, std::span<const Float3> origins,
                             std::span<const Float3> normals, const NormalQuery& query,
                             const NormalHits& out, std::span<std::uint8_t> undecided,
                             MappingScratch& scratch);

}  // namespace dispex::extract
