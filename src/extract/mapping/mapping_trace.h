// Normal queries answered through the subdivision correspondence instead of a BVH: when the
// sculpt is the base refined (MatchRefinedSculpt), a sample at (u, v) of Ptex face f lies over
// cell (floor(u m), floor(v m)) of f's m x m grid of sculpt quads, and its rays along +-n need
// only be tested against the quads of that cell and the rings of cells around it.
//
// The answers follow the Tracer's hit contract (dispex/trace.h) for the hits found: t is the
// line o + t d against the plane of the hit triangle -- v0 v1 v3 or v2 v3 v1 of the sculpt
// face's own corners, as Embree splits quads -- in double, rounded to float once; windows are
// closed; a triangle is met where the line's projection along d lies inside it or on its edges
// (edge values of the corners projected in double, each edge's from the same two projections
// whichever triangle asks, so two triangles sharing an edge never both reject a line through
// it); the policies, kNegative and kBackFace as TraceNormals sets them. Where the line passes
// within rounding of an edge, the triangle kept may be the other one than Embree's: t then
// differs by rounding (both planes hold the edge).
//
// Rings. Ring r is the cells at Chebyshev distance r from the sample's cell, continued across
// Ptex face edges (PtexAcrossEdge: faces, sub-faces, and the quad <-> sub-face halves) into the
// neighbours' grids, which meet cell for cell; around an extraordinary vertex (or a boundary
// vertex with more than two faces) the diagonal block has no lattice, so every face around the
// vertex lends its corner cells instead, at ring (distance of the sample's cell to the corner
// cell) + 1 + (the cell's distance from the vertex).
//
// Certainty. Rings are tested outward from ring 0. A sample is decided once the hit its policy
// keeps among the crossings found so far lies at least one ring inside the last ring tested
// (a miss: no hit in the window, and the line crosses a tested quad beyond the window at least
// one ring inside), up to ring kMaxRings. Samples not decided that way -- hits or crossings
// only in the outermost ring, no crossing at all, a ring reaching where the neighbourhood
// cannot be laid out, a degenerate triangle, quads tested that face the line both ways (the
// sheet folds or stands edge-on there) -- are left undecided for a BVH to answer, and so are
// all samples of faces near a quad turned over against the limit normal (MarkFolds). Then the
// decided samples whose ray window crosses any part of the sculpt outside the blocks of cells
// near them -- the other side of a thin part, a fold farther than two faces, another part
// that comes close -- are left undecided too (CheckFarSheets, far_sheets.h: boxes of 4 x 4-cell
// blocks against the windows up to the hit kept, then the quads of the blocks' quarters they
// meet).
//
// Speed. The samples of one cell go through rings 0 and 1 together (4 lanes): the cell's 4 x 4
// lattice of corners projected in float, each edge's value once, and a triangle classified as
// surely met, surely missed or unsure by a bound on the float error; only the met and the
// unsure are tested (and t computed) in double. Other samples, and those rings 0 and 1 do not
// decide, go ring by ring in double.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "dispex/correspondence.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "extract/mapping/sculpt_blocks.h"

namespace dispex::extract {

// Rings tested at most (0 = the sample's cell): a hit found in ring kMaxRings - 1 is decided.
inline constexpr int kMaxRings = 3;

// What the kernel needs of a correspondence, built once: per Ptex face its grid size and a
// cell -> sculpt face table (4 bytes per sculpt face: the face id, with the rotation of its
// corners against the cell in the top two bits).
class SculptMapping {
 public:
  // `faces`: the map's face table (adjacency). Errors: the sculpt is not all quads, has 2^30
  // faces or more, or does not fit the correspondence (one line naming it).
  static StatusOr<SculptMapping> Build(const SculptCorrespondence& correspondence,
                                       const Mesh& sculpt, std::span<const PtexFaceInfo> faces);
  // The same, taking over the correspondence's grid sizes and cell labels (no copy of them).
  static StatusOr<SculptMapping> Build(SculptCorrespondence&& correspondence, const Mesh& sculpt,
                                       std::span<const PtexFaceInfo> faces);

  int levels() const { return levels_; }
  int num_ptex_faces() const { return static_cast<int>(grid_sizes_.size()); }
  int grid_size(int face) const { return grid_sizes_[static_cast<std::size_t>(face)]; }
  // The sculpt face of cell (i, j) of Ptex face `face` and which of its corners sits at the
  // cell's (i, j) corner (SculptCorrespondence::face_rotation, cell_labels).
  std::uint32_t cell(int face, int i, int j) const {
    return cells_[static_cast<std::size_t>(cell_offsets_[static_cast<std::size_t>(face)] +
                                           std::int64_t{j} * grid_size(face) + i)];
  }
  // Every face's cells, the faces in order and each grid row by row.
  std::span<const std::uint32_t> cells() const { return cells_; }
  static int FaceOf(std::uint32_t cell) { return static_cast<int>(cell & 0x3fffffffu); }
  static int RotationOf(std::uint32_t cell) { return static_cast<int>(cell >> 30); }
  // The (m + 1)^2 sculpt vertices of face `face`'s grid (m = grid_size(face) > 0) row by row,
  // vertex (a, b) at b (m + 1) + a, read from its cells' corners.
  void GridVertices(int face, const Mesh& sculpt, std::vector<VertexId>& out) const;
  // Vertex (a, b) of that grid alone, 0 <= a, b <= m.
  VertexId GridVertex(int face, int a, int b, const Mesh& sculpt) const;
  std::size_t bytes() const;

