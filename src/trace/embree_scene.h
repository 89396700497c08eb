// The sculpt as an Embree scene: geometry 0 holds the quads, geometry 1 the triangles (the
// mesh's triangles and its n-gons fan-triangulated), with maps from Embree primitive ids back
// to sculpt face indices.
//
// Embree reads the mesh's own arrays wherever it can: the vertex buffer always (when the
// vector has capacity for the 4 bytes of padding Embree may read past the last vertex;
// otherwise one padded copy is made), the index buffer when every face is a quad or every
// face is a triangle. Only mixed meshes get index copies and primitive-to-face maps.
#pragma once

#include <embree3/rtcore.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/trace.h"
#include "trace/embree_device.h"
#include "trace/vertex_prims.h"

namespace dispex::trace {

inline constexpr unsigned kQuadGeometry = 0;
inline constexpr unsigned kTriangleGeometry = 1;
inline constexpr unsigned kNumGeometries = 2;

// One Embree geometry's primitives, for code that needs the vertices of a hit primitive.
struct GeometryView {
  const std::int32_t* indices = nullptr;       // `corners` vertex ids per primitive
  const std::int32_t* face_of_prim = nullptr;  // nullptr: primitive id == sculpt face index
  std::size_t count = 0;
  int corners = 0;  // 4 for quads, 3 for triangles
};

class EmbreeScene {
 public:
  // Validates `mesh` (see MakeEmbreeTracer in dispex/trace.h for the errors) and builds the
  // BVH. `mesh` must outlive the scene and stay unchanged.
  static StatusOr<std::unique_ptr<EmbreeScene>> Build(const Mesh& mesh,
                                                      const TracerOptions& options);

  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;
  ~EmbreeScene();

  RTCScene scene() const { return scene_; }
  const EmbreeDevice& device() const { return *device_; }
  const Float3* positions() const { return positions_; }
  const GeometryView& geometry(unsigned geom_id) const { return geometries_[geom_id]; }

  // Sculpt face index of Embree primitive `prim_id` of geometry `geom_id` (a valid hit).
  std::int32_t FaceOf(unsigned geom_id, unsigned prim_id) const {
    const GeometryView& g = geometries_[geom_id];
    return g.face_of_prim != nullptr ? g.face_of_prim[prim_id] : static_cast<std::int32_t>(prim_id);
  }

  // The primitives around each vertex (the tie rule of normal queries, batch_kernels.h), built
  // on first use: scenes that only answer other queries (render, verify) never build them.
  // Thread-safe.
  const VertexPrims& vertex_prims() const;
  // Global primitive `p` of VertexPrims as (geometry, primitive), and back.
  unsigned GeomOf(std::uint32_t p) const {
    return p < num_quads_ ? kQuadGeometry : kTriangleGeometry;
  }
  std::uint32_t GlobalOf(unsigned geom, unsigned prim) const {
    return geom == kQuadGeometry ? prim : static_cast<std::uint32_t>(num_quads_ + prim);
  }
  unsigned PrimOf(std::uint32_t p) const {
    return p < num_quads_ ? p : static_cast<unsigned>(p - num_quads_);
  }

  const TracerStats& stats() const { return stats_; }

  // The vertex guard's settings (TracerOptions::retry_misses, verify_hits; see
  // batch_kernels.h), and the largest absolute coordinate of the scene's bounds, the scale of
  // its sideways step.
  bool retry_misses() const { return retry_misses_; }
  bool verify_hits() const { return verify_hits_; }
  float scale() const { return scale_; }

 private:
  EmbreeScene() = default;
  Status Setup(const Mesh& mesh, const TracerOptions& options);
  Status AddGeometry(unsigned geom_id, RTCGeometryType type, const std::int32_t* indices,
                     std::size_t count, std::size_t num_vertices, RTCBuildQuality quality);

  std::unique_ptr<EmbreeDevice> device_;
  RTCScene scene_ = nullptr;
  const Float3* positions_ = nullptr;
  std::vector<Float3> vertex_copy_;  // only when the mesh's vector lacks the padding
  std::vector<std::int32_t> quad_indices_, quad_faces_;          // mixed meshes only
  std::vector<std::int32_t> triangle_indices_, triangle_faces_;  // n-gons or mixed meshes
  GeometryView geometries_[kNumGeometries];
  std::size_t num_quads_ = 0, num_vertices_ = 0;
  mutable std::once_flag vertex_prims_once_;
  mutable VertexPrims vertex_prims_;
  TracerStats stats_;
  bool retry_misses_ = true;
  bool verify_hits_ = false;
  float scale_ = 0;
};

}  // namespace dispex::trace
