// The Catmull-Clark limit surface of a base cage: topology, Ptex face ids, and evaluation of
// limit points and unit normals on Ptex faces (OpenSubdiv Far + Bfr, behind a pimpl).
//
// Ptex faces follow OpenSubdiv's Far::PtexIndices: a quad base face is one Ptex face; a face
// of n != 4 vertices is n quad sub-faces, one per corner, numbered consecutively from the
// face's first Ptex face. A Ptex face's (u,v) runs u along its first edge and v along its
// last edge reversed; sub-face k of an n-gon has its origin at the face's vertex k, u towards
// the midpoint of edge k (v_k -> v_k+1), v towards the midpoint of edge k-1, and the face
// centre at (1,1).
//
// Texel centres: texel (i,j) of an rx x ry grid samples (u,v) = ((i+0.5)/rx, (j+0.5)/ry);
// outputs are row-major with i fastest (rows of constant v), xyz interleaved, as Ptex stores
// texels. Normals are normalize(cross(dP/du, dP/dv)), outward for counter-clockwise faces.
//
// Errors are Status values whose message starts with the cage's file name; element numbers
// (faces, vertices, tags) in messages are 0-based.
//
// Thread safety: a LimitSurface is immutable once built and may be shared by any number of
// threads; a LimitEvaluator holds per-thread scratch (its own Bfr factory and cache) and
// must not be used by two threads at once: make one per thread.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex {

struct SubdivOptions {
  // Bfr refinement levels used to represent faces around extraordinary vertices (smooth) and
  // around semi-sharp features (sharp); valid 1..10. Near an extraordinary vertex Bfr (like a
  // Far::PatchTable) ends the refinement with Gregory patches, which approximate the limit:
  // with OpenSubdiv's default (2), points move by ~2e-3 of the bounding-box diagonal from the
  // level-10 surface; at 6 still by up to ~3e-4 (normals ~8e-4 rad) on small cages; the
  // difference shrinks geometrically with the level. The level does not change the
  // evaluation speed (docs/bench-notes/subdiv.md), so the default is the deepest, 10.
  int approx_level_smooth = 10;
  // 0: automatic, max(approx_level_smooth, ceil(largest semi-sharp crease or corner
  // sharpness)), at most 10.
  int approx_level_sharp = 0;
  // Evaluate regular faces (a single bicubic B-spline patch) with a separable Bezier
  // evaluation instead of Bfr per sample. Same results to rounding; off only for comparison.
  bool regular_fast_path = true;
};

// Ptex adjacency of one Ptex face, exactly as Far::PtexIndices::GetAdjacency returns it:
// for each edge e (0: v=0, 1: u=1, 2: v=1, 3: u=0), the adjacent Ptex face (invalid on
// boundary and non-manifold edges) and the edge of that face that is shared.
struct PtexAdjacency {
  std::array<PtexFaceId, 4> faces;
  std::array<std::int8_t, 4> edges{};
};

// An edge of the cage by its two vertices (as they appear in the faces).
struct CageEdge {
  VertexId v0, v1;
};

// Counts of interest in messages and reports.
struct LimitSurfaceStats {
  int base_faces = 0;
  int ptex_faces = 0;
  int hole_ptex_faces = 0;       // Ptex faces without a limit surface
  int irregular_base_faces = 0;  // non-quads
  int inf_sharp_edges = 0;       // interior edges whose limit normal has two values
  int non_manifold_edges = 0;    // edges with more than two faces (sharpened by OpenSubdiv)
  // Base faces near interior valence-2 vertices, which OpenSubdiv 3.5's Bfr mishandles:
  // evaluated through a Far::PatchTable at the same levels instead (same surface, slower).
  int patch_table_faces = 0;
  int approx_level_smooth = 0;  // levels in use
  int approx_level_sharp = 0;
};

class LimitSurface {
 public:
  // Builds the Catmull-Clark topology of `cage` with its subdivision tags (creases and
  // corners, semi-sharp or infinite with sharpness >= 10, holes, boundary interpolation;
  // face-varying settings are ignored). Fails with a Status naming the face, edge or vertex
  // for: no faces, malformed CSR arrays, faces of fewer than 3 vertices, vertex indices out
  // of range, a vertex repeated within a face, non-finite positions, crease tags that are not
  // edges of the mesh or have bad sharpness, corner/hole tags out of range, and any topology
  // OpenSubdiv itself rejects. The cage is copied; it need not outlive the surface.
  static StatusOr<LimitSurface> Build(const Mesh& cage, const SubdivOptions& options = {});