  // Ptex faces whose samples all go to a BVH: within two faces of a sculpt quad turned over
  // against the limit normal (MarkFolds), where a folded sheet can lie over samples far outside
  // their rings.
  bool fold_risk(int face) const {
    return !fold_risk_.empty() && fold_risk_[static_cast<std::size_t>(face)] != 0;
  }
  // Finds them: the limit normal at every cell's centre against its quad's normal (the cross
  // product of its diagonals). The same for any thread count.
  Status MarkFolds(const LimitSurface& surface, const Mesh& sculpt,
                   std::span<const PtexFaceInfo> faces);
  std::size_t fold_risk_faces() const;

  // The boxes of blocks of cells (SculptBlocks) that decided samples are checked against for
  // sculpt outside the blocks near them (far_sheets.h); built by BuildBlocks.
  void BuildBlocks(const Mesh& sculpt) { blocks_ = SculptBlocks::Build(*this, sculpt); }
  const SculptBlocks& blocks() const { return blocks_; }

  // Edge `edge` of Ptex face `face` into its neighbour's grid: points p of the face's grid in
  // half-cell units (vertex (i, j) at (2i, 2j)) are R p + (tx, ty) there, R a rotation by q
  // quarter turns.
  struct Crossing {
    std::int32_t to = -1;
    std::uint8_t kind = 0;  // 0: no neighbour with a surface, 1: `to`, 2: not laid out
    std::uint8_t q = 0;
    std::int32_t tx = 0, ty = 0;
    bool leads() const { return kind == 1 && to >= 0; }  // into face `to`'s grid
  };
  const Crossing& crossing(int face, int edge) const {
    return crossings_[4 * static_cast<std::size_t>(face) + static_cast<std::size_t>(edge)];
  }
  // Where point (x, y) of a face's grid, in half-cell units, lies in the grid of the face
  // `crossing` leads to.
  static std::array<int, 2> CrossEdge(const Crossing& crossing, int x, int y);
  // The crossings of every Ptex face's edges for grids of these sizes, 4 per face (the
  // default Crossing for a hole face): what Build keeps, for users of a correspondence alone.
  static std::vector<Crossing> Crossings(std::span<const PtexFaceInfo> faces,
                                         std::span<const std::int32_t> sizes);

