// The parsing pass of the parallel OBJ reader: one chunk of whole logical lines at a time.
//
// The counting pass (obj_reader.cpp) has already told each chunk where its vertices, texture
// coordinates, faces and (where it counted them) face corners go in the final arrays and how many
// the whole file has, so a chunk writes positions, UVs and face sizes in place, resolves relative
// (negative) indices and checks every index and tag id while it parses: the first error of each
// chunk is found with its exact line number.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "mesh/chunk_buffer.h"

namespace dispex::mesh {

struct ChunkInput {
  const char* file_begin = nullptr;     // start of the whole buffer (for look-back)
  const char* begin = nullptr;          // first byte of the chunk: the start of a logical line
  const char* end = nullptr;            // one past the last byte: after a '\n' or the buffer end
  std::int64_t first_line = 1;          // 1-based line number of `begin`
  std::int64_t vertex_base = 0;         // vertices before this chunk
  std::int64_t texcoord_base = 0;       // texture coordinates (vt) before this chunk
  std::int64_t face_base = 0;           // faces before this chunk
  std::int64_t num_vertices = 0;        // in the whole file
  std::int64_t num_texcoords = 0;       // in the whole file
  std::int64_t num_faces = 0;           // in the whole file
  Float3* positions = nullptr;          // the final array, num_vertices long
  float* uvs = nullptr;                 // the final array, 2 * num_texcoords long
  std::uint32_t* face_sizes = nullptr;  // num_faces long: the size of face f at [f]
  // Where the chunk's face indices go in the final array, room for `corners` (the counting
  // pass's); null: into ChunkOutput::indices.
  std::int32_t* indices = nullptr;
  std::int64_t corners = 0;
};

struct GroupStart {
  std::int64_t first_face = 0;  // global index of the first face after the `o`/`g` line
  std::string name;
};

struct ChunkError {
  std::int64_t line = 0;
  std::string message;  // without file and line
};

struct ChunkOutput {
  ChunkBuffer<std::int32_t> indices;  // 0-based vertex ids, face after face (unless in place)
  std::int64_t corners = 0;           // vertex ids read, when ChunkInput::indices is set
  // 0-based texture coordinate ids, one per corner of indices, while every face of the chunk
  // so far names one at every corner (unused when the file has no vt line, and no longer
  // filled after a face without: the file then has no UVs).
  ChunkBuffer<std::int32_t> uv_indices;
  std::vector<GroupStart> groups;  // in file order
  SubdivTags tags;                 // this chunk's tags, in file order
  std::int64_t vertices = 0;       // parsed (equals the counting pass unless error)
  std::int64_t texcoords = 0;
  std::int64_t faces = 0;
  std::int64_t faces_with_uvs = 0;           // faces that name a texture coordinate at every corner
  std::int64_t first_face_without_uvs = -1;  // within the chunk; -1: none
  std::optional<ChunkError> error;           // the first error in the chunk; parsing stopped there
};

// Parses the chunk. Never throws for bad bytes; an error stops the chunk and is recorded.
// Returns false only when an index buffer cannot be mapped (out of memory).
bool ParseChunk(const ChunkInput& in, ChunkOutput& out);

}  // namespace dispex::mesh
