// The in-memory polygon mesh shared by every stage: base cages and sculpts alike.
//
// Structure of arrays: positions as float3, faces in CSR form (face_offsets has one entry
// per face plus one; face f uses face_indices[face_offsets[f] .. face_offsets[f+1])), vertex
// ids as int32 so OpenSubdiv and Embree can read the arrays without copies. Faces keep the
// winding of the file (counter-clockwise = outward).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/ids.h"
#include "dispex/status.h"

namespace dispex {

struct Float3 {
  float x = 0, y = 0, z = 0;
};

// OpenSubdiv's boundary interpolation ("t interpolateboundary N" in OBJ: 0 = none,
// 1 = edge and corner, 2 = edge only). Without a tag, edge and corner, as renderers do.
enum class BoundaryInterpolation : std::uint8_t { kNone, kEdgeOnly, kEdgeAndCorner };

// OpenSubdiv's crease rule for semi-sharp creases ("t creasemethod 0/0/1 normal|chaikin"):
// uniform decrements sharpness by 1 per level; Chaikin averages it along crease chains.
enum class CreaseMethod : std::uint8_t { kUniform, kChaikin };

// Catmull-Clark weights at triangles ("t smoothtriangles 0/0/1 catmark|smooth"): catmark, or
// OpenSubdiv's "smooth triangle" edge weights that round triangles off.
enum class TriangleSubdivision : std::uint8_t { kCatmark, kSmooth };

// Subdivision tags of a Catmull-Clark cage, as OpenSubdiv's OBJ `t` lines carry them.
struct SubdivTags {
  struct Crease {
    VertexId v0, v1;
    float sharpness = 0;  // >= 10 is infinitely sharp (Sdc::Crease::SHARPNESS_INFINITE)
  };
  struct Corner {
    VertexId vertex;
    float sharpness = 0;
  };
  std::vector<Crease> creases;
  std::vector<Corner> corners;
  std::vector<BaseFaceId> holes;
  BoundaryInterpolation boundary = BoundaryInterpolation::kEdgeAndCorner;
  bool boundary_from_file = false;  // true when a tag set it
  CreaseMethod crease_method = CreaseMethod::kUniform;
  bool crease_method_from_file = false;
  TriangleSubdivision triangles = TriangleSubdivision::kCatmark;
  bool triangles_from_file = false;
  // Names of the tag lines read but not used (face-varying settings, unknown names), one
  // entry per line in file order; bytes that are not printable ASCII become '?', names
  // longer than 64 bytes end in "...".
  std::vector<std::string> ignored_tag_names;

  bool empty() const { return creases.empty() && corners.empty() && holes.empty(); }
};

struct Mesh {
  std::string source;  // file name, for messages

  std::vector<Float3> positions;
  std::vector<std::uint32_t> face_offsets;  // num_faces() + 1 entries, starts at 0
  std::vector<std::int32_t> face_indices;   // vertex ids, face after face

  // Optional: one group id per face (index into group_names), from OBJ `o`/`g` lines.
  std::vector<std::int32_t> face_groups;
  std::vector<std::string> group_names;

  // Optional face-varying texture coordinates (OBJ `vt` and the `/vt` of face corners). Either
  // both are empty (no UVs), or face_uv_indices has one entry per entry of face_indices, laid
  // out the same way (corner c of face f at face_uv_indices[face_offsets[f] + c]), each an
  // index in [0, uvs.size() / 2) into uvs, which holds (u, v) pairs, all finite. The OBJ
  // convention: v = 0 at the bottom of the image.
  std::vector<float> uvs;
  std::vector<std::int32_t> face_uv_indices;
  // When some faces name texture coordinates and others do not, the reader keeps the mesh
  // without UVs (both arrays empty) and counts here the faces that had none; 0 otherwise.
  std::size_t faces_without_uvs = 0;
  std::size_t first_face_without_uvs = 0;  // 0-based; meaningful when faces_without_uvs > 0

  SubdivTags tags;