 private:
  int levels_ = 0;
  std::vector<std::int32_t> grid_sizes_;
  std::vector<std::int64_t> cell_offsets_;
  std::vector<std::uint32_t> cells_;
  std::vector<Crossing> crossings_;      // 4 per Ptex face
  std::vector<std::uint8_t> fold_risk_;  // per Ptex face, once MarkFolds ran
  SculptBlocks blocks_;
};

// What TraceMapped did, added up per thread.
struct MappingCounters {
  std::uint64_t queries = 0;     // samples given
  std::uint64_t decided = 0;     // of those, answered (hit or miss)
  std::uint64_t quads = 0;       // sculpt quads tested
  std::uint64_t far_sheets = 0;  // of the decided, left undecided by CheckFarSheets
  MappingCounters& operator+=(const MappingCounters& other);
};

// Whether this CPU runs the kernel that traces two blocks of samples at once (AVX2 on x86-64),
// unless the environment variable DISPEX_MAPPING_KERNEL is "sse2": the 4-lane kernel alone,
// which every x86-64 CPU runs. Both answer alike.
bool PairedBlocksByDefault();

// Per-thread buffers: the neighbourhood of the face last traced (kept while the same face is
// traced again, e.g. for a second search) and the rings' scratch. Never shrinks.
struct MappingScratch {
  // Trace blocks of samples two at a time (PairedBlocksByDefault); false on a CPU without it.
  bool paired_blocks = PairedBlocksByDefault();
  struct Slot {
    std::int32_t face = -1;   // sculpt face
    std::uint8_t corner = 0;  // which of its corners sits at the slot's lower-left corner
    std::uint8_t state = 0;   // SlotState (mapping_lattice.h)
  };
  struct FanCell {
    std::int32_t face = -1;
    std::int32_t offset = 0;  // Chebyshev distance of the cell from the vertex, in cells
  };
  int face = -1;                 // the face the apron is laid out for (-1: none)
  int lattice_face = -1;         // the face `lattice` holds (-1: none)
  bool margins = false;          // whether the apron holds the slots beyond the face
  int m = 0;                     // its grid size
  std::vector<Slot> apron;       // (m + 2 kMaxRings)^2 slots, row by row
  std::vector<FanCell> fans[4];  // per corner of the face: cells of every face around it
  bool fan_corner[4] = {false, false, false, false};
  std::vector<std::pair<int, int>> around;  // faces around a corner, while laying out
  // The apron's vertices, (m + 2 kMaxRings + 1)^2 points xyz, relative to `centre` (a vertex
  // of the face), for the float filter; `extent`: their largest |coordinate|.
  std::vector<float> lattice;
  double centre[3] = {0, 0, 0};
  float extent = 0;
  std::vector<int> first_sample;  // per cell row: its first sample row
  // The blocks near each block of the face (far_sheets.h), laid out for `near_face`: per slot
  // of its (M + 2)^2 block grid with a margin of one block (M blocks per side), the ids of the
  // sculpt blocks there at near_ids[near_starts[s] .. near_starts[s + 1]).
  int near_face = -1;
  std::vector<std::int32_t> near_starts;
  std::vector<std::int64_t> near_ids;
  // The check's buffers: the samples grouped by block of the face, and a block's candidates.
  std::vector<std::int32_t> sample_block_of;  // per sample column (row): its block of cells
  std::vector<std::int32_t> block_first, block_fill, block_samples;
  std::vector<std::int64_t> candidate_ids;
  // The window boxes of a block's samples, four samples a group: lower x, y, z then upper x, y,
  // z, four lanes each (24 floats a group); a sample with no window to check has an empty box.
  std::vector<float> window_boxes;
  std::vector<std::uint32_t> near_stamp;  // per sculpt block: the stamp of the last block near it
  std::uint32_t stamp = 0;
};

// Lays out scratch.near_* for `face` (after LayOut's corners): each block slot's sculpt
// blocks, found cell by cell across Ptex face edges as the rings cross them, and at an
// extraordinary corner the corner blocks of every face around it.
void LayOutNearBlocks(const SculptMapping& mapping, int face, MappingScratch& scratch);

// The quads of one sculpt block (SculptBlocks), gathered once for every window tested against
// it: per cell (i, j), row by row, its sculpt face and the lattice point at each of the face's
// corners; the points (each vertex once where neighbouring cells share it); and the boxes of
// the block's quarters of cells (cell (i, j) in quarter (2 j / b) * 2 + 2 i / b; one quarter
// when b = 1), exact boxes of their cells' corners.
struct BlockQuads {
  static constexpr int kCells = SculptBlocks::kBlock * SculptBlocks::kBlock;
  int b = 0;
  int quarters() const { return b == 1 ? 1 : 4; }
  std::int32_t face[kCells];
  std::uint8_t corner_point[kCells][4];
  std::uint8_t quarter_of[kCells];
  int num_points = 0;
  Float3 points[4 * kCells];
  Box quarter_box[4];
};
void GatherBlockQuads(const SculptMapping& mapping, const Mesh& sculpt, std::int64_t block,
                      BlockQuads& out);

// Whether the line origin + t normal crosses a quad of the cells of `quads` in the quarters
// set in `quarters` (bit q for quarter q) at |t| <= window, tested as the rings test quads (a
// triangle with no plane counts as crossed).
bool WindowCrossesQuads(const BlockQuads& quads, const Mesh& sculpt, unsigned quarters,
                        const Float3& origin, const Float3& normal, float window);

// The normal queries of samples `samples` (grid indices j * n + i of face `face`'s n x n
// grid of texel centres ((i + 0.5) / n, (j + 0.5) / n); all n * n when empty) of `origins` and
// unit `normals` (both n * n, indexed by grid index) against the sculpt through `mapping`.
// Decided samples get out.t / out.flags (and out.prim when not empty) at their grid index as
// Tracer::TraceNormals sets them and undecided[k] = 0; the others undecided[k] = 1, out
// untouched. `sculpt` is the matched mesh. Every sample of a face at risk of folds
// (SculptMapping::fold_risk) is undecided, and so is every sample whose window crosses a quad
// of a sculpt block not near it (CheckFarSheets, when BuildBlocks ran).
void TraceMapped(const SculptMapping& mapping, const Mesh& sculpt, PtexFaceId face, int n,
                 std::span<const std::int32_t> samples, std::span<const Float3> origins,
                 std::span<const Float3> normals, const NormalQuery& query, const NormalHits& out,
                 std::span<std::uint8_t> undecided, MappingScratch& scratch,
                 MappingCounters& counters);

}  // namespace dispex::extract
