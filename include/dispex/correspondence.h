// Subdivision correspondence: whether a sculpt is the base cage refined L times (Catmull-Clark,
// quads) with its vertices moved, and if so where every sculpt vertex sits on the base.
//
// Sculpting tools number vertices and faces their own way and may start each face's corner
// list at any corner, but they keep the topology of the refinement and the winding of the
// faces. The match is decided on the topology alone: the sculpt must be isomorphic, face for
// face and vertex for vertex with the winding kept, to the cage refined L times (holes
// dropped, as RefineUniform and MakeSculpt drop them). Positions only pick, among the
// refinement's symmetries, the labelling closest to the limit surface, and check the result.
//
// Grids (the Ptex conventions of dispex/subdiv.h): after L refinements a quad Ptex face is
// n x n sculpt quads, n = 2^L; a sub-face of an n-gon is 2^(L-1) x 2^(L-1) (so L = 0 is only
// possible when every face with a surface is a quad); a hole face has none. Grid vertex (i, j)
// of a face of size n sits at Ptex (u, v) = (i / n, j / n); vertices on a Ptex face's border
// belong to the grids of every face that meets there.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"

namespace dispex {

struct MatchOptions {
  // Levels tried, 0..max_levels; valid 0..7.
  int max_levels = 7;
  // The position check: a sculpt vertex farther than this from its home point on the limit
  // surface rejects the match (object units; 0: 15% of the base's bounding-box diagonal).
  double max_offset = 0;
  // Threads; 0: the caller's TBB arena (all cores by default). The result does not depend on it.
  int threads = 0;
  // Fill SculptCorrespondence::face_ptex, face_cell and face_rotation (cell_labels holds the
  // same facts by cell; without the tables the match needs 9 bytes per sculpt face less).
  bool face_tables = true;
  // Fill SculptCorrespondence::vertex_faces and vertex_uvs (12 bytes per sculpt vertex).
  bool vertex_homes = true;
  // A sculpt whose every face winds the other way from the cage's (flipped normals), and which
  // reversed is the cage refined, matches: SculptCorrespondence::reversed is set and the result
  // is that of the sculpt after ReverseWinding, which the caller applies to it before using
  // the two together. Otherwise such a sculpt fails, saying so.
  bool accept_reversed = false;
  // A folder where the sculpt's half-edge adjacency, which depends on its faces only and is
  // the match's largest step, and the match itself are kept for the next match of a sculpt with
  // the same faces (an incremental run after its vertices moved); "": none. The next match
  // takes the kept one when its choice among the refinement's symmetries is still the one
  // these positions make (the position check is run anew), else matches with the adjacency
  // read back. The result is the same either way.
  std::string cache_dir;
};

struct SculptCorrespondence {
  int levels = 0;  // the sculpt is the cage refined this many times
  // The sculpt matched only with every face wound the other way (MatchOptions::accept_reversed):
  // everything below is of ReverseWinding(sculpt).
  bool reversed = false;

  // Per Ptex face f: its (n+1) x (n+1) grid of sculpt vertex ids, n = grid_sizes[f]; vertex
  // (i, j), at Ptex (u, v) = (i / n, j / n), is grid_vertices[grid_offsets[f] + j * (n+1) + i].
  // Hole faces have n = 0 and no entries.
  std::vector<std::int64_t> grid_offsets;  // num_ptex_faces + 1
  std::vector<VertexId> grid_vertices;
  std::vector<std::int32_t> grid_sizes;  // per Ptex face: n

  // Per sculpt vertex: one home, in the first Ptex face (by id) whose grid holds it, and its
  // (u, v) there (2 floats per vertex, exact: multiples of 1 / n). Empty unless
  // MatchOptions::vertex_homes.
  std::vector<PtexFaceId> vertex_faces;
  std::vector<float> vertex_uvs;

