// SculptMapping (mapping_trace.h): the correspondence's grids as the kernel reads them, the
// crossings of every Ptex face edge into its neighbour's grid, and the faces at risk of folds.
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/vec3.h"
#include "extract/mapping/mapping_lattice.h"
#include "extract/mapping/mapping_trace.h"
#include "extract/parallel_errors.h"

namespace dispex::extract {

using namespace mapping;

namespace {

using Crossing = SculptMapping::Crossing;

// From `face` across `edge` where PtexAcrossEdge answers (faces, sub-faces, sub-face to quad):
// the rotation taking the edge's direction to its image's, checked to put the face's inside
// outside the neighbour.
Crossing DirectCrossing(std::span<const PtexFaceInfo> faces, std::span<const std::int32_t> sizes,
                        int face, int edge) {
  Crossing c;
  PtexEdgeSide s0, s1;
  if (!PtexAcrossEdge(faces, PtexFaceId(face), edge, 0.0, s0) ||
      !PtexAcrossEdge(faces, PtexFaceId(face), edge, 1.0, s1) || s0.face != s1.face ||
      s0.edge != s1.edge) {
    c.kind = kUnknown;
    return c;
  }
  const int m = sizes[static_cast<std::size_t>(face)];
  const int g = s0.face.value;
  const int mg = sizes[static_cast<std::size_t>(g)];
  if (mg == 0) return c;  // a hole: no sculpt there
  const Point a0 = EdgePoint(m, edge, 0), a1 = EdgePoint(m, edge, 1);
  const Point b0 = EdgePoint(mg, s0.edge, s0.t), b1 = EdgePoint(mg, s1.edge, s1.t);
  c.kind = kUnknown;
  for (int q = 0; q < 4; ++q) {
    if (Rotate(q, {a1.x - a0.x, a1.y - a0.y}) != Point{b1.x - b0.x, b1.y - b0.y}) continue;
    const Point r = Rotate(q, a0);
    const Iso iso{q, b0.x - r.x, b0.y - r.y};
    const Point inward = Rotate(1, EdgeDirection(edge));
    const Point inside = Apply(iso, {(a0.x + a1.x) / 2 + inward.x, (a0.y + a1.y) / 2 + inward.y});
    const bool outside = inside.x < 0 || inside.y < 0 || inside.x > 2 * mg || inside.y > 2 * mg;
    if (!outside) break;
    c = Crossing{g, kCell, static_cast<std::uint8_t>(q), iso.tx, iso.ty};
    break;
  }
  return c;
}

Crossing EdgeCrossing(std::span<const PtexFaceInfo> faces, std::span<const std::int32_t> sizes,
                      int face, int edge) {
  const PtexFaceInfo& info = faces[static_cast<std::size_t>(face)];
  const int g = info.adjfaces[static_cast<std::size_t>(edge)];
  if (g < 0 || sizes[static_cast<std::size_t>(g)] == 0) return Crossing{};
  if (!faces[static_cast<std::size_t>(g)].subface || info.subface) {
    return DirectCrossing(faces, sizes, face, edge);
  }
  // A quad beside sub-faces: the inverse of the named sub-face's crossing into the quad.
  const Crossing back =
      DirectCrossing(faces, sizes, g, info.adjedges[static_cast<std::size_t>(edge)]);
  if (back.kind != kCell || back.to != face) return Crossing{-1, kUnknown, 0, 0, 0};
  const Iso inverse = Inverse({back.q, back.tx, back.ty});
  return Crossing{g, kCell, static_cast<std::uint8_t>(inverse.q), inverse.tx, inverse.ty};
}

}  // namespace

StatusOr<SculptMapping> SculptMapping::Build(const SculptCorrespondence& correspondence,
                                             const Mesh& sculpt,
                                             std::span<const PtexFaceInfo> faces) {
  SculptCorrespondence needed;
  needed.levels = correspondence.levels;
  needed.grid_sizes = correspondence.grid_sizes;
  needed.cell_labels = correspondence.cell_labels;
  return Build(std::move(needed), sculpt, faces);
}

StatusOr<SculptMapping> SculptMapping::Build(SculptCorrespondence&& correspondence,
                                             const Mesh& sculpt,
                                             std::span<const PtexFaceInfo> faces) {
  const std::size_t num_faces = sculpt.num_faces();
  if (sculpt.face_indices.size() != 4 * num_faces) {
    return Status::Error(fmt::format("{}: the mapping needs a sculpt of quads", sculpt.source));
  }
  if (num_faces >= (std::size_t{1} << 30)) {
    return Status::Error(
        fmt::format("{}: {} faces, more than the mapping's 2^30", sculpt.source, num_faces));
  }
  const std::size_t num_ptex = correspondence.grid_sizes.size();
  if (faces.size() != num_ptex || correspondence.cell_labels.size() != num_faces) {
    return Status::Error(
        fmt::format("{}: the correspondence does not fit the sculpt", sculpt.source));
  }
  SculptMapping out;
  out.levels_ = correspondence.levels;
  out.grid_sizes_ = std::move(correspondence.grid_sizes);
  out.cell_offsets_.resize(num_ptex + 1, 0);
  for (std::size_t f = 0; f < num_ptex; ++f) {
    const std::int64_t m = out.grid_sizes_[f];
    out.cell_offsets_[f + 1] = out.cell_offsets_[f] + m * m;
  }
  if (out.cell_offsets_.back() != static_cast<std::int64_t>(num_faces)) {
    return Status::Error(fmt::format("{}: the correspondence's grids hold {} cells for {} faces",
                                     sculpt.source, out.cell_offsets_.back(), num_faces));
  }
  // The labels (4 x face + rotation) become face | rotation << 30, in place.
  out.cells_ = std::move(correspondence.cell_labels);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_faces, 1 << 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t c = range.begin(); c != range.end(); ++c) {
                        const std::uint32_t label = out.cells_[c];
                        out.cells_[c] = label >> 2 | (label & 3u) << 30;
                      }
                    });
  out.crossings_ = Crossings(faces, out.grid_sizes_);
  return out;
}