  LimitSurface(LimitSurface&&) noexcept;
  LimitSurface& operator=(LimitSurface&&) noexcept;
  ~LimitSurface();

  const std::string& source() const;  // the cage's file name, for messages
  const SubdivOptions& options() const;
  LimitSurfaceStats stats() const;

  int num_vertices() const;
  int num_base_faces() const;
  int num_ptex_faces() const;

  // Preconditions (asserted): ids in range.
  BaseFaceId base_face(PtexFaceId face) const;
  // 0 for a quad; the corner k for sub-face k of an n-gon.
  int sub_face(PtexFaceId face) const;
  PtexFaceId first_ptex_face(BaseFaceId face) const;
  // 1 for a quad, n for an n-gon.
  int num_ptex_faces(BaseFaceId face) const;
  // The number of vertices of a base face.
  int base_face_size(BaseFaceId face) const;
  // True when the Ptex face has no limit surface (a tagged hole, or a face that boundary
  // interpolation "none" leaves without surface): callers skip it; evaluation fails on it.
  bool is_hole(PtexFaceId face) const;
  const PtexAdjacency& adjacency(PtexFaceId face) const;

  // Interior edges with infinite sharpness (crease tags >= 10 and non-manifold edges): the
  // limit normal has two (or more) values across them, so displacing along either opens a
  // gap or an overlap. Boundary edges are not listed.
  std::span<const CageEdge> inf_sharp_edges() const;

  struct Impl;  // defined in src/subdiv/surface_impl.h