  // Per sculpt face: its Ptex face, its cell (i, j) there as face_cell = i + j * n, and which
  // of its corners sits at the cell's (i, j) corner: the cell's corners (i,j), (i+1,j),
  // (i+1,j+1), (i,j+1) are the face's corners r, r+1, r+2, r+3 (mod 4), r = face_rotation.
  // Empty unless MatchOptions::face_tables.
  std::vector<PtexFaceId> face_ptex;
  std::vector<std::int32_t> face_cell;
  std::vector<std::uint8_t> face_rotation;
  // The same by cell, the Ptex faces in order and each grid's cells row by row (cell (i, j) of
  // Ptex face f at the sum of grid_sizes[g]^2 over g < f, plus i + j * n): 4 x the sculpt
  // face there + its face_rotation.
  std::vector<std::uint32_t> cell_labels;

  std::size_t components = 0;         // connected components matched (edge-connected)
  bool adjacency_from_cache = false;  // read from MatchOptions::cache_dir, not built
  // The labelling was kept in MatchOptions::cache_dir by a match of a sculpt with the same
  // faces, and its seeds are still those chosen with these positions: no adjacency was needed.
  bool labelling_from_cache = false;

  // The position check: |sculpt vertex - limit point at its home| over the vertices checked,
  // each once, at its home: every vertex of grids up to 8 x 8; on larger grids those on the
  // border and on every (n / 8)-th row and column (a quarter of them on large grids).
  std::size_t checked_vertices = 0;
  // With labelling_from_cache: the Ptex faces whose checked vertices moved since the match was
  // kept, measured again (the others take what was measured then).
  std::size_t faces_checked_again = 0;
  double max_offset = 0, rms_offset = 0;
  VertexId worst_vertex;    // the vertex of max_offset
  double offset_limit = 0;  // the bound in use (MatchOptions::max_offset or its default)
  double seconds = 0;

  int grid_size(PtexFaceId face) const { return grid_sizes[face.value]; }
  // Precondition: 0 <= i, j <= grid_size(face).
  // Face `face`'s grid of (n+1)^2 vertices, row by row (empty for a hole).
  std::span<const VertexId> grid(PtexFaceId face) const {
    const auto first = static_cast<std::size_t>(grid_offsets[face.value]);
    return std::span(grid_vertices)
        .subspan(first, static_cast<std::size_t>(grid_offsets[face.value + 1]) - first);
  }
  VertexId vertex(PtexFaceId face, int i, int j) const {
    const int n = grid_sizes[face.value];
    return grid_vertices[grid_offsets[face.value] + static_cast<std::int64_t>(j) * (n + 1) + i];
  }
};

// The sculpt surface at (u, v) of Ptex face `face`: bilinear interpolation over the sculpt
// quad of the face's grid that contains (u, v): cell i = min(floor(u n), n - 1), local
// s = u n - i, likewise j and t from v. (u, v) are clamped to [0, 1]. Preconditions: `face`
// is not a hole (grid_size > 0) and `sculpt` is the mesh that was matched.
Float3 SculptPointAt(const SculptCorrespondence& correspondence, const Mesh& sculpt,
                     PtexFaceId face, float u, float v);

// The correspondence of `sculpt` to `surface` (the base cage's limit surface), or a Status
// whose one-line message starts with the sculpt's source and says why the sculpt is not the
// base refined: the sculpt has a face that is not a quad, or a vertex no face uses; its counts
// fit no level; an edge of it has more than two faces, or two faces run it the same way; its
// connected components differ from the base's; vertex V has valence k where base vertex W has
// k'; face F does not fit the grid of Ptex face P; every face winds the other way (flipped
// normals: the sculpt is matched once more with its faces reversed to tell so); the position
// check failed (vertex V is D from its home on Ptex face P, more than the limit, or no vertex
// of a base vertex's valence is within the limit of its limit point). A cage the match cannot
// work on fails with a message starting with the cage's source: an edge with more than two
// faces, or two faces running an edge the same way. Bad options fail too.
//
// Topology decides; positions only choose among the refinement's symmetries (the labelling
// whose offsets at the base vertices, across the limit normal above all, are least) and bound
// the result.
//
// Runs on options.threads threads; the result is the same for any thread count. Memory
// besides the sculpt: about 40 bytes per sculpt face at the peak (its half-edge adjacency),
// of which the result keeps about 29 (20 without the face tables).
StatusOr<SculptCorrespondence> MatchRefinedSculpt(const LimitSurface& surface, const Mesh& sculpt,
                                                  const MatchOptions& options = {});

}  // namespace dispex
