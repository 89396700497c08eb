// BaseFacePatches: what the limit surface over each base face is made from, hashed.
#include <opensubdiv/far/topologyRefiner.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "core/hash128.h"
#include "dispex/subdiv.h"
#include "subdiv/surface_impl.h"

namespace dispex {
namespace {

namespace Far = OpenSubdiv::Far;

// The ring's faces and vertices, numbered in order of first appearance from the face's
// corners, so that the key does not depend on the cage's global numbering.
struct Ring {
  std::vector<int> faces;     // cage face ids
  std::vector<int> vertices;  // cage vertex ids
  int LocalVertex(int v) {
    auto it = std::find(vertices.begin(), vertices.end(), v);
    if (it != vertices.end()) return static_cast<int>(it - vertices.begin());
    vertices.push_back(v);
    return static_cast<int>(vertices.size()) - 1;
  }
  int LocalFace(int f) const {
    return static_cast<int>(std::find(faces.begin(), faces.end(), f) - faces.begin());
  }
};

Float3 RingPoint(const LimitSurface::Impl& impl, int v) {
  const double* p = impl.positions.data() + 3 * static_cast<std::size_t>(v);
  return {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
}

Hash128 GlobalKey(const LimitSurface::Impl& impl) {
  const auto sdc = impl.refiner->GetSchemeOptions();
  Hasher h;
  h.Add(std::string_view("dispex patch key 1"));
  h.Add(static_cast<int>(impl.refiner->GetSchemeType()));
  h.Add(static_cast<int>(sdc.GetVtxBoundaryInterpolation()));
  h.Add(static_cast<int>(sdc.GetFVarLinearInterpolation()));
  h.Add(static_cast<int>(sdc.GetCreasingMethod()));
  h.Add(static_cast<int>(sdc.GetTriangleSubdivision()));
  h.Add(impl.options.approx_level_smooth);
  h.Add(impl.options.approx_level_sharp);
  h.Add(impl.options.regular_fast_path);
  return h.Digest();
}

Hash128 FaceKey(const LimitSurface::Impl& impl, const Hash128& global, int face, Ring& ring) {
  const Far::TopologyLevel& level = impl.refiner->GetLevel(0);
  ring.faces.clear();
  ring.vertices.clear();
  const auto corners = level.GetFaceVertices(face);
  for (int c = 0; c < corners.size(); ++c) {
    for (int g : level.GetVertexFaces(corners[c])) {
      if (std::find(ring.faces.begin(), ring.faces.end(), g) == ring.faces.end()) {
        ring.faces.push_back(g);
      }
    }
  }
  Hasher h;
  h.Add(global);
  h.Add(static_cast<std::uint8_t>(impl.use_patch_table.empty() ? 0 : impl.use_patch_table[face]));
  h.Add(corners.size());
  for (int c = 0; c < corners.size(); ++c) h.Add(ring.LocalVertex(corners[c]));
  for (int c = 0; c < corners.size(); ++c) {
    const int v = corners[c];
    h.Add(level.GetVertexSharpness(v));
    h.Add(level.IsVertexBoundary(v));
    h.Add(level.IsVertexNonManifold(v));
    const auto around = level.GetVertexFaces(v);
    h.Add(around.size());
    for (int g : around) h.Add(ring.LocalFace(g));
  }
  for (int g : ring.faces) {
    const auto vertices = level.GetFaceVertices(g);
    const auto edges = level.GetFaceEdges(g);
    h.Add(vertices.size());
    h.Add(level.IsFaceHole(g));
    for (int k = 0; k < vertices.size(); ++k) {
      h.Add(ring.LocalVertex(vertices[k]));
      h.Add(level.GetEdgeSharpness(edges[k]));
      h.Add(level.GetEdgeFaces(edges[k]).size());
    }
  }
  for (int v : ring.vertices) {
    h.AddArray(std::span<const double>(impl.positions.data() + 3 * static_cast<std::size_t>(v), 3));
  }
  return h.Digest();
}

}  // namespace

std::vector<BaseFacePatch> BaseFacePatches(const LimitSurface& surface) {
  const LimitSurface::Impl& impl = SurfaceImpl(surface);
  const int num_faces = impl.num_base_faces();
  const Hash128 global = GlobalKey(impl);
  std::vector<BaseFacePatch> patches(static_cast<std::size_t>(num_faces));
  tbb::parallel_for(tbb::blocked_range<int>(0, num_faces, 256),
                    [&](const tbb::blocked_range<int>& range) {
                      Ring ring;
                      for (int f = range.begin(); f != range.end(); ++f) {
                        BaseFacePatch& patch = patches[static_cast<std::size_t>(f)];
                        const Hash128 key = FaceKey(impl, global, f, ring);
                        patch.key = {key.low, key.high};
                        patch.lower = patch.upper = RingPoint(impl, ring.vertices[0]);
                        for (int v : ring.vertices) {
                          const Float3 p = RingPoint(impl, v);
                          patch.lower = {std::min(patch.lower.x, p.x), std::min(patch.lower.y, p.y),
                                         std::min(patch.lower.z, p.z)};
                          patch.upper = {std::max(patch.upper.x, p.x), std::max(patch.upper.y, p.y),
                                         std::max(patch.upper.z, p.z)};
                        }
                      }
                    });
  return patches;
}

}  // namespace dispex
