// Follows OpenSubdiv's documented way to adapt a client mesh: specialise
// Far::TopologyRefinerFactory<MESH> (resizeComponentTopology, assignComponentTopology,
// assignComponentTags, reportInvalidTopology) for a small adapter over dispex::Mesh, so the
// face-vertex arrays are read without copies and every complaint reaches a Status.
#include "subdiv/refiner_builder.h"

#include <fmt/format.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/sdc/crease.h>
#include <opensubdiv/sdc/options.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "subdiv/osd_messages.h"

namespace dispex::subdiv {

// What the factory specialisation reads, plus where it leaves its complaints.
struct CageAdapter {
  const Mesh* mesh = nullptr;
  mutable std::string error;
};

}  // namespace dispex::subdiv

namespace OpenSubdiv {
namespace OPENSUBDIV_VERSION {
namespace Far {

using dispex::subdiv::CageAdapter;

template <>
bool TopologyRefinerFactory<CageAdapter>::resizeComponentTopology(TopologyRefiner& refiner,
                                                                  const CageAdapter& cage) {
  const dispex::Mesh& mesh = *cage.mesh;
  setNumBaseVertices(refiner, static_cast<int>(mesh.num_vertices()));
  const int num_faces = static_cast<int>(mesh.num_faces());
  setNumBaseFaces(refiner, num_faces);
  for (int f = 0; f < num_faces; ++f) setNumBaseFaceVertices(refiner, f, mesh.face_size(f));
  return true;
}

template <>
bool TopologyRefinerFactory<CageAdapter>::assignComponentTopology(TopologyRefiner& refiner,
                                                                  const CageAdapter& cage) {
  const dispex::Mesh& mesh = *cage.mesh;
  const int num_faces = static_cast<int>(mesh.num_faces());
  for (int f = 0; f < num_faces; ++f) {
    IndexArray dst = getBaseFaceVertices(refiner, f);
    std::span<const std::int32_t> src = mesh.face(f);
    for (int k = 0; k < dst.size(); ++k) dst[k] = src[k];
  }
  return true;
}

template <>
bool TopologyRefinerFactory<CageAdapter>::assignComponentTags(TopologyRefiner& refiner,
                                                              const CageAdapter& cage) {
  const dispex::Mesh& mesh = *cage.mesh;
  const dispex::SubdivTags& tags = mesh.tags;
  for (std::size_t i = 0; i < tags.creases.size(); ++i) {
    const auto& crease = tags.creases[i];
    const Index edge = findBaseEdge(refiner, crease.v0.value, crease.v1.value);
    if (edge == INDEX_INVALID) {
      cage.error = fmt::format("crease tag {} (vertices {}-{}) is not an edge of the mesh", i,
                               crease.v0.value, crease.v1.value);
      return false;
    }
    setBaseEdgeSharpness(refiner, edge,
                         std::min(crease.sharpness, Sdc::Crease::SHARPNESS_INFINITE));
  }
  for (const auto& corner : tags.corners) {
    setBaseVertexSharpness(refiner, corner.vertex.value,
                           std::min(corner.sharpness, Sdc::Crease::SHARPNESS_INFINITE));
  }
  for (dispex::BaseFaceId hole : tags.holes) setBaseFaceHole(refiner, hole.value, true);
  return true;
}

template <>
bool TopologyRefinerFactory<CageAdapter>::assignFaceVaryingTopology(TopologyRefiner&,
                                                                    const CageAdapter&) {
  return true;  // face-varying data is not used by dispex
}

template <>
void TopologyRefinerFactory<CageAdapter>::reportInvalidTopology(TopologyError, const char* message,
                                                                const CageAdapter& cage) {
  if (!cage.error.empty()) cage.error += "; ";
  cage.error += message;
}

}  // namespace Far
}  // namespace OPENSUBDIV_VERSION
}  // namespace OpenSubdiv

