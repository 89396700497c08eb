// The test oracle for the map's Ptex faces: the Ptex numbering and adjacency of a
// Catmull-Clark mesh computed from its topology alone, without OpenSubdiv. subdiv_faces_test
// checks it against OpenSubdiv on every cage, so a test can compare a map's face table with
// it independently of the limit surface the library takes its faces from.
#pragma once

#include <cstdint>
#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/status.h"

namespace dispex {

// The Ptex faces of a Catmull-Clark mesh, numbered as OpenSubdiv's Far::PtexIndices: base
// faces in order, a quad gives one face, an n-gon (n != 4) n sub-faces, sub-face q having
// (0,0) at the face's vertex q. Adjacency follows Far::PtexIndices::GetAdjacency: edges with
// other than two incident faces have no neighbour; a quad next to an n-gon points at the
// sub-face met first along its own edge, with edge 3. Resolutions are left at 0 (1x1).
struct SubdivPtexFaces {
  std::vector<PtexFaceInfo> faces;          // one per Ptex face
  std::vector<BaseFaceId> base_face;        // base face of each Ptex face
  std::vector<std::int32_t> subface_index;  // q for sub-faces, 0 for quads
  std::vector<PtexFaceId> first_face;       // per base face its first Ptex face; one extra entry
                                            // holding the number of Ptex faces

  int num_faces() const { return static_cast<int>(faces.size()); }
};

// Fails, naming the mesh and face, on a face with fewer than 3 vertices or a vertex index
// out of range, or when the Ptex face count would exceed 2^28.
StatusOr<SubdivPtexFaces> ComputeSubdivPtexFaces(const Mesh& mesh);

}  // namespace dispex