  std::size_t num_vertices() const { return positions.size(); }
  std::size_t num_faces() const { return face_offsets.empty() ? 0 : face_offsets.size() - 1; }
  int face_size(std::size_t f) const {
    return static_cast<int>(face_offsets[f + 1] - face_offsets[f]);
  }
  std::span<const std::int32_t> face(std::size_t f) const {
    return {face_indices.data() + face_offsets[f], face_indices.data() + face_offsets[f + 1]};
  }
  bool all_quads() const { return face_indices.size() == 4 * num_faces(); }
  bool has_uvs() const { return !face_uv_indices.empty(); }
  std::size_t num_uvs() const { return uvs.size() / 2; }
};

// Every face wound the other way: corners 1..n-1 in reverse order, corner 0 kept (texture
// coordinates with them). Tags and groups are unchanged.
void ReverseWinding(Mesh& mesh);

// ---- Reading -------------------------------------------------------------------------------

struct ReadOptions {
  int threads = 0;  // 0: the caller's TBB arena (all available cores by default)
  // Size of the pieces a text file is cut into for parallel parsing (0: 4 MiB). Cuts fall at
  // line starts, so the result never depends on it or on `threads`; tests make it small to
  // exercise the cuts.
  std::size_t chunk_bytes = 0;
};

enum class MeshFormat : std::uint8_t { kUnknown, kObj, kPly };

// The reader ReadMesh picks for `path`: PLY when the file starts with the "ply" magic line or
// is named *.ply, OBJ when named *.obj (any letter case), else kUnknown. Reads 5 bytes at most.
MeshFormat DetectMeshFormat(const std::string& path);
// The format a file's name asks for (*.obj, *.ply, any letter case), else kUnknown; reads
// nothing. WriteMesh writes it.
MeshFormat MeshFormatOfName(const std::string& path);

// What a mesh file holds, counted without reading the mesh (to plan memory before reading it):
// a PLY file's header counts, its corners taken as 4 per face (they are in the body); an OBJ's
// `v` and `f` lines and the corners on them, by the OBJ reader's counting pass. Not validated:
// a file ReadMesh refuses may be counted.
struct MeshSize {
  std::uint64_t vertices = 0, faces = 0, corners = 0;
  bool corners_counted = false;  // false: 4 per face assumed
};
StatusOr<MeshSize> CountMeshElements(const std::string& path);

// Reads an OBJ or PLY file, chosen by DetectMeshFormat (an unknown format is an error).
//
// What every reader guarantees on success: at least one face; every face has at least 3
// vertices; every index is in [0, num_vertices()); every position is finite; face_offsets
// starts at 0 and ends at face_indices.size(); positions.capacity() > positions.size() (Embree
// reads 16 bytes at the last vertex); UVs absent or consistent as Mesh::uvs states (both
// arrays empty, or one in-range UV index per corner and finite UVs); `source` is the path
// (or `name`). The result is the same
// for any ReadOptions. On failure the Status message is one line that starts with the file
// name, then the 1-based line (OBJ, ASCII PLY) or the element and its index (PLY), then what
// is wrong: "sculpt.obj:1234: face index 99 out of range (98 vertices)". Never throws for bad
// bytes, never reads out of bounds, and rejects counts the file cannot hold before allocating.
StatusOr<Mesh> ReadMesh(const std::string& path, const ReadOptions& options = {});

// Wavefront OBJ, parsed in parallel over chunks of the memory-mapped file.
//  - `v x y z [w | r g b ...]`: extra numbers are ignored; coordinates must be finite floats.
//  - `vt u [v [w]]`: texture coordinates (v defaults to 0; w and further numbers are ignored);
//    they must be finite.
//  - `f` with `i`, `i/t`, `i//n`, `i/t/n` corners and n-gons; negative indices count back from
//    the vertices (for t: the texture coordinates) defined before the line; positive ones may
//    refer to any vertex (texture coordinate) of the file. Vertex and texture indices are
//    checked against those counts ("face texture index 7 out of range (6 texture
//    coordinates)"); normal indices are checked for syntax only (they may dangle).
//  - UVs (Mesh::uvs, face_uv_indices) are kept when every face names a texture coordinate at
//    every corner. When some faces (or corners) do and others do not, the mesh is still read
//    but without UVs, and Mesh::faces_without_uvs counts the faces that had none (this reader
//    has no warning channel: callers that need UVs say why they are missing from that count).
//  - `o name` / `g name...`: a group per distinct name (blanks collapsed; no name = "default"),
//    in order of first appearance, listing only groups that own faces; faces before the first
//    group line form the group "default". With no o/g line, face_groups stays empty.
//  - OpenSubdiv `t` tags (crease, corner, hole, interpolateboundary, creasemethod,
//    smoothtriangles; other names kept in tags.ignored_tag_names) with 0-based ids checked
//    against the whole file.
//  - `#` comments, blank lines, CRLF; a `\` at the end of any line (comments too) joins the
//    next line. Every other keyword (vn, vp, usemtl, mtllib, s, l, p, ...) is ignored; a line
//    that does not start with a keyword is an error.
// Peak memory is about the final arrays: the file's pages are released as chunks are done.
StatusOr<Mesh> ReadObj(const std::string& path, const ReadOptions& options = {});

// PLY: ascii, binary_little_endian, binary_big_endian. The `vertex` element's x, y, z (any
// numeric type) and the `face` element's `vertex_indices` (or `vertex_index`) list (any
// integer count and index types) are read; other properties and elements are skipped (so are
// texture coordinates: a PLY mesh has no UVs). Binary vertex and face data are converted in
// parallel.
StatusOr<Mesh> ReadPly(const std::string& path, const ReadOptions& options = {});

// The same parsers over bytes in memory (`name` is used in messages). For tests and fuzzing.
StatusOr<Mesh> ParseObj(std::string_view bytes, const std::string& name,
                        const ReadOptions& options = {});
StatusOr<Mesh> ParsePly(std::string_view bytes, const std::string& name,
                        const ReadOptions& options = {});

// Writes `mesh` as a Wavefront OBJ (`header` verbatim, e.g. comment lines, then v and f lines,
// 1-based indices), atomically: the file appears whole or not at all. Floats are printed in their
// shortest round-trip form, so ReadObj gives back the same positions bit for bit. Faces only:
// no UVs, no subdivision tags.
Status WriteObj(const std::string& path, const Mesh& mesh, const std::string& header = {});

// Writes `mesh` as a binary little-endian PLY (float x, y, z per vertex; a face's
// vertex_indices as an int list with a uchar count, uint where a face has more than 255
// corners), atomically, with `comment` (line ends become blanks) as a comment line. ReadPly
// gives back the same positions and faces bit for bit. PLY holds neither UVs, nor
// subdivision tags, nor groups: they are not written.
Status WritePly(const std::string& path, const Mesh& mesh, std::string_view comment = {});

// A binary little-endian PLY written as it is made, for meshes too large to hold (WritePly
// writes through it): the counts go in the header first, then the vertices in order, then the
// faces. The file appears on Commit, and only when exactly the declared counts were written;
// destroyed before that, it leaves nothing (and a file already at `path` as it was).
class PlyStreamWriter {
 public:
  // `largest_face`: the most corners a face will have (255 or fewer: one-byte corner counts).
  // `comment`'s line ends become blanks.
  static StatusOr<PlyStreamWriter> Create(const std::string& path, std::size_t vertices,
                                          std::size_t faces, int largest_face,
                                          std::string_view comment = {});
  PlyStreamWriter(PlyStreamWriter&&) noexcept;
  PlyStreamWriter& operator=(PlyStreamWriter&&) noexcept;
  ~PlyStreamWriter();

