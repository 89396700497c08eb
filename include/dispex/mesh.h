// The in-memory polygon mesh shared by every stage: base cages and sculpts alike.
//
// Structure of arrays: positions as float3, faces in CSR form (face_offsets has one entry
// per face plus one; face f uses face_indices[face_offsets[f] .. face_offsets[f+1])), vertex
// ids as int32 so OpenSubdiv and Embree can read the arrays without copies. Faces keep the
// winding of the file (counter-clockwise = outward).
#pragma once

#include <cstdint>
#include <span>
#include <string>
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
  int ignored_tags = 0;             // tags read but not used (face-varying settings, ...)

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
};

// ---- Reading -------------------------------------------------------------------------------

struct ReadOptions {
  int threads = 0;  // 0: all available (TBB's default)
};

// Reads an OBJ or PLY file, chosen by content (PLY magic) and extension. Every malformed
// input gives a Status naming the file and the line (OBJ) or element (PLY).
StatusOr<Mesh> ReadMesh(const std::string& path, const ReadOptions& options = {});
StatusOr<Mesh> ReadObj(const std::string& path, const ReadOptions& options = {});
StatusOr<Mesh> ReadPly(const std::string& path, const ReadOptions& options = {});

// The same parsers over bytes in memory (`name` is used in messages). For tests and fuzzing.
StatusOr<Mesh> ParseObj(std::string_view bytes, const std::string& name,
                        const ReadOptions& options = {});
StatusOr<Mesh> ParsePly(std::string_view bytes, const std::string& name,
                        const ReadOptions& options = {});

// ---- Validation and summary ----------------------------------------------------------------

struct MeshValidation {
  std::size_t unreferenced_vertices = 0;
  std::size_t degenerate_faces = 0;       // a vertex repeated within a face
  std::size_t non_manifold_edges = 0;     // edges used by more than two faces
  std::size_t inconsistent_edges = 0;     // edges two faces traverse in the same direction
  std::size_t boundary_edges = 0;
  std::vector<std::string> warnings;      // one line each, naming the first offending element

  bool clean() const {
    return unreferenced_vertices == 0 && degenerate_faces == 0 && non_manifold_edges == 0 &&
           inconsistent_edges == 0;
  }
};

MeshValidation ValidateMesh(const Mesh& mesh);

// Turns validation warnings into an error (the --strict flag).
Status RequireClean(const Mesh& mesh, const MeshValidation& validation);

struct BoundingBox {
  Float3 min{0, 0, 0}, max{0, 0, 0};
  float diagonal() const;
};

BoundingBox ComputeBounds(const Mesh& mesh);
// Median length of the mesh's edges (each undirected edge counted once per face side).
double MedianEdgeLength(const Mesh& mesh);

}  // namespace dispex