namespace dispex::subdiv {
namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

Sdc::Options SchemeOptions(const SubdivTags& tags) {
  Sdc::Options options;
  switch (tags.boundary) {
    case BoundaryInterpolation::kNone:
      options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_NONE);
      break;
    case BoundaryInterpolation::kEdgeOnly:
      options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
      break;
    case BoundaryInterpolation::kEdgeAndCorner:
      options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
      break;
  }
  options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
  options.SetCreasingMethod(tags.crease_method == CreaseMethod::kChaikin
                                ? Sdc::Options::CREASE_CHAIKIN
                                : Sdc::Options::CREASE_UNIFORM);
  options.SetTriangleSubdivision(tags.triangles == TriangleSubdivision::kSmooth
                                     ? Sdc::Options::TRI_SUB_SMOOTH
                                     : Sdc::Options::TRI_SUB_CATMARK);
  return options;
}

std::string Where(const Mesh& cage) {
  return cage.source.empty() ? "cage" : cage.source;
}

bool ValidSharpness(float s) {
  return std::isfinite(s) && s >= 0.0f;
}

Status Fail(const std::string& where, const std::string& what) {
  return Status::Error(where + ": " + what);
}

// The face arrays' extent, the sizes OpenSubdiv's int indices hold, and finite positions.
Status CheckArrays(const Mesh& cage, const std::string& where) {
  if (cage.face_offsets.size() < 2) return Fail(where, "the cage has no faces");
  if (cage.face_offsets.front() != 0 || cage.face_offsets.back() != cage.face_indices.size()) {
    return Fail(
        where,
        fmt::format("face offsets do not span the {} face indices (first {}, last {})",
                    cage.face_indices.size(), cage.face_offsets.front(), cage.face_offsets.back()));
  }
  constexpr std::size_t kMaxIndex = std::numeric_limits<std::int32_t>::max();
  if (cage.num_faces() > kMaxIndex || cage.num_vertices() > kMaxIndex ||
      cage.face_indices.size() > kMaxIndex) {
    return Fail(where, fmt::format("too large for OpenSubdiv ({} vertices, {} faces)",
                                   cage.num_vertices(), cage.num_faces()));
  }
  if (cage.num_vertices() == 0) return Fail(where, "the cage has no vertices");
  for (std::size_t v = 0; v < cage.num_vertices(); ++v) {
    const Float3& p = cage.positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return Fail(
          where, fmt::format("vertex {} has a non-finite position ({}, {}, {})", v, p.x, p.y, p.z));
    }
  }
  return Status::Ok();
}

// Every face: its size, its vertex indices in range, no vertex twice.
Status CheckFaces(const Mesh& cage, const std::string& where) {
  const std::int64_t num_vertices = static_cast<std::int64_t>(cage.num_vertices());
  std::vector<std::int32_t> sorted;  // scratch for repeated-vertex checks of large faces
  for (std::size_t f = 0; f < cage.num_faces(); ++f) {
    if (cage.face_offsets[f + 1] < cage.face_offsets[f]) {
      return Fail(where, fmt::format("face {}: face offsets decrease", f));
    }
    const int n = cage.face_size(f);
    if (n < 3) {
      return Fail(where, fmt::format("face {} has {} vertices; a face needs at least 3", f, n));
    }
    if (n > Far::VALENCE_LIMIT) {
      return Fail(where, fmt::format("face {} has {} vertices; OpenSubdiv allows at most {}", f, n,
                                     Far::VALENCE_LIMIT));
    }
    std::span<const std::int32_t> face = cage.face(f);
    for (int k = 0; k < n; ++k) {
      if (face[k] < 0 || face[k] >= num_vertices) {
        return Fail(where, fmt::format("face {}: vertex index {} out of range ({} vertices)", f,
                                       face[k], num_vertices));
      }
    }
    if (n <= 16) {
      for (int a = 0; a < n; ++a) {
        for (int b = a + 1; b < n; ++b) {
          if (face[a] == face[b]) {
            return Fail(where,
                        fmt::format("face {} repeats vertex {} (a degenerate face)", f, face[a]));
          }
        }
      }
    } else {
      sorted.assign(face.begin(), face.end());
      std::sort(sorted.begin(), sorted.end());
      auto it = std::adjacent_find(sorted.begin(), sorted.end());
      if (it != sorted.end()) {
        return Fail(where, fmt::format("face {} repeats vertex {} (a degenerate face)", f, *it));
      }
    }
  }
  return Status::Ok();
}

