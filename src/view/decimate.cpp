#include "view/decimate.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_set>

namespace dispex::view {

namespace {

// A cell of the grid as 3 x 21 bits.
std::uint64_t CellKey(const Float3& p, const Float3& lo, double inverse_cell) {
  auto axis = [&](float c, float l) {
    const double q = std::floor((double(c) - double(l)) * inverse_cell);
    return static_cast<std::uint64_t>(std::clamp(q, 0.0, double((1 << 21) - 1)));
  };
  return axis(p.x, lo.x) | (axis(p.y, lo.y) << 21) | (axis(p.z, lo.z) << 42);
}

struct TriangleHash {
  std::size_t operator()(const std::array<std::uint32_t, 3>& t) const {
    std::uint64_t h = t[0];
    h = h * 0x9E3779B97F4A7C15ull + t[1];
    h = h * 0x9E3779B97F4A7C15ull + t[2];
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

// Twice the area vector of a face (its triangle fan's cross products, summed).
void FaceAreaVector(const Mesh& mesh, std::span<const std::int32_t> face, double n[3]) {
  n[0] = n[1] = n[2] = 0;
  const Float3& p = mesh.positions[static_cast<std::size_t>(face[0])];
  for (std::size_t c = 1; c + 1 < face.size(); ++c) {
    const Float3& q = mesh.positions[static_cast<std::size_t>(face[c])];
    const Float3& r = mesh.positions[static_cast<std::size_t>(face[c + 1])];
    const double u[3] = {double(q.x) - p.x, double(q.y) - p.y, double(q.z) - p.z};
    const double v[3] = {double(r.x) - p.x, double(r.y) - p.y, double(r.z) - p.z};
    n[0] += u[1] * v[2] - u[2] * v[1];
    n[1] += u[2] * v[0] - u[0] * v[2];
    n[2] += u[0] * v[1] - u[1] * v[0];
  }
}

Float3 UnitOr(const double* n) {
  const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(l > 0) || !std::isfinite(l)) return {0, 0, 1};
  return {float(n[0] / l), float(n[1] / l), float(n[2] / l)};
}

// The vertices some face uses, in order.
std::vector<std::uint32_t> UsedVertices(const Mesh& mesh) {
  const std::size_t nv = mesh.num_vertices();
  std::vector<std::uint8_t> used(nv, 0);
  for (std::int32_t v : mesh.face_indices) used[static_cast<std::size_t>(v)] = 1;
  std::vector<std::uint32_t> used_ids;
  for (std::size_t v = 0; v < nv; ++v) {
    if (used[v]) used_ids.push_back(static_cast<std::uint32_t>(v));
  }
  return used_ids;
}

// A mesh within the budget as it is: its used vertices, its faces as triangle fans, the
// vertices' normals from the area vectors of the faces at them.
DecimatedMesh Triangulated(const Mesh& mesh, std::span<const std::uint32_t> used_ids) {
  DecimatedMesh out;
  std::vector<std::uint32_t> remap(mesh.num_vertices(), 0);
  for (std::size_t k = 0; k < used_ids.size(); ++k) {
    remap[used_ids[k]] = static_cast<std::uint32_t>(k);
    out.positions.push_back(mesh.positions[used_ids[k]]);
  }
  std::vector<double> normal(3 * used_ids.size(), 0.0);
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    double n[3];
    FaceAreaVector(mesh, face, n);
    for (std::int32_t v : face) {
      double* m = &normal[3 * remap[static_cast<std::size_t>(v)]];
      m[0] += n[0], m[1] += n[1], m[2] += n[2];
    }
    for (std::size_t c = 1; c + 1 < face.size(); ++c) {
      out.triangles.push_back(remap[static_cast<std::size_t>(face[0])]);
      out.triangles.push_back(remap[static_cast<std::size_t>(face[c])]);
      out.triangles.push_back(remap[static_cast<std::size_t>(face[c + 1])]);
    }
  }
  for (std::size_t k = 0; k < used_ids.size(); ++k) out.normals.push_back(UnitOr(&normal[3 * k]));
  return out;
}

// The clustering's grid: the cell size, each used vertex's cell key and the occupied cells
// (sorted, each once), within max_vertices cells.
struct CellGrid {
  double cell = 0;
  std::vector<std::uint64_t> keys, cells;
};
CellGrid ChooseCells(const Mesh& mesh, std::span<const std::uint32_t> used_ids,
                     std::int64_t max_vertices) {
  const BoundingBox box = ComputeBounds(mesh);
  const double extent = std::max({double(box.max.x) - box.min.x, double(box.max.y) - box.min.y,
                                  double(box.max.z) - box.min.z, 1e-30});
  const double area = MeshArea(mesh);
  // About one vertex per cell of the surface's area; never finer than 2^21 cells per side.
  CellGrid grid;
  double& cell = grid.cell;
  cell = std::max(std::sqrt(std::max(area, 0.0) / double(max_vertices)),
                  extent / double((1 << 21) - 2));
  grid.keys.resize(used_ids.size());
  for (int attempt = 0;; ++attempt) {
    const double inverse = 1.0 / cell;
    tbb::parallel_for(std::size_t{0}, used_ids.size(), [&](std::size_t k) {
      grid.keys[k] = CellKey(mesh.positions[used_ids[k]], box.min, inverse);
    });
    grid.cells = grid.keys;
    tbb::parallel_sort(grid.cells.begin(), grid.cells.end());
    grid.cells.erase(std::unique(grid.cells.begin(), grid.cells.end()), grid.cells.end());
    const auto count = static_cast<std::int64_t>(grid.cells.size());
    if (count <= max_vertices || attempt >= 40) break;
    cell *= std::max(1.02, 1.01 * std::sqrt(double(count) / double(max_vertices)));
  }
  return grid;
}

// The vertices gathered into cells: each used vertex's cell, the sums and counts of the cells'
// points, and each cell's normal.
struct Clusters {
  std::vector<std::uint32_t> cell_of;  // per vertex of the mesh
  std::vector<double> sum;             // per cell: x, y, z
  std::vector<std::uint32_t> count;
  std::vector<double> normal;  // per cell: x, y, z