 private:
  // Evaluators and uniform refinement read the surface's state through SurfaceImpl
  // (src/subdiv/surface_impl.h).
  friend const Impl& SurfaceImpl(const LimitSurface& surface);
  explicit LimitSurface(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// What the limit surface over each base face is made from: a 128-bit key (two halves of
// XXH3-128) of the positions of the vertices of the faces around its corners (the
// Catmull-Clark one-ring) in the ring's own numbering, the ring's topology, the sharpness of
// its edges and vertices, boundaries, non-manifold edges and holes, and the surface's global
// options (scheme options, resolved approximation levels, evaluation path); and the bounding
// box of the ring's vertices, which holds the face's limit surface (limit points are convex
// combinations of them). Equal keys on two surfaces with the same Ptex numbering mean the same
// limit surface over that face: incremental extraction re-uses a face's texels when its key,
// among others, is unchanged.
struct BaseFacePatch {
  std::array<std::uint64_t, 2> key{};
  Float3 lower, upper;
};
std::vector<BaseFacePatch> BaseFacePatches(const LimitSurface& surface);

// Counters of one evaluator, for reports and benchmarks.
struct LimitEvaluatorStats {
  std::int64_t faces = 0;          // Ptex faces evaluated
  std::int64_t regular_faces = 0;  // of which on the regular fast path
  std::int64_t samples = 0;
  std::int64_t fallback_normals = 0;  // normals from the degenerate-derivative fallback
};

// Per-thread evaluation of the limit surface: Bfr per sample, a separable Bezier evaluation
// for regular faces, a Far::PatchTable for the faces in stats().patch_table_faces. Keeps the
// Bfr surface of the last base face, so consecutive sub-faces of an n-gon share it. No
// allocation per sample; buffers grow to the largest face met and are reused.
//
// Degenerate derivatives (cross(dP/du, dP/dv) zero or not finite, e.g. collapsed control
// points): the normal is taken at points moved towards the Ptex face centre by 1e-6, 1e-4,
// 1e-2 and 0.1 of the way, then from the cage polygon (Newell normal of the base face), then
// +z. It is never NaN; such samples are counted in stats().fallback_normals.
class LimitEvaluator {
 public:
  // `surface` must outlive the evaluator (moving the LimitSurface is fine).
  explicit LimitEvaluator(const LimitSurface& surface);
  LimitEvaluator(LimitEvaluator&&) noexcept;
  LimitEvaluator& operator=(LimitEvaluator&&) noexcept;
  ~LimitEvaluator();

  // Limit positions and unit normals at the rx x ry texel centres of `face`, texel (i,j) at
  // index j*rx+i. `positions` needs 3*rx*ry floats; `normals` 3*rx*ry floats, or empty to
  // skip normals. Fails (nothing written) for an invalid or hole face, rx or ry < 1, short
  // buffers, or when OpenSubdiv cannot build the face's surface (the message names the base
  // face and quotes OpenSubdiv).
  Status EvaluateGrid(PtexFaceId face, int rx, int ry, std::span<float> positions,
                      std::span<float> normals);

  // The same at arbitrary (u,v) on one Ptex face: `uv` holds n pairs (u0,v0,u1,v1,...) in
  // [0,1]; outputs 3n floats each (normals may be empty). Coordinates outside [0,1] or not
  // finite fail with a Status naming the pair.
  Status EvaluatePoints(PtexFaceId face, std::span<const float> uv, std::span<float> positions,
                        std::span<float> normals);

  // Limit points with their frames: unit normals and the partial derivatives dP/du and dP/dv
  // with respect to the Ptex face's own (u,v) -- on an n-gon's sub-faces too, where
  // OpenSubdiv differentiates in its own sub-face coordinates (half the span, twice the
  // derivative). 3 floats per point in each output. Same grid, points and errors as above.
  struct Frames {
    std::span<float> positions, normals, du, dv;
  };
  Status EvaluateGridFrames(PtexFaceId face, int rx, int ry, Frames out);
  Status EvaluatePointFrames(PtexFaceId face, std::span<const float> uv, Frames out);

  const LimitEvaluatorStats& stats() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// ---- Uniform refinement --------------------------------------------------------------------

struct RefineOptions {
  int threads = 0;           // 0: TBB's default; results do not depend on it
  bool face_charts = false;  // also fill RefinedMesh::face_ptex / face_uvs
};

// The cage refined uniformly `levels` times with OpenSubdiv (Far::TopologyRefiner::
// RefineUniform), tags honoured, with every vertex moved to its LIMIT position.
struct RefinedMesh {
  // Level-`levels` faces in OpenSubdiv's order, winding preserved (quads for levels >= 1;
  // the cage's own faces for levels = 0). Faces of holes are dropped, and so are vertices
  // only they used (the remaining vertices keep OpenSubdiv's order). No subdivision tags.
  Mesh mesh;
  std::vector<float> normals;          // 3 per vertex: the unit limit normal there
  std::vector<PtexFaceId> ptex_faces;  // per vertex: ONE Ptex face of the cage it lies on...
  std::vector<float> uvs;              // ...and its (u,v) there, 2 per vertex
  // With RefineOptions::face_charts: per face, the cage Ptex face containing it and the
  // (u,v) of each of its 4 corners in that face (8 floats, in the face's vertex order).
  std::vector<PtexFaceId> face_ptex;
  std::vector<float> face_uvs;
  int levels = 0;
  std::size_t refined_vertices = 0;  // OpenSubdiv's level counts, before dropping holes
  std::size_t refined_faces = 0;
};

// Among the faces sharing a vertex, the vertex's (ptex face, u, v) comes from the first one
// in face order, so results are deterministic (and independent of options.threads). A vertex
// on an infinitely sharp crease gets the normal of that face's side. OpenSubdiv refines to
// level `levels`-1 and the last split is generated in OpenSubdiv's numbering, so the memory
// is about the output (36 bytes per vertex, 20 per quad) plus OpenSubdiv's topology of one
// level less: level 6 of a 17K-quad cage (71M vertices) peaks near 9 GB. Fails for levels
// outside 0..8 or when the refined mesh would exceed 2^31-1 face-vertex indices (about 537M
// quads), and when OpenSubdiv fails on a face (the message names the base face).
StatusOr<RefinedMesh> RefineUniform(const LimitSurface& surface, int levels,
                                    const RefineOptions& options = {});

// Per Ptex face of `surface` (built from `cage`), bit e set when its edge e lies on an
// infinitely sharp crease of the cage (sharpness >= 10): the limit normal, and with it any
// displacement along it, is discontinuous there.
std::vector<std::uint8_t> SharpCreaseEdges(const Mesh& cage, const LimitSurface& surface);

}  // namespace dispex