// Crease, corner and hole tags: their vertices and faces in range, their sharpness valid.
Status CheckTags(const Mesh& cage, const std::string& where) {
  const std::int64_t num_vertices = static_cast<std::int64_t>(cage.num_vertices());
  const SubdivTags& tags = cage.tags;
  for (std::size_t i = 0; i < tags.creases.size(); ++i) {
    const auto& c = tags.creases[i];
    if (c.v0.value < 0 || c.v0.value >= num_vertices || c.v1.value < 0 ||
        c.v1.value >= num_vertices) {
      return Fail(where, fmt::format("crease tag {}: vertex {}-{} out of range ({} vertices)", i,
                                     c.v0.value, c.v1.value, num_vertices));
    }
    if (c.v0 == c.v1) {
      return Fail(where, fmt::format("crease tag {}: vertices {}-{} do not make an edge", i,
                                     c.v0.value, c.v1.value));
    }
    if (!ValidSharpness(c.sharpness)) {
      return Fail(where, fmt::format("crease tag {} (vertices {}-{}): sharpness {} is not a finite "
                                     "value >= 0",
                                     i, c.v0.value, c.v1.value, c.sharpness));
    }
  }
  for (std::size_t i = 0; i < tags.corners.size(); ++i) {
    const auto& c = tags.corners[i];
    if (c.vertex.value < 0 || c.vertex.value >= num_vertices) {
      return Fail(where, fmt::format("corner tag {}: vertex {} out of range ({} vertices)", i,
                                     c.vertex.value, num_vertices));
    }
    if (!ValidSharpness(c.sharpness)) {
      return Fail(where, fmt::format("corner tag {} (vertex {}): sharpness {} is not a finite "
                                     "value >= 0",
                                     i, c.vertex.value, c.sharpness));
    }
  }
  const std::int64_t num_faces = static_cast<std::int64_t>(cage.num_faces());
  for (std::size_t i = 0; i < tags.holes.size(); ++i) {
    if (tags.holes[i].value < 0 || tags.holes[i].value >= num_faces) {
      return Fail(where, fmt::format("hole tag {}: face {} out of range ({} faces)", i,
                                     tags.holes[i].value, num_faces));
    }
  }
  return Status::Ok();
}

}  // namespace

float MaxSemiSharpness(const SubdivTags& tags) {
  float max_sharpness = 0.0f;
  for (const auto& c : tags.creases) {
    if (c.sharpness < kInfiniteSharpness) max_sharpness = std::max(max_sharpness, c.sharpness);
  }
  for (const auto& c : tags.corners) {
    if (c.sharpness < kInfiniteSharpness) max_sharpness = std::max(max_sharpness, c.sharpness);
  }
  return max_sharpness;
}

Status ValidateCage(const Mesh& cage) {
  const std::string where = Where(cage);
  DISPEX_RETURN_IF_ERROR(CheckArrays(cage, where));
  DISPEX_RETURN_IF_ERROR(CheckFaces(cage, where));
  return CheckTags(cage, where);
}

StatusOr<std::unique_ptr<Far::TopologyRefiner>> BuildTopologyRefiner(const Mesh& cage) {
  DISPEX_RETURN_IF_ERROR(ValidateCage(cage));

  CageAdapter adapter;
  adapter.mesh = &cage;
  using Factory = Far::TopologyRefinerFactory<CageAdapter>;
  Factory::Options options(Sdc::SCHEME_CATMARK, SchemeOptions(cage.tags));
  // Full validation checks every relation OpenSubdiv derived from the face-vertices; it is
  // linear in the cage size and cages are small.
  options.validateFullTopology = true;

  OsdMessageCapture capture;
  std::unique_ptr<Far::TopologyRefiner> refiner(Factory::Create(adapter, options));
  if (refiner == nullptr || !adapter.error.empty()) {
    std::string why = adapter.error;
    if (!capture.empty()) why += (why.empty() ? "" : "; ") + capture.messages();
    if (why.empty()) why = "unknown reason";
    return Status::Error(Where(cage) + ": OpenSubdiv rejected the topology: " + why);
  }
  return refiner;
}

}  // namespace dispex::subdiv
