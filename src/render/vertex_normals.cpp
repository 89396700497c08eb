// Vertex normals of polygon meshes (vertex_normals.h), and ShadePolygonMesh (tessellation.h):
// any polygon mesh fanned into triangles, shaded by the Newell normals of its own polygons.
#include "render/vertex_normals.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <numeric>

#include "render/tessellation.h"

namespace dispex::render {

void VertexNormals(std::size_t num_vertices, std::span<const std::uint32_t> face_offsets,
                   std::span<const std::int32_t> face_indices, std::span<const Float3> face_normals,
                   std::span<const Float3> fallback, std::vector<Float3>& normals) {
  const std::size_t num_faces = face_offsets.size() - 1;
  std::vector<std::uint32_t> start(num_vertices + 1, 0);
  for (std::int32_t v : face_indices) ++start[static_cast<std::size_t>(v) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  std::vector<std::uint32_t> faces_of(face_indices.size());
  for (std::size_t f = 0; f < num_faces; ++f) {
    for (std::uint32_t k = face_offsets[f]; k < face_offsets[f + 1]; ++k) {
      faces_of[fill[static_cast<std::size_t>(face_indices[k])]++] = static_cast<std::uint32_t>(f);
    }
  }
  normals.resize(num_vertices);
  tbb::parallel_for(std::size_t{0}, num_vertices, [&](std::size_t v) {
    double x = 0, y = 0, z = 0;
    std::uint32_t previous = std::numeric_limits<std::uint32_t>::max();
    for (std::uint32_t k = start[v]; k < start[v + 1]; ++k) {
      if (faces_of[k] == previous) continue;  // a face listing the vertex twice counts once
      previous = faces_of[k];
      const Float3& n = face_normals[faces_of[k]];
      x += n.x, y += n.y, z += n.z;
    }
    const double len = std::sqrt(x * x + y * y + z * z);
    if (len > 0 && std::isfinite(len)) {
      normals[v] = {float(x / len), float(y / len), float(z / len)};
    } else {
      normals[v] = v < fallback.size() ? fallback[v] : Float3{0, 0, 1};
    }
  });
}

ShadedMesh ShadePolygonMesh(const Mesh& mesh) {
  ShadedMesh out;
  const std::size_t num_faces = mesh.num_faces();
  // Newell normals of the polygons (twice the area times the unit normal for planar ones).
  std::vector<Float3> face_normals(num_faces);
  std::vector<std::uint32_t> triangle_start(num_faces + 1, 0);
  for (std::size_t f = 0; f < num_faces; ++f) {
    triangle_start[f + 1] = triangle_start[f] + static_cast<std::uint32_t>(mesh.face_size(f) - 2);
  }
  tbb::parallel_for(std::size_t{0}, num_faces, [&](std::size_t f) {
    const auto verts = mesh.face(f);
    double x = 0, y = 0, z = 0;
    for (std::size_t k = 0; k < verts.size(); ++k) {
      const Float3& p = mesh.positions[static_cast<std::size_t>(verts[k])];
      const Float3& q = mesh.positions[static_cast<std::size_t>(verts[(k + 1) % verts.size()])];
      x += (double(p.y) - q.y) * (double(p.z) + q.z);
      y += (double(p.z) - q.z) * (double(p.x) + q.x);
      z += (double(p.x) - q.x) * (double(p.y) + q.y);
    }
    face_normals[f] = {float(x), float(y), float(z)};
  });
  VertexNormals(mesh.num_vertices(), mesh.face_offsets, mesh.face_indices, face_normals, {},
                out.normals);

  Mesh& tri = out.mesh;
  tri.source = mesh.source;
  tri.positions.reserve(mesh.positions.size() + 1);  // Embree reads 16 bytes at the last one
  tri.positions.assign(mesh.positions.begin(), mesh.positions.end());
  const std::size_t num_triangles = triangle_start[num_faces];
  tri.face_offsets.resize(num_triangles + 1);
  tri.face_indices.resize(3 * num_triangles);
  tbb::parallel_for(std::size_t{0}, num_faces, [&](std::size_t f) {
    const auto verts = mesh.face(f);
    for (std::size_t k = 1; k + 1 < verts.size(); ++k) {
      const std::size_t t = triangle_start[f] + k - 1;
      tri.face_offsets[t] = static_cast<std::uint32_t>(3 * t);
      tri.face_indices[3 * t] = verts[0];
      tri.face_indices[3 * t + 1] = verts[k];
      tri.face_indices[3 * t + 2] = verts[k + 1];
    }
  });
  tri.face_offsets[num_triangles] = static_cast<std::uint32_t>(3 * num_triangles);
  return out;
}

}  // namespace dispex::render