std::vector<SculptMapping::Crossing> SculptMapping::Crossings(std::span<const PtexFaceInfo> faces,
                                                              std::span<const std::int32_t> sizes) {
  std::vector<Crossing> out(4 * sizes.size());
  for (std::size_t f = 0; f < sizes.size(); ++f) {
    if (sizes[f] == 0) continue;
    for (int e = 0; e < 4; ++e) {
      out[4 * f + static_cast<std::size_t>(e)] = EdgeCrossing(faces, sizes, static_cast<int>(f), e);
    }
  }
  return out;
}

std::array<int, 2> SculptMapping::CrossEdge(const Crossing& crossing, int x, int y) {
  const Point p = Apply(Iso{crossing.q, crossing.tx, crossing.ty}, {x, y});
  return {p.x, p.y};
}

VertexId SculptMapping::GridVertex(int face, int a, int b, const Mesh& sculpt) const {
  // The vertex is the (a > i, b > j) corner of cell (i, j); the cell's corners (i, j),
  // (i + 1, j), (i + 1, j + 1), (i, j + 1) are its sculpt face's corners r, r + 1, r + 2, r + 3.
  const int m = grid_size(face);
  const int i = std::min(a, m - 1), j = std::min(b, m - 1);
  static constexpr int kCorner[2][2] = {{0, 3}, {1, 2}};  // [a > i][b > j]
  const std::uint32_t c = cell(face, i, j);
  const auto f = static_cast<std::size_t>(FaceOf(c));
  const int k = (RotationOf(c) + kCorner[a > i][b > j]) & 3;
  return VertexId(sculpt.face_indices[4 * f + static_cast<std::size_t>(k)]);
}

void SculptMapping::GridVertices(int face, const Mesh& sculpt, std::vector<VertexId>& out) const {
  // GridVertex row by row: vertex (a, b) is corner 0 of cell (a, b), the last column corner 1
  // of the row's last cell, the last row corner 3 of the cells below it, (m, m) corner 2.
  const auto m = static_cast<std::size_t>(grid_size(face));
  const std::size_t side = m + 1;
  out.resize(side * side);
  const std::uint32_t* cells =
      cells_.data() + static_cast<std::size_t>(cell_offsets_[static_cast<std::size_t>(face)]);
  const std::int32_t* corners = sculpt.face_indices.data();
  auto corner = [&](std::uint32_t c, int k) {
    return VertexId(corners[4 * static_cast<std::size_t>(FaceOf(c)) +
                            static_cast<std::size_t>((RotationOf(c) + k) & 3)]);
  };
  for (std::size_t b = 0; b < m; ++b) {
    const std::uint32_t* row = cells + b * m;
    VertexId* to = out.data() + b * side;
    for (std::size_t a = 0; a < m; ++a) to[a] = corner(row[a], 0);
    to[m] = corner(row[m - 1], 1);
  }
  const std::uint32_t* last = cells + (m - 1) * m;
  VertexId* to = out.data() + m * side;
  for (std::size_t a = 0; a < m; ++a) to[a] = corner(last[a], 3);
  to[m] = corner(last[m - 1], 2);
}