  Float3 Mean(std::uint32_t c) const {
    const double m = count[c];
    return Float3{float(sum[3 * c] / m), float(sum[3 * c + 1] / m), float(sum[3 * c + 2] / m)};
  }
};
Clusters Cluster(const Mesh& mesh, std::span<const std::uint32_t> used_ids, const CellGrid& grid) {
  Clusters out;
  const std::vector<std::uint64_t>& cells = grid.cells;
  out.cell_of.assign(mesh.num_vertices(), 0);
  tbb::parallel_for(std::size_t{0}, used_ids.size(), [&](std::size_t k) {
    out.cell_of[used_ids[k]] = static_cast<std::uint32_t>(
        std::lower_bound(cells.begin(), cells.end(), grid.keys[k]) - cells.begin());
  });
  out.sum.assign(3 * cells.size(), 0.0);
  out.count.assign(cells.size(), 0);
  for (std::uint32_t v : used_ids) {
    const std::uint32_t c = out.cell_of[v];
    const Float3& p = mesh.positions[v];
    out.sum[3 * c] += p.x, out.sum[3 * c + 1] += p.y, out.sum[3 * c + 2] += p.z;
    ++out.count[c];
  }

  // Each cell's normal: the sum of the area vectors of the faces at its vertices (the sculpt's
  // own shading, whatever the clustering did to the triangles).
  out.normal.assign(3 * cells.size(), 0.0);
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    double n[3];
    FaceAreaVector(mesh, face, n);
    for (std::int32_t v : face) {
      double* m = &out.normal[3 * out.cell_of[static_cast<std::size_t>(v)]];
      m[0] += n[0], m[1] += n[1], m[2] += n[2];
    }
  }
  return out;
}

// The triangles between three cells (of the faces' triangle fans), each once, turned to face
// along their cells' normals where the clustering turned them over (a renderer would shade
// them from behind); as cell ids.
std::vector<std::uint32_t> ClusterTriangles(const Mesh& mesh, const Clusters& clusters) {
  const std::vector<std::uint32_t>& cell_of = clusters.cell_of;
  const std::vector<double>& cell_normal = clusters.normal;
  std::unordered_set<std::array<std::uint32_t, 3>, TriangleHash> seen;
  std::vector<std::uint32_t> triangles;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    const std::uint32_t a = cell_of[static_cast<std::size_t>(face[0])];
    for (std::size_t c = 1; c + 1 < face.size(); ++c) {
      const std::uint32_t b = cell_of[static_cast<std::size_t>(face[c])];
      const std::uint32_t d = cell_of[static_cast<std::size_t>(face[c + 1])];
      if (a == b || b == d || a == d) continue;
      std::array<std::uint32_t, 3> key = {a, b, d};
      std::sort(key.begin(), key.end());
      if (!seen.insert(key).second) continue;
      double n[3] = {0, 0, 0};
      const Float3 p = clusters.Mean(a), q = clusters.Mean(b), r = clusters.Mean(d);
      const double u[3] = {double(q.x) - p.x, double(q.y) - p.y, double(q.z) - p.z};
      const double v[3] = {double(r.x) - p.x, double(r.y) - p.y, double(r.z) - p.z};
      n[0] = u[1] * v[2] - u[2] * v[1];
      n[1] = u[2] * v[0] - u[0] * v[2];
      n[2] = u[0] * v[1] - u[1] * v[0];
      double facing = 0;
      for (int k = 0; k < 3; ++k) {
        facing += n[k] * (cell_normal[3 * a + k] + cell_normal[3 * b + k] + cell_normal[3 * d + k]);
      }
      if (facing < 0) {
        triangles.insert(triangles.end(), {a, d, b});
      } else {
        triangles.insert(triangles.end(), {a, b, d});
      }
    }
  }
  return triangles;
}

// Only the cells the triangles use, in the order they first use them, with their normals.
void KeepUsedCells(const Clusters& clusters, std::vector<std::uint32_t> triangles,
                   DecimatedMesh& out) {
  std::vector<std::uint32_t> remap(clusters.count.size(), UINT32_MAX);
  for (std::uint32_t& c : triangles) {
    if (remap[c] == UINT32_MAX) {
      remap[c] = static_cast<std::uint32_t>(out.positions.size());
      out.positions.push_back(clusters.Mean(c));
      out.normals.push_back(UnitOr(&clusters.normal[3 * c]));
    }
    c = remap[c];
  }
  out.triangles = std::move(triangles);
}

}  // namespace

DecimatedMesh DecimateByClustering(const Mesh& mesh, std::int64_t max_vertices) {
  const std::vector<std::uint32_t> used_ids = UsedVertices(mesh);
  max_vertices = std::max<std::int64_t>(max_vertices, 1);
  if (std::int64_t(used_ids.size()) <= max_vertices) return Triangulated(mesh, used_ids);

  const CellGrid grid = ChooseCells(mesh, used_ids, max_vertices);
  const Clusters clusters = Cluster(mesh, used_ids, grid);
  DecimatedMesh out;
  out.cell = grid.cell;
  KeepUsedCells(clusters, ClusterTriangles(mesh, clusters), out);
  return out;
}

}  // namespace dispex::view
