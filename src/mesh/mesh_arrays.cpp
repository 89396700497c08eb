// CheckMeshArrays: a mesh built in memory held to what the readers guarantee of a file's;
// ReverseWinding.
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "dispex/mesh.h"

namespace dispex {

namespace {

bool Finite(const Float3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

Status CheckVertex(const Mesh& mesh, VertexId v, const std::string& what) {
  if (v.value < 0 || static_cast<std::size_t>(v.value) >= mesh.num_vertices()) {
    return Status::Error(fmt::format("{}: vertex index {} out of range ({} vertices)", what,
                                     v.value, mesh.num_vertices()));
  }
  return Status::Ok();
}

Status CheckSharpness(float sharpness, const std::string& what) {
  if (!std::isfinite(sharpness) || sharpness < 0) {
    return Status::Error(
        fmt::format("{}: sharpness {} is not a finite number >= 0", what, sharpness));
  }
  return Status::Ok();
}

Status CheckFaces(const Mesh& mesh) {
  if (mesh.face_offsets.size() < 2) return Status::Error("no faces");
  if (mesh.face_offsets.front() != 0 || mesh.face_offsets.back() != mesh.face_indices.size()) {
    return Status::Error(fmt::format("face offsets run from {} to {}, not from 0 to the {} indices",
                                     mesh.face_offsets.front(), mesh.face_offsets.back(),
                                     mesh.face_indices.size()));
  }
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    if (mesh.face_offsets[f + 1] < mesh.face_offsets[f] + 3) {
      return Status::Error(fmt::format("face {}: fewer than 3 vertices", f));
    }
    for (std::int32_t v : mesh.face(f)) {
      DISPEX_RETURN_IF_ERROR(CheckVertex(mesh, VertexId(v), fmt::format("face {}", f)));
    }
  }
  return Status::Ok();
}

Status CheckTags(const Mesh& mesh) {
  for (std::size_t i = 0; i < mesh.tags.creases.size(); ++i) {
    const SubdivTags::Crease& c = mesh.tags.creases[i];
    const std::string what = fmt::format("crease {}", i);
    DISPEX_RETURN_IF_ERROR(CheckVertex(mesh, c.v0, what));
    DISPEX_RETURN_IF_ERROR(CheckVertex(mesh, c.v1, what));
    DISPEX_RETURN_IF_ERROR(CheckSharpness(c.sharpness, what));
  }
  for (std::size_t i = 0; i < mesh.tags.corners.size(); ++i) {
    const std::string what = fmt::format("corner {}", i);
    DISPEX_RETURN_IF_ERROR(CheckVertex(mesh, mesh.tags.corners[i].vertex, what));
    DISPEX_RETURN_IF_ERROR(CheckSharpness(mesh.tags.corners[i].sharpness, what));
  }
  for (std::size_t i = 0; i < mesh.tags.holes.size(); ++i) {
    const BaseFaceId f = mesh.tags.holes[i];
    if (f.value < 0 || static_cast<std::size_t>(f.value) >= mesh.num_faces()) {
      return Status::Error(fmt::format("hole {}: face index {} out of range ({} faces)", i, f.value,
                                       mesh.num_faces()));
    }
  }
  return Status::Ok();
}

Status CheckGroupsAndUvs(const Mesh& mesh) {
  if (!mesh.face_groups.empty()) {
    if (mesh.face_groups.size() != mesh.num_faces()) {
      return Status::Error(
          fmt::format("{} face groups for {} faces", mesh.face_groups.size(), mesh.num_faces()));
    }
    for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
      const std::int32_t g = mesh.face_groups[f];
      if (g < 0 || static_cast<std::size_t>(g) >= mesh.group_names.size()) {
        return Status::Error(fmt::format("face {}: group {} out of range ({} group names)", f, g,
                                         mesh.group_names.size()));
      }
    }
  }
  if (mesh.face_uv_indices.empty()) {
    if (!mesh.uvs.empty()) return Status::Error("texture coordinates without face UV indices");
    return Status::Ok();
  }
  if (mesh.face_uv_indices.size() != mesh.face_indices.size() || mesh.uvs.size() % 2 != 0) {
    return Status::Error("face UV indices not one per face corner, or UVs not (u, v) pairs");
  }
  for (std::size_t i = 0; i < mesh.uvs.size(); ++i) {
    if (!std::isfinite(mesh.uvs[i])) {
      return Status::Error(fmt::format("texture coordinate {} is not finite", i / 2));
    }
  }
  for (std::size_t i = 0; i < mesh.face_uv_indices.size(); ++i) {
    const std::int32_t t = mesh.face_uv_indices[i];
    if (t < 0 || static_cast<std::size_t>(t) >= mesh.num_uvs()) {
      return Status::Error(
          fmt::format("face corner {}: texture index {} out of range ({} texture "
                      "coordinates)",
                      i, t, mesh.num_uvs()));
    }
  }
  return Status::Ok();
}

}  // namespace

Status CheckMeshArrays(const Mesh& mesh) {
  const std::string name = mesh.source.empty() ? "mesh" : mesh.source;
  for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
    if (!Finite(mesh.positions[v])) {
      return Status::Error(fmt::format("{}: vertex {} is not finite", name, v));
    }
  }
  DISPEX_RETURN_IF_ERROR(CheckFaces(mesh).WithPrefix(name));
  DISPEX_RETURN_IF_ERROR(CheckTags(mesh).WithPrefix(name));
  return CheckGroupsAndUvs(mesh).WithPrefix(name);
}

void ReverseWinding(Mesh& mesh) {
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, mesh.num_faces(), 1 << 14),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t f = range.begin(); f != range.end(); ++f) {
          const std::size_t begin = mesh.face_offsets[f] + 1;
          const std::size_t end = mesh.face_offsets[f + 1];
          std::reverse(mesh.face_indices.begin() + begin, mesh.face_indices.begin() + end);
          if (mesh.has_uvs()) {
            std::reverse(mesh.face_uv_indices.begin() + begin, mesh.face_uv_indices.begin() + end);
          }
        }
      });
}

}  // namespace dispex
