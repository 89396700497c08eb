// The sculpt's half-edge adjacency kept in a cache folder between matches of sculpts with the
// same faces (an incremental run after an edit of positions only): the adjacency depends on the
// faces alone, and building it is the largest step of matching a large sculpt. A file is keyed
// by a hash of the faces and vertex count and checked whole by a hash of its content; one that
// is missing, damaged or of other faces is built again. The folder's cache files are kept
// under kAdjacencyCacheBytes, the least recently used removed first.
#pragma once

#include <cstdint>
#include <string>

#include "core/hash128.h"
#include "dispex/mesh.h"
#include "dispex/status.h"
#include "subdiv/quad_adjacency.h"

namespace dispex::subdiv {

inline constexpr std::uint64_t kAdjacencyCacheBytes = std::uint64_t{4} << 30;

// The key of a mesh's faces (and vertex count): equal for two meshes with the same faces.
Hash128 SculptFacesKey(const Mesh& mesh);

// BuildQuadAdjacency(mesh), read from `folder` when a file there holds it, else built and
// written there (a folder that cannot be written is only a slower run). `from_cache` says
// which. The result is the same either way. `faces_key`: SculptFacesKey(mesh) when the caller
// has it.
StatusOr<QuadAdjacency> CachedQuadAdjacency(const Mesh& mesh, const std::string& folder,
                                            bool& from_cache, const Hash128* faces_key = nullptr);

}  // namespace dispex::subdiv