  Status AddVertex(float x, float y, float z);
  // After the last vertex.
  Status AddFace(std::span<const std::int32_t> corners);
  Status Commit();

 private:
  struct Impl;
  PlyStreamWriter();
  std::unique_ptr<Impl> impl_;
};

// WritePly or WriteObj by MeshFormatOfName(path) (an unknown name is an error), with
// `comment` as one comment line.
Status WriteMesh(const std::string& path, const Mesh& mesh, std::string_view comment = {});

// ---- Validation and summary ----------------------------------------------------------------

// What the readers guarantee (ReadMesh), checked for a mesh built in memory: at least one face;
// face_offsets from 0 to face_indices.size(), each face of 3 or more vertices; vertex indices
// in range; finite positions; crease and corner vertices in range with finite sharpness >= 0,
// hole faces in range; face_groups empty or one in-range id per face; UVs absent or as
// Mesh::uvs states. The first problem, in that order, as "<source>: face 3: vertex index 9 out
// of range (8 vertices)" ("mesh" when source is empty).
Status CheckMeshArrays(const Mesh& mesh);

// What ValidateMesh finds. clean() ignores boundary edges (open meshes are fine).
struct MeshValidation {
  std::size_t unreferenced_vertices = 0;
  std::size_t degenerate_faces = 0;    // a vertex repeated within a face
  std::size_t non_manifold_edges = 0;  // edges used by more than two faces
  std::size_t inconsistent_edges = 0;  // edges two faces traverse in the same direction
  std::size_t boundary_edges = 0;
  std::vector<std::string> warnings;  // one line each, naming the first offending element

  bool clean() const {
    return unreferenced_vertices == 0 && degenerate_faces == 0 && non_manifold_edges == 0 &&
           inconsistent_edges == 0;
  }
};

// Counts the problems above and writes one warning per kind of problem that clean() rejects
// ("3 unreferenced vertices (first: vertex 17)", "... (first: edge 4-5, faces 1, 2)"; the
// first element is the lowest id). Boundary edges are counted but are no warning: open
// meshes are valid. Edges are the sides (a, b) with a != b; a zero-length side of a degenerate
// face is no edge. Runs in parallel; the result does not depend on the thread count.
// Requires a well-formed mesh (indices in range), as the readers return.
MeshValidation ValidateMesh(const Mesh& mesh);

// OK when validation.clean(); otherwise an error "<source>: mesh is not clean: <warnings
// joined by '; '>".
Status RequireClean(const Mesh& mesh, const MeshValidation& validation);

// One line per distinct ignored tag name (tags.ignored_tag_names, first appearance first),
// naming the file, the tag, how many lines carry it and that it is ignored; after 10 names,
// one line counting the rest. Empty when none.
std::vector<std::string> IgnoredTagWarnings(const Mesh& mesh);

struct BoundingBox {
  Float3 min{0, 0, 0}, max{0, 0, 0};
  // Length of max - min (0 for the default box).
  float diagonal() const;
};

// The box around all positions, referenced by a face or not; the zero box for no positions.
BoundingBox ComputeBounds(const Mesh& mesh);

// Median length of the mesh's face sides (an edge shared by two faces counts twice), the mean
// of the two middle values for an even count; 0 for no faces. Above 2^22 sides it is the
// median of every k-th side, k the smallest prime >= max(5, sides / 2^22): deterministic, and
// a prime stride does not alias with the corners of triangles and quads.
double MedianEdgeLength(const Mesh& mesh);

// Total area of the faces (n-gons as triangle fans from their first vertex), in double.
// Deterministic for any thread count.
double MeshArea(const Mesh& mesh);

}  // namespace dispex