std::size_t SculptMapping::bytes() const {
  return grid_sizes_.capacity() * sizeof(std::int32_t) +
         cell_offsets_.capacity() * sizeof(std::int64_t) +
         cells_.capacity() * sizeof(std::uint32_t) + crossings_.capacity() * sizeof(Crossing) +
         blocks_.bytes();
}

Status SculptMapping::MarkFolds(const LimitSurface& surface, const Mesh& sculpt,
                                std::span<const PtexFaceInfo> faces) {
  const std::size_t num_ptex = grid_sizes_.size();
  std::vector<std::uint8_t> folded(num_ptex, 0);
  struct Scratch {
    std::optional<LimitEvaluator> evaluator;
    std::vector<float> positions, normals;
  };
  tbb::enumerable_thread_specific<Scratch> scratches;
  FirstError error;
  tbb::parallel_for(std::size_t{0}, num_ptex, [&](std::size_t f) {
    const int m = grid_sizes_[f];
    if (m == 0 || error.failed()) return;
    Scratch& w = scratches.local();
    if (!w.evaluator) w.evaluator.emplace(surface);
    // The limit normal at the centre of each block of up to 4 x 4 cells (every cell on grids
    // of up to 4 x 4): within a few degrees of every cell's own on fine grids, and a quad
    // turned over is far beyond that.
    const int g = std::min(m, std::max(4, m / 4));
    const std::size_t blocks = static_cast<std::size_t>(g) * g;
    w.positions.resize(3 * blocks);
    w.normals.resize(3 * blocks);
    const Status s =
        w.evaluator->EvaluateGrid(PtexFaceId(static_cast<int>(f)), g, g, w.positions, w.normals);
    if (!s.ok()) return error.Record(static_cast<int>(f), s);
    const Float3* p = sculpt.positions.data();
    for (int j = 0; j < m && !folded[f]; ++j) {
      for (int i = 0; i < m; ++i) {
        const std::int32_t* ids =
            sculpt.face_indices.data() +
            4 * static_cast<std::size_t>(FaceOf(cells_[static_cast<std::size_t>(
                    cell_offsets_[f] + static_cast<std::int64_t>(j) * m + i)]));
        const Vec3d n =
            Cross(ToVec3d(p[ids[2]]) - ToVec3d(p[ids[0]]), ToVec3d(p[ids[3]]) - ToVec3d(p[ids[1]]));
        const std::size_t b = static_cast<std::size_t>(j * g / m) * g + i * g / m;
        const Vec3d limit{w.normals[3 * b], w.normals[3 * b + 1], w.normals[3 * b + 2]};
        if (!(Dot(n, limit) > 0)) {
          folded[f] = 1;
          break;
        }
      }
    }
  });
  if (error.failed()) return error.status();
  // Two rings of faces across edges around each.
  fold_risk_ = folded;
  for (int ring = 0; ring < 2; ++ring) {
    std::vector<std::uint8_t> next = fold_risk_;
    for (std::size_t f = 0; f < num_ptex; ++f) {
      if (!fold_risk_[f]) continue;
      for (std::int32_t g : faces[f].adjfaces) {
        if (g >= 0) next[static_cast<std::size_t>(g)] = 1;
      }
    }
    fold_risk_ = std::move(next);
  }
  return Status::Ok();
}

std::size_t SculptMapping::fold_risk_faces() const {
  return static_cast<std::size_t>(std::count(fold_risk_.begin(), fold_risk_.end(), 1));
}

MappingCounters& MappingCounters::operator+=(const MappingCounters& other) {
  queries += other.queries;
  decided += other.decided;
  quads += other.quads;
  far_sheets += other.far_sheets;
  return *this;
}

}  // namespace dispex::extract
