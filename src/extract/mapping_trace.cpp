#include "extract/mapping_trace.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string_view>

#include "core/vec3.h"
#include "dispex/ptex_sampler.h"
#include "extract/far_sheets.h"
#include "extract/parallel_errors.h"

namespace dispex::extract {

namespace {

constexpr int kMargin = kMaxRings;  // the apron: cells laid out beyond each edge of the face
constexpr int kMaxHops = 6;         // edge crossings to reach one apron cell

enum SlotState : std::uint8_t {
  kNone = 0,     // no surface there: beyond a boundary, a hole face
  kCell = 1,     // a sculpt quad
  kUnknown = 2,  // not laid out (ambiguous or too far): a sample whose rings reach it is undecided
  kFan = 3,      // the block diagonal to an extraordinary corner: its fan holds the cells
};

// ---- The lattice of cells across Ptex face edges -------------------------------------------
// Points of a face's grid in doubled units: vertex (i, j) at (2i, 2j), cell centres odd.

struct Point {
  int x = 0, y = 0;
  bool operator==(const Point&) const = default;
};

// p' = R_q p + (tx, ty), R_q a rotation by q quarter turns counter-clockwise.
struct Iso {
  int q = 0, tx = 0, ty = 0;
  bool operator==(const Iso&) const = default;
};

Point Rotate(int q, Point p) {
  switch (q & 3) {
    case 0:
      return p;
    case 1:
      return {-p.y, p.x};
    case 2:
      return {-p.x, -p.y};
    default:
      return {p.y, -p.x};
  }
}

Point Apply(const Iso& s, Point p) {
  const Point r = Rotate(s.q, p);
  return {r.x + s.tx, r.y + s.ty};
}

// `second` after `first`.
Iso Then(const Iso& first, const Iso& second) {
  const Point t = Rotate(second.q, {first.tx, first.ty});
  return {(first.q + second.q) & 3, t.x + second.tx, t.y + second.ty};
}

Iso Inverse(const Iso& s) {
  const int q = (4 - s.q) & 3;
  const Point t = Rotate(q, {-s.tx, -s.ty});
  return {q, t.x, t.y};
}

Point CornerPoint(int m, int corner) {
  switch (corner & 3) {
    case 0:
      return {0, 0};
    case 1:
      return {2 * m, 0};
    case 2:
      return {2 * m, 2 * m};
    default:
      return {0, 2 * m};
  }
}

// Edge e runs from corner e to corner e + 1.
Point EdgeDirection(int edge) {
  static constexpr Point kDirections[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  return kDirections[edge & 3];
}

Point EdgePoint(int m, int edge, double t) {
  double u = 0, v = 0;
  PtexEdgePoint(edge, t, u, v);
  return {static_cast<int>(std::lround(2 * m * u)), static_cast<int>(std::lround(2 * m * v))};
}

}  // namespace

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
  const int m = grid_size(face);
  const auto side = static_cast<std::size_t>(m) + 1;
  out.resize(side * side);
  for (int b = 0; b <= m; ++b) {
    for (int a = 0; a <= m; ++a) {
      out[static_cast<std::size_t>(b) * side + static_cast<std::size_t>(a)] =
          GridVertex(face, a, b, sculpt);
    }
  }
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

namespace {

// ---- Laying out a face's neighbourhood -----------------------------------------------------

struct Located {
  std::uint8_t kind = kNone;  // kCell: found in `face` at `p`
  int face = -1;
  Point p;
  Iso iso;  // from the starting face's grid to `face`'s
};

Located NotFound(std::uint8_t kind) {
  Located l;
  l.kind = kind;
  return l;
}

// Where point p of face h's grid (doubled units; outside it, across its edges) lies: crossing
// one edge at a time, and at a corner both ways round, which must agree.
Located Locate(const SculptMapping& mapping, int h, Point p, Iso iso, int depth) {
  const int size = 2 * mapping.grid_size(h);
  const bool out[4] = {p.y<0, p.x> size, p.y > size, p.x < 0};
  const int count = out[0] + out[1] + out[2] + out[3];
  if (count == 0) return Located{kCell, h, p, iso};
  if (depth >= kMaxHops || count > 2) return NotFound(kUnknown);
  auto cross = [&](int edge) {
    const SculptMapping::Crossing& c = mapping.crossing(h, edge);
    if (c.kind != kCell) return NotFound(c.kind);
    const Iso step{c.q, c.tx, c.ty};
    return Locate(mapping, c.to, Apply(step, p), Then(iso, step), depth + 1);
  };
  int edges[2], k = 0;
  for (int e = 0; e < 4; ++e) {
    if (out[e]) edges[k++] = e;
  }
  if (count == 1) return cross(edges[0]);
  const Located a = cross(edges[0]), b = cross(edges[1]);
  if (a.kind == kNone && b.kind == kNone) return a;
  if (a.kind == kCell && b.kind == kCell && a.face == b.face && a.p == b.p && a.iso == b.iso) {
    return a;
  }
  return NotFound(kUnknown);
}

// Locate for a point of face h's grid beyond its edge `edge` only: the crossing, then, where
// the point lands inside the face across, that face's grid without a further call.
Located LocateAcross(const SculptMapping& mapping, int h, int edge, Point p) {
  const SculptMapping::Crossing& c = mapping.crossing(h, edge);
  if (c.kind != kCell) return NotFound(c.kind);
  const Iso step = Then(Iso{}, Iso{c.q, c.tx, c.ty});
  const Point q = Apply(step, p);
  const int size = 2 * mapping.grid_size(c.to);
  if (q.x >= 0 && q.y >= 0 && q.x <= size && q.y <= size) return Located{kCell, c.to, q, step};
  return Locate(mapping, c.to, q, step, 1);
}

enum class CornerKind : std::uint8_t { kRegular, kNone, kFan, kUnknown };

// The faces around corner `c` of `face` (not `face` itself), each with the corner of its own
// that meets there: walking across one edge at the vertex after another, both ways round when
// a boundary stops the walk.
CornerKind WalkCorner(const SculptMapping& mapping, int face, int c,
                      std::vector<std::pair<int, int>>& around) {
  around.clear();
  bool closed = false;
  for (int way = 0; way < 2 && !closed; ++way) {
    int h = face, ch = c;
    int edge = way == 0 ? c : (c + 3) & 3;
    for (int step = 0;; ++step) {
      if (step > 64) return CornerKind::kUnknown;
      const SculptMapping::Crossing& x = mapping.crossing(h, edge);
      if (x.kind == kNone) break;
      if (x.kind != kCell) return CornerKind::kUnknown;
      const Iso iso{x.q, x.tx, x.ty};
      const int mh = mapping.grid_size(h), g = x.to, mg = mapping.grid_size(g);
      const Point corner = Apply(iso, CornerPoint(mh, ch));
      int cg = -1;
      for (int k = 0; k < 4; ++k) {
        if (CornerPoint(mg, k) == corner) cg = k;
      }
      // Mid-edge of a quad beside sub-faces: the quad's grid runs on through the vertex.
      if (cg < 0) return CornerKind::kRegular;
      // A point of the crossed edge next to the vertex tells which edge of g it is.
      const Point d = EdgeDirection(edge);
      const Point at = CornerPoint(mh, ch);
      const Point near = ch == edge ? Point{at.x + d.x, at.y + d.y} : Point{at.x - d.x, at.y - d.y};
      const Point n = Apply(iso, near);
      const int in = n.y == 0 ? 0 : n.x == 2 * mg ? 1 : n.y == 2 * mg ? 2 : 3;
      if (in != cg && in != ((cg + 3) & 3)) return CornerKind::kUnknown;
      if (g == face) {
        if (cg != c) return CornerKind::kUnknown;
        closed = true;
        break;
      }
      around.emplace_back(g, cg);
      h = g;
      ch = cg;
      edge = in == cg ? (cg + 3) & 3 : cg;
    }
  }
  if (closed && around.size() == 3) return CornerKind::kRegular;
  if (!closed && around.size() <= 1) return CornerKind::kNone;
  return CornerKind::kFan;
}

// The positions of the apron's corners, relative to the face's middle vertex, for the float
// filter: each slot's corners, its face's corner `slot.corner + k` at its corner k.
void FillLattice(const Mesh& sculpt, MappingScratch& w) {
  const int m = w.m, width = m + 2 * kMargin, points = width + 1;
  w.lattice.assign(3 * static_cast<std::size_t>(points) * points, 0.0f);
  const int mid = m / 2;
  // The middle vertex: corner 0 of cell (mid, mid) (for m = 1, the face's corner 0).
  const MappingScratch::Slot& ms =
      w.apron[static_cast<std::size_t>((mid + kMargin) * width + mid + kMargin)];
  const Float3& c = sculpt.positions[static_cast<std::size_t>(
      sculpt.face_indices[4 * static_cast<std::size_t>(ms.face) + ms.corner])];
  w.centre[0] = c.x;
  w.centre[1] = c.y;
  w.centre[2] = c.z;
  float extent = 0;
  // Each point from one slot that has it as a corner: mostly its own slot (k = 0), whose
  // quad's corner ids are fetched 16 points ahead and their position 6 ahead (the sculpt's
  // arrays are read at random).
  static constexpr int kDx[4] = {0, -1, -1, 0}, kDy[4] = {0, 0, -1, -1};
  const std::int32_t* const indices = sculpt.face_indices.data();
  for (int b = 0; b < points; ++b) {
    for (int a = 0; a < points; ++a) {
      if (b < width && a + 16 < width) {
        const MappingScratch::Slot& ahead = w.apron[static_cast<std::size_t>(b * width + a + 16)];
        if (ahead.state == kCell) __builtin_prefetch(indices + 4 * std::size_t(ahead.face));
      }
      if (b < width && a + 6 < width) {
        const MappingScratch::Slot& ahead = w.apron[static_cast<std::size_t>(b * width + a + 6)];
        if (ahead.state == kCell) {
          __builtin_prefetch(&sculpt.positions[static_cast<std::size_t>(
              indices[4 * std::size_t(ahead.face) + ahead.corner])]);
        }
      }
      for (int k = 0; k < 4; ++k) {
        const int sa = a + kDx[k], sb = b + kDy[k];
        if (sa < 0 || sb < 0 || sa >= width || sb >= width) continue;
        const MappingScratch::Slot& slot = w.apron[static_cast<std::size_t>(sb * width + sa)];
        if (slot.state != kCell) continue;
        const std::int32_t* ids =
            sculpt.face_indices.data() + 4 * static_cast<std::size_t>(slot.face);
        const Float3& v = sculpt.positions[static_cast<std::size_t>(ids[(slot.corner + k) & 3])];
        float* q = &w.lattice[3 * static_cast<std::size_t>(b * points + a)];
        q[0] = static_cast<float>(double(v.x) - w.centre[0]);
        q[1] = static_cast<float>(double(v.y) - w.centre[1]);
        q[2] = static_cast<float>(double(v.z) - w.centre[2]);
        extent = std::max({extent, std::fabs(q[0]), std::fabs(q[1]), std::fabs(q[2])});
        break;
      }
    }
  }
  w.extent = extent;
}

// The apron of `face`; without `margins`, its cells only: every slot beyond the face is
// kUnknown (a ring that reaches one leaves its sample undecided) and no corner has a fan.
void LayOut(const SculptMapping& mapping, int face, MappingScratch& w, bool margins) {
  const int m = mapping.grid_size(face);
  const int width = m + 2 * kMargin;
  w.face = face;
  w.m = m;
  w.margins = margins;
  w.apron.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(width), {});
  CornerKind corners[4];
  std::vector<std::pair<int, int>>& around = w.around;
  for (int c = 0; c < 4; ++c) {
    corners[c] = margins ? WalkCorner(mapping, face, c, around) : CornerKind::kUnknown;
    w.fans[c].clear();
    w.fan_corner[c] = corners[c] == CornerKind::kFan;
    if (!w.fan_corner[c]) continue;
    for (const auto& [h, ch] : around) {
      const int mh = mapping.grid_size(h), reach = std::min(kMargin, mh);
      for (int q = 0; q < reach; ++q) {
        for (int p = 0; p < reach; ++p) {
          const int i = ch == 0 || ch == 3 ? p : mh - 1 - p;
          const int j = ch == 0 || ch == 1 ? q : mh - 1 - q;
          w.fans[c].push_back({SculptMapping::FaceOf(mapping.cell(h, i, j)), std::max(p, q)});
        }
      }
    }
    std::stable_sort(w.fans[c].begin(), w.fans[c].end(),
                     [](const auto& a, const auto& b) { return a.offset < b.offset; });
  }
  for (int b = -kMargin; b < m + kMargin; ++b) {
    for (int a = -kMargin; a < m + kMargin; ++a) {
      MappingScratch::Slot& slot =
          w.apron[static_cast<std::size_t>((b + kMargin) * width + a + kMargin)];
      const bool out_a = a < 0 || a >= m, out_b = b < 0 || b >= m;
      if (!out_a && !out_b) {
        const std::uint32_t cell = mapping.cell(face, a, b);
        slot = {SculptMapping::FaceOf(cell), static_cast<std::uint8_t>(cell >> 30), kCell};
        continue;
      }
      if (!margins) {
        slot.state = kUnknown;
        continue;
      }
      if (out_a && out_b) {
        const int c = b < 0 ? (a < 0 ? 0 : 1) : (a < 0 ? 3 : 2);
        if (corners[c] == CornerKind::kNone) continue;
        if (corners[c] == CornerKind::kFan || corners[c] == CornerKind::kUnknown) {
          slot.state = corners[c] == CornerKind::kFan ? kFan : kUnknown;
          continue;
        }
      }
      const Located at =
          out_a != out_b ? LocateAcross(mapping, face, out_b ? (b < 0 ? 0 : 2) : (a < 0 ? 3 : 1),
                                        {2 * a + 1, 2 * b + 1})
                         : Locate(mapping, face, {2 * a + 1, 2 * b + 1}, Iso{}, 0);
      if (at.kind != kCell) {
        slot.state = at.kind;
        continue;
      }
      const int ci = (at.p.x - 1) / 2, cj = (at.p.y - 1) / 2;
      const std::uint32_t cell = mapping.cell(at.face, ci, cj);
      // Which corner of the cell there the slot's lower-left corner is.
      const Point q = Apply(at.iso, {2 * a, 2 * b});
      const int k = q.y == 2 * cj ? (q.x == 2 * ci ? 0 : 1) : (q.x == 2 * ci ? 3 : 2);
      slot = {SculptMapping::FaceOf(cell),
              static_cast<std::uint8_t>((k + SculptMapping::RotationOf(cell)) & 3), kCell};
    }
  }
  w.lattice_face = -1;
}

}  // namespace

void LayOutNearBlocks(const SculptMapping& mapping, int face, MappingScratch& w) {
  const SculptBlocks& blocks = mapping.blocks();
  const int b = blocks.block_size(face), per = blocks.blocks_per_side(face);
  w.near_face = face;
  w.near_starts.assign(1, 0);
  w.near_ids.clear();
  int corner_state[4];  // 0: none or regular, 1: a fan
  std::vector<std::pair<int, int>>& around = w.around;
  for (int c = 0; c < 4; ++c)
    corner_state[c] = WalkCorner(mapping, face, c, around) == CornerKind::kFan;
  auto add = [&](std::int64_t id) {
    const auto begin = w.near_ids.begin() + w.near_starts.back();
    if (std::find(begin, w.near_ids.end(), id) == w.near_ids.end()) w.near_ids.push_back(id);
  };
  // The block of the cell at (a, c) of the face's lattice: face and block indices, or face -1.
  auto block_of = [&](int a, int c) {
    const Located at = Locate(mapping, face, {2 * a + 1, 2 * c + 1}, Iso{}, 0);
    if (at.kind != kCell) return std::array<int, 3>{-1, 0, 0};
    const int bg = blocks.block_size(at.face);
    return std::array<int, 3>{at.face, (at.p.x - 1) / 2 / bg, (at.p.y - 1) / 2 / bg};
  };
  for (int bj = -1; bj <= per; ++bj) {
    for (int bi = -1; bi <= per; ++bi) {
      const bool out_i = bi < 0 || bi >= per, out_j = bj < 0 || bj >= per;
      if (!out_i && !out_j) {
        add(blocks.id(face, bi, bj));
      } else if (out_i && out_j && corner_state[bj < 0 ? (bi < 0 ? 0 : 1) : (bi < 0 ? 3 : 2)]) {
        // The diagonal slot at an extraordinary corner: the corner block of each face there.
        const int c = bj < 0 ? (bi < 0 ? 0 : 1) : (bi < 0 ? 3 : 2);
        WalkCorner(mapping, face, c, around);
        for (const auto& [h, ch] : around) {
          const int ph = blocks.blocks_per_side(h);
          add(blocks.id(h, ch == 0 || ch == 3 ? 0 : ph - 1, ch == 0 || ch == 1 ? 0 : ph - 1));
        }
      } else {
        // The slot's corner cells; where all four land in one face, the blocks between them
        // (the crossings are isometries of the lattices), else cell by cell.
        const int a0 = bi * b, a1 = a0 + b - 1, c0 = bj * b, c1 = c0 + b - 1;
        const std::array<int, 3> k[4] = {block_of(a0, c0), block_of(a1, c0), block_of(a1, c1),
                                         block_of(a0, c1)};
        if (k[0][0] >= 0 && k[0][0] == k[1][0] && k[0][0] == k[2][0] && k[0][0] == k[3][0]) {
          const int i0 = std::min({k[0][1], k[1][1], k[2][1], k[3][1]});
          const int i1 = std::max({k[0][1], k[1][1], k[2][1], k[3][1]});
          const int j0 = std::min({k[0][2], k[1][2], k[2][2], k[3][2]});
          const int j1 = std::max({k[0][2], k[1][2], k[2][2], k[3][2]});
          for (int j = j0; j <= j1; ++j) {
            for (int i = i0; i <= i1; ++i) add(blocks.id(k[0][0], i, j));
          }
        } else {
          for (int c = c0; c <= c1; ++c) {
            for (int a = a0; a <= a1; ++a) {
              const std::array<int, 3> at = block_of(a, c);
              if (at[0] >= 0) add(blocks.id(at[0], at[1], at[2]));
            }
          }
        }
      }
      w.near_starts.push_back(static_cast<std::int32_t>(w.near_ids.size()));
    }
  }
}

namespace {

// ---- Lines against quads -------------------------------------------------------------------

// Direction components below 2^-24 of the largest are zero (the Tracer's rule).
Float3 FlushTiny(const Float3& d) {
  const float floor = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}) * 0x1p-24f;
  return Float3{std::fabs(d.x) < floor ? 0.0f : d.x, std::fabs(d.y) < floor ? 0.0f : d.y,
                std::fabs(d.z) < floor ? 0.0f : d.z};
}

bool Finite(const Float3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// One sample's line o + t d and the plane across it the quads' corners are projected onto.
// Projections and edge values are computed the same way for every quad, so two triangles that
// share an edge see the line on opposite sides of it, or on it (this needs the products rounded
// one by one: no fused multiply-add, which ISO C++ mode leaves off).
struct Line {
  Float3 o, d;
  Vec3d origin, e1, e2;

  Line() = default;
  Line(const Float3& o_in, const Float3& d_in) : o(o_in), d(d_in), origin(ToVec3d(o_in)) {
    const Vec3d dir = ToVec3d(d);
    const double ax = std::fabs(dir.x), ay = std::fabs(dir.y), az = std::fabs(dir.z);
    e1 = ax <= ay && ax <= az ? Vec3d{0, dir.z, -dir.y}
         : ay <= az           ? Vec3d{-dir.z, 0, dir.x}
                              : Vec3d{dir.y, -dir.x, 0};
    e2 = Cross(dir, e1);
  }
  void Project(const Float3& v, double& px, double& py) const {
    const Vec3d w = ToVec3d(v) - origin;
    px = Dot(w, e1);
    py = Dot(w, e2);
  }
};

double EdgeValue(double ax, double ay, double bx, double by) {
  return ax * by - ay * bx;
}

bool Inside(double a, double b, double c) {
  return ((a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0)) &&
         (a != 0 || b != 0 || c != 0);
}

// The Tracer's t (batch_kernels.h, ExactT): the line against the plane of triangle (a, b, c).
double PlaneT(const Float3& fa, const Float3& fb, const Float3& fc, const Float3& o,
              const Float3& d, double& den) {
  const Vec3d a = ToVec3d(fa);
  const Vec3d n = Cross(ToVec3d(fb) - a, ToVec3d(fc) - a);
  den = n.x * d.x + n.y * d.y + n.z * d.z;
  return (n.x * (double(fa.x) - o.x) + n.y * (double(fa.y) - o.y) + n.z * (double(fa.z) - o.z)) /
         den;
}

struct Candidate {
  float t = 0;         // along +d (a -n hit has t <= 0)
  int ring = INT_MAX;  // where it was found
  std::int32_t face = -1;
  bool front_plus = false;  // dot(+d, normal) <= 0
  bool found() const { return face >= 0; }
};

// One sample's crossings, as the rings are tested.
struct Crossings {
  float distance = 0;
  Candidate plus, minus;    // the nearest within the window on either side
  int any_ring = INT_MAX;   // the innermost ring where the line crossed a quad at all
  bool degenerate = false;  // crossed a triangle with no plane (t not finite)
  // Which way round the quads tested face the line (bit 0: counter-clockwise seen along -d,
  // bit 1: clockwise or edge-on): both means the sculpt folds over or stands edge-on nearby.
  unsigned orientations = 0;

  void Add(float t, double den, int ring, std::int32_t face) {
    any_ring = std::min(any_ring, ring);
    const bool front_plus = !(den > 0);
    if (!(t < 0) && t <= distance && (!plus.found() || t < plus.t)) {
      plus = {t, ring, face, front_plus};
    }
    const float tm = -t;
    if (!(tm < 0) && tm <= distance && (!minus.found() || tm < -minus.t)) {
      minus = {t, ring, face, front_plus};
    }
  }
};

// TestQuad with its corners' projections given: (x_k, y_k) that of the face's corner k.
void TestProjectedQuad(const Line& line, const Mesh& sculpt, std::int32_t face, int ring, double x0,
                       double y0, double x1, double y1, double x2, double y2, double x3, double y3,
                       Crossings& x) {
  const std::int32_t* ids = sculpt.face_indices.data() + 4 * static_cast<std::size_t>(face);
  const Float3* p = sculpt.positions.data();
  const Float3& v0 = p[ids[0]];
  const Float3& v1 = p[ids[1]];
  const Float3& v2 = p[ids[2]];
  const Float3& v3 = p[ids[3]];
  const double e01 = EdgeValue(x0, y0, x1, y1), e13 = EdgeValue(x1, y1, x3, y3);
  const double e30 = EdgeValue(x3, y3, x0, y0), e23 = EdgeValue(x2, y2, x3, y3);
  const double e12 = EdgeValue(x1, y1, x2, y2);
  x.orientations |= e01 + e12 + e23 + e30 > 0 ? 1u : 2u;
  double den = 0;
  if (Inside(e01, e13, e30)) {
    const double t = PlaneT(v0, v1, v3, line.o, line.d, den);
    if (!std::isfinite(t)) {
      x.degenerate = true;
    } else {
      x.Add(static_cast<float>(t), den, ring, face);
    }
  }
  if (Inside(e23, -e13, e12)) {
    const double t = PlaneT(v2, v3, v1, line.o, line.d, den);
    if (!std::isfinite(t)) {
      x.degenerate = true;
    } else {
      x.Add(static_cast<float>(t), den, ring, face);
    }
  }
}

void TestQuad(const Line& line, const Mesh& sculpt, std::int32_t face, int ring, Crossings& x) {
  const std::int32_t* ids = sculpt.face_indices.data() + 4 * static_cast<std::size_t>(face);
  const Float3* p = sculpt.positions.data();
  double px[4], py[4];
  for (int k = 0; k < 4; ++k) line.Project(p[ids[k]], px[k], py[k]);
  TestProjectedQuad(line, sculpt, face, ring, px[0], py[0], px[1], py[1], px[2], py[2], px[3],
                    py[3], x);
}

// The hit `policy` keeps (TraceNormals' choice between the two rays), and whether it is -n's.
const Candidate* Kept(const Crossings& x, HitPolicy policy, bool& negative) {
  const Candidate* pick = nullptr;
  switch (policy) {
    case HitPolicy::kNearest:
      // A tie keeps +n; so does a +n hit at t = 0, after which -n is not cast.
      if (x.plus.found() && !(x.minus.found() && -x.minus.t < x.plus.t)) {
        pick = &x.plus;
      } else if (x.minus.found()) {
        pick = &x.minus;
      }
      break;
    case HitPolicy::kOutsideFirst:
      pick = x.plus.found() ? &x.plus : x.minus.found() ? &x.minus : nullptr;
      break;
    case HitPolicy::kInsideFirst:
      pick = x.minus.found() ? &x.minus : x.plus.found() ? &x.plus : nullptr;
      break;
  }
  negative = pick == &x.minus;
  return pick;
}

int CornerDistance(int ci, int cj, int m, int corner) {
  const int di = corner == 0 || corner == 3 ? ci : m - 1 - ci;
  const int dj = corner == 0 || corner == 1 ? cj : m - 1 - cj;
  return std::max(di, dj);
}

// Tests ring `r` around cell (ci, cj); false when part of it is not laid out.
bool TestRing(const MappingScratch& w, const Mesh& sculpt, const Line& line, int ci, int cj, int r,
              Crossings& x, std::uint64_t& quads) {
  const int width = w.m + 2 * kMargin;
  auto test_slot = [&](int a, int b) {
    const MappingScratch::Slot& slot =
        w.apron[static_cast<std::size_t>((b + kMargin) * width + a + kMargin)];
    if (slot.state == kCell) {
      TestQuad(line, sculpt, slot.face, r, x);
      ++quads;
    }
    return slot.state != kUnknown;
  };
  bool complete = true;
  if (r == 0) {
    complete = test_slot(ci, cj);
  } else {
    for (int a = ci - r; a <= ci + r; ++a) {
      complete &= test_slot(a, cj - r);
      complete &= test_slot(a, cj + r);
    }
    for (int b = cj - r + 1; b <= cj + r - 1; ++b) {
      complete &= test_slot(ci - r, b);
      complete &= test_slot(ci + r, b);
    }
  }
  for (int c = 0; c < 4; ++c) {
    if (!w.fan_corner[c]) continue;
    const int offset = r - 1 - CornerDistance(ci, cj, w.m, c);
    if (offset < 0) continue;
    for (const MappingScratch::FanCell& cell : w.fans[c]) {
      if (cell.offset > offset) break;
      if (cell.offset < offset) continue;
      TestQuad(line, sculpt, cell.face, r, x);
      ++quads;
    }
  }
  return complete;
}

// ---- One sample, ring after ring -----------------------------------------------------------

// Writes sample k's answer when rings 0..r decide it; false when they do not yet.
bool Decide(const Crossings& x, int r, HitPolicy policy, std::size_t k, const NormalHits& out) {
  bool negative = false;
  const Candidate* kept = Kept(x, policy, negative);
  if (kept != nullptr && kept->ring <= r - 1) {
    out.t[k] = kept->t;
    const bool back = negative ? kept->front_plus : !kept->front_plus;
    out.flags[k] = static_cast<std::uint8_t>(HitFlags::kHit | (negative ? HitFlags::kNegative : 0) |
                                             (back ? HitFlags::kBackFace : 0));
    if (!out.prim.empty()) out.prim[k] = SculptPrimId(kept->face);
    return true;
  }
  if (kept == nullptr && x.any_ring <= r - 1) {
    out.t[k] = std::numeric_limits<float>::quiet_NaN();
    out.flags[k] = 0;
    if (!out.prim.empty()) out.prim[k] = SculptPrimId();
    return true;
  }
  return false;
}

// Sample k over cell (ci, cj), rings 0 to kMaxRings; whether it was decided.
bool TraceRings(const MappingScratch& w, const Mesh& sculpt, const Line& line, int ci, int cj,
                const NormalQuery& query, std::size_t k, const NormalHits& out,
                std::uint64_t& quads) {
  Crossings x;
  x.distance = query.distance;
  for (int r = 0; r <= kMaxRings; ++r) {
    if (!TestRing(w, sculpt, line, ci, cj, r, x, quads) || x.degenerate || x.orientations == 3) {
      return false;
    }
    if (Decide(x, r, query.policy, k, out)) return true;
  }
  return false;
}

// ---- The samples of one cell at once -------------------------------------------------------
// The cell's 3 x 3 slots (rings 0 and 1) against up to kLanes samples: the lattice's 16 points
// projected along each sample's normal in float, each edge's value once, and a triangle
// classified as surely met, surely missed (beyond a bound on the float error) or unsure; the
// met and the unsure go to the exact test in double (the same as TestQuad's).

constexpr int kLanes = 4;
using f4 = float __attribute__((vector_size(16)));
using i4 = std::int32_t __attribute__((vector_size(16)));

f4 Abs(f4 a) {
  return a < 0 ? -a : a;
}
f4 Max(f4 a, f4 b) {
  return a > b ? a : b;
}
f4 Min(f4 a, f4 b) {
  return a < b ? a : b;
}
unsigned Bits(i4 mask) {
#if defined(__SSE__)
  return static_cast<unsigned>(__builtin_ia32_movmskps(reinterpret_cast<f4>(mask)));
#else
  return (mask[0] & 1u) | (mask[1] & 2u) | (mask[2] & 4u) | (mask[3] & 8u);
#endif
}

struct Lanes {
  int count = 0;
  std::size_t k[kLanes] = {};
  Float3 o[kLanes], d[kLanes];   // d FlushTiny'd
  f4 ox = {}, oy = {}, oz = {};  // origins relative to the lattice's centre
  f4 e1x = {}, e1y = {}, e1z = {}, e2x = {}, e2y = {}, e2z = {};  // Line's basis, in float
};

void AddLane(const MappingScratch& w, std::size_t k, const Float3& o, const Float3& d, Lanes& b) {
  const int l = b.count++;
  b.k[l] = k;
  b.o[l] = o;
  b.d[l] = d;
  b.ox[l] = static_cast<float>(double(o.x) - w.centre[0]);
  b.oy[l] = static_cast<float>(double(o.y) - w.centre[1]);
  b.oz[l] = static_cast<float>(double(o.z) - w.centre[2]);
  const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  const float e1[3] = {ax <= ay && ax <= az ? 0
                       : ay <= az           ? -d.z
                                            : d.y,
                       ax <= ay && ax <= az ? d.z
                       : ay <= az           ? 0
                                            : -d.x,
                       ax <= ay && ax <= az ? -d.y
                       : ay <= az           ? d.x
                                            : 0};
  b.e1x[l] = e1[0], b.e1y[l] = e1[1], b.e1z[l] = e1[2];
  b.e2x[l] = d.y * e1[2] - d.z * e1[1];
  b.e2y[l] = d.z * e1[0] - d.x * e1[2];
  b.e2z[l] = d.x * e1[1] - d.y * e1[0];
}

// Triangle (a, b, c) of a face by the exact test: whether the line meets it.
bool ExactInside(const Line& line, const Float3& fa, const Float3& fb, const Float3& fc) {
  double xa, ya, xb, yb, xc, yc;
  line.Project(fa, xa, ya);
  line.Project(fb, xb, yb);
  line.Project(fc, xc, yc);
  return Inside(EdgeValue(xa, ya, xb, yb), EdgeValue(xb, yb, xc, yc), EdgeValue(xc, yc, xa, ya));
}

// Rings 0 and 1 of cell (ci, cj), whose 9 slots are all quads, for the lanes: decided[l] when
// they decide lane l, settled[l] when it is undecided whatever more rings hold (a fold, a
// degenerate triangle); the others need more rings.
void TraceBlock(const MappingScratch& w, const Mesh& sculpt, int ci, int cj, const Lanes& b,
                const NormalQuery& query, const NormalHits& out, bool decided[kLanes],
                bool settled[kLanes]) {
  const int width = w.m + 2 * kMargin, points = width + 1;
  f4 px[16], py[16];
  f4 reach = {};
  for (int q = 0; q < 16; ++q) {
    const int x = ci - 1 + (q & 3) + kMargin, y = cj - 1 + (q >> 2) + kMargin;
    const float* v = &w.lattice[3 * static_cast<std::size_t>(y * points + x)];
    const f4 wx = v[0] - b.ox, wy = v[1] - b.oy, wz = v[2] - b.oz;
    px[q] = wx * b.e1x + wy * b.e1y + wz * b.e1z;
    py[q] = wx * b.e2x + wy * b.e2y + wz * b.e2z;
    reach = Max(reach, Abs(px[q]) + Abs(py[q]));
  }
  // An edge value's error: the projections are within 2^-19 of the coordinates' magnitude
  // (lattice and origin, relative to the centre; each step rounds to float once) and an edge
  // value multiplies projections of at most `reach`.
  const f4 magnitude = Max(Max(Abs(b.ox), Abs(b.oy)), Max(Abs(b.oz), f4{} + w.extent));
  const f4 tol = 4 * reach * magnitude * 0x1p-19f + reach * reach * 0x1p-19f;
  auto edge = [&](int a, int c) { return px[a] * py[c] - py[a] * px[c]; };
  f4 h[4][3], v[3][4];
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 3; ++x) h[y][x] = edge(y * 4 + x, y * 4 + x + 1);
  }
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) v[y][x] = edge(y * 4 + x, (y + 1) * 4 + x);
  }
  const unsigned active = (1u << b.count) - 1;
  Crossings x[kLanes];
  for (int l = 0; l < kLanes; ++l) x[l].distance = query.distance;
  i4 counter_clockwise = {}, clockwise = {};
  const Float3* p = sculpt.positions.data();
  for (int sy = 0; sy < 3; ++sy) {
    for (int sx = 0; sx < 3; ++sx) {
      const MappingScratch::Slot& slot = w.apron[static_cast<std::size_t>(
          (cj - 1 + sy + kMargin) * width + ci - 1 + sx + kMargin)];
      const int ring = sx == 1 && sy == 1 ? 0 : 1;
      const int c0 = sy * 4 + sx, c1 = c0 + 1, c2 = c0 + 5, c3 = c0 + 4;
      // The face's corner 2 at this slot corner; its triangle (v0 v1 v3) lies opposite it.
      const int corner2 = (2 - slot.corner) & 3;
      const bool main = (corner2 & 1) != 0;  // the diagonal runs through slot corners 0 and 2
      const f4 dg = main ? edge(c0, c2) : edge(c1, c3);
      const f4 bottom = h[sy][sx], right = v[sy][sx + 1], top = -h[sy + 1][sx], left = -v[sy][sx];
      const i4 ccw = bottom + right + top + left > 0;
      counter_clockwise |= ccw;
      clockwise |= ~ccw;
      // The slot's two triangles, each by its edge values and the slot corner it leaves out.
      const f4 tri[2][3] = {{bottom, main ? right : dg, main ? -dg : left},
                            {main ? dg : right, top, main ? left : -dg}};
      const int left_out[2] = {main ? 3 : 2, main ? 1 : 0};
      const std::int32_t* ids =
          sculpt.face_indices.data() + 4 * static_cast<std::size_t>(slot.face);
      for (int t = 0; t < 2; ++t) {
        const f4 low = Min(Min(tri[t][0], tri[t][1]), tri[t][2]);
        const f4 high = Max(Max(tri[t][0], tri[t][1]), tri[t][2]);
        const unsigned maybe = Bits((low >= -tol) | (high <= tol)) & active;
        if (maybe == 0) continue;
        const unsigned sure = Bits((low > tol) | (high < -tol));
        const bool first = left_out[t] == corner2;  // the face's (v0, v1, v3)
        const Float3& fa = p[ids[first ? 0 : 2]];
        const Float3& fb = p[ids[first ? 1 : 3]];
        const Float3& fc = p[ids[first ? 3 : 1]];
        for (int l = 0; l < b.count; ++l) {
          if (!(maybe & (1u << l))) continue;
          if (!(sure & (1u << l)) && !ExactInside(Line(b.o[l], b.d[l]), fa, fb, fc)) continue;
          double den = 0;
          const double tt = PlaneT(fa, fb, fc, b.o[l], b.d[l], den);
          if (!std::isfinite(tt)) {
            x[l].degenerate = true;
          } else {
            x[l].Add(static_cast<float>(tt), den, ring, slot.face);
          }
        }
      }
    }
  }
  const unsigned both = Bits(counter_clockwise) & Bits(clockwise);
  for (int l = 0; l < b.count; ++l) {
    settled[l] = x[l].degenerate || (both & (1u << l)) != 0;
    decided[l] = !settled[l] && Decide(x[l], 1, query.policy, b.k[l], out);
  }
}

#if defined(__x86_64__)
// ---- Two blocks at once, in AVX2 -------------------------------------------------------------
// The 8 lanes of a 256-bit register hold two blocks of the same face (lane 4 h + l: block h's
// lane l), each of its own cell. Every lane's floats come from the operations TraceBlock does,
// in the same order (no fused multiply-add in either), so both kernels keep the same samples
// for the exact test and answer alike (tests/extract/mapping_test.cpp compares them). Its
// vector code is written out here: lambdas and helper functions would be compiled for the
// baseline ISA, not this function's.

using f8 = float __attribute__((vector_size(32)));
using i8 = std::int32_t __attribute__((vector_size(32)));

__attribute__((target("avx2"))) void TraceBlockPair(const MappingScratch& w, const Mesh& sculpt,
                                                    const int ci[2], const int cj[2],
                                                    const Lanes* const blocks[2],
                                                    const NormalQuery& query, const NormalHits& out,
                                                    bool decided[2][kLanes],
                                                    bool settled[2][kLanes]) {
  const int width = w.m + 2 * kMargin, points = width + 1;
  const Lanes& A = *blocks[0];
  const Lanes& B = *blocks[1];
#define DISPEX_JOIN(field) __builtin_shufflevector(A.field, B.field, 0, 1, 2, 3, 4, 5, 6, 7)
  const f8 ox = DISPEX_JOIN(ox), oy = DISPEX_JOIN(oy), oz = DISPEX_JOIN(oz);
  const f8 e1x = DISPEX_JOIN(e1x), e1y = DISPEX_JOIN(e1y), e1z = DISPEX_JOIN(e1z);
  const f8 e2x = DISPEX_JOIN(e2x), e2y = DISPEX_JOIN(e2y), e2z = DISPEX_JOIN(e2z);
#undef DISPEX_JOIN
  f8 px[16], py[16];
  f8 reach = {};
  for (int q = 0; q < 16; ++q) {
    const float* v[2];
    for (int h = 0; h < 2; ++h) {
      const int x = ci[h] - 1 + (q & 3) + kMargin, y = cj[h] - 1 + (q >> 2) + kMargin;
      v[h] = &w.lattice[3 * static_cast<std::size_t>(y * points + x)];
    }
    const f8 vx = {v[0][0], v[0][0], v[0][0], v[0][0], v[1][0], v[1][0], v[1][0], v[1][0]};
    const f8 vy = {v[0][1], v[0][1], v[0][1], v[0][1], v[1][1], v[1][1], v[1][1], v[1][1]};
    const f8 vz = {v[0][2], v[0][2], v[0][2], v[0][2], v[1][2], v[1][2], v[1][2], v[1][2]};
    const f8 wx = vx - ox, wy = vy - oy, wz = vz - oz;
    px[q] = wx * e1x + wy * e1y + wz * e1z;
    py[q] = wx * e2x + wy * e2y + wz * e2z;
    const f8 ax = px[q] < 0 ? -px[q] : px[q], ay = py[q] < 0 ? -py[q] : py[q];
    const f8 sum = ax + ay;
    reach = reach > sum ? reach : sum;
  }
  // TraceBlock's bound on an edge value's error, lane by lane.
  const f8 aox = ox < 0 ? -ox : ox, aoy = oy < 0 ? -oy : oy, aoz = oz < 0 ? -oz : oz;
  const f8 extent = f8{} + w.extent;
  const f8 mxy = aox > aoy ? aox : aoy, mze = aoz > extent ? aoz : extent;
  const f8 magnitude = mxy > mze ? mxy : mze;
  const f8 tol = 4 * reach * magnitude * 0x1p-19f + reach * reach * 0x1p-19f;
#define DISPEX_EDGE(a, c) (px[a] * py[c] - py[a] * px[c])
  f8 hz[4][3], vt[3][4];
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 3; ++x) hz[y][x] = DISPEX_EDGE(y * 4 + x, y * 4 + x + 1);
  }
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) vt[y][x] = DISPEX_EDGE(y * 4 + x, (y + 1) * 4 + x);
  }
  const unsigned active = ((1u << A.count) - 1) | (((1u << B.count) - 1) << 4);
  Crossings x[2 * kLanes];
  for (int l = 0; l < 2 * kLanes; ++l) x[l].distance = query.distance;
  i8 counter_clockwise = {}, clockwise = {};
  const Float3* p = sculpt.positions.data();
  for (int sy = 0; sy < 3; ++sy) {
    for (int sx = 0; sx < 3; ++sx) {
      const MappingScratch::Slot* slot[2];
      int corner2[2];
      bool main[2];
      for (int h = 0; h < 2; ++h) {
        slot[h] = &w.apron[static_cast<std::size_t>((cj[h] - 1 + sy + kMargin) * width + ci[h] - 1 +
                                                    sx + kMargin)];
        corner2[h] = (2 - slot[h]->corner) & 3;
        main[h] = (corner2[h] & 1) != 0;
      }
      const int ring = sx == 1 && sy == 1 ? 0 : 1;
      const int c0 = sy * 4 + sx, c1 = c0 + 1, c2 = c0 + 5, c3 = c0 + 4;
      const std::int32_t ma = main[0] ? -1 : 0, mb = main[1] ? -1 : 0;
      const i8 is_main = {ma, ma, ma, ma, mb, mb, mb, mb};
      const f8 dg = is_main ? DISPEX_EDGE(c0, c2) : DISPEX_EDGE(c1, c3);
      const f8 bottom = hz[sy][sx], right = vt[sy][sx + 1], top = -hz[sy + 1][sx],
               left = -vt[sy][sx];
      const i8 ccw = bottom + right + top + left > 0;
      counter_clockwise |= ccw;
      clockwise |= ~ccw;
      const f8 tri[2][3] = {{bottom, is_main ? right : dg, is_main ? -dg : left},
                            {is_main ? dg : right, top, is_main ? left : -dg}};
      // A lane's exact value of the slot's diagonal (slot corner 0 to 2, or 1 to 3), once
      // computed: where a triangle is unsure only along the diagonal (texel centres at a
      // quarter of a cell lie on it), that value decides both triangles; see below.
      double diagonal[2 * kLanes];
      unsigned have_diagonal = 0;
      for (int t = 0; t < 2; ++t) {
        const f8 lo01 = tri[t][0] < tri[t][1] ? tri[t][0] : tri[t][1];
        const f8 low = lo01 < tri[t][2] ? lo01 : tri[t][2];
        const f8 hi01 = tri[t][0] > tri[t][1] ? tri[t][0] : tri[t][1];
        const f8 high = hi01 > tri[t][2] ? hi01 : tri[t][2];
        const i8 maybe_mask = (low >= -tol) | (high <= tol);
        const unsigned maybe =
            static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<f8>(maybe_mask))) &
            active;
        if (maybe == 0) continue;
        const i8 sure_mask = (low > tol) | (high < -tol);
        const auto sure =
            static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<f8>(sure_mask)));
        for (int l = 0; l < 2 * kLanes; ++l) {
          if (!(maybe & (1u << l))) continue;
          const int h = l >> 2, lane = l & 3;
          const Lanes& b = *blocks[h];
          const int left_out = t == 0 ? (main[h] ? 3 : 2) : (main[h] ? 1 : 0);
          const bool first = left_out == corner2[h];  // the face's (v0, v1, v3)
          const std::int32_t* ids =
              sculpt.face_indices.data() + 4 * static_cast<std::size_t>(slot[h]->face);
          const Float3& fa = p[ids[first ? 0 : 2]];
          const Float3& fb = p[ids[first ? 1 : 3]];
          const Float3& fc = p[ids[first ? 3 : 1]];
          if (!(sure & (1u << l))) {
            // The triangle's diagonal is tri[t][di] (dg, or -dg where `negated`). When its
            // two other edges lie beyond the float error with one sign, ExactInside's answer
            // is that the diagonal's exact value, seen the same way round, has that sign or
            // is 0: its other two exact values have the sign the float ones have (what "sure"
            // relies on), and ExactInside's three values are these, all negated or not.
            const int di = main[h] ? (t == 0 ? 2 : 0) : (t == 0 ? 1 : 2);
            const bool negated = (t == 0) == main[h];
            const float ea = tri[t][(di + 1) % 3][l], eb = tri[t][(di + 2) % 3][l];
            const bool positive = ea > tol[l] && eb > tol[l];
            const bool negative = ea < -tol[l] && eb < -tol[l];
            if (positive || negative) {
              if (!(have_diagonal & (1u << l))) {
                const Line line(b.o[lane], b.d[lane]);
                const int k = main[h] ? 0 : 1;  // the diagonal's first slot corner
                double xa, ya, xb, yb;
                line.Project(p[ids[(slot[h]->corner + k) & 3]], xa, ya);
                line.Project(p[ids[(slot[h]->corner + k + 2) & 3]], xb, yb);
                diagonal[l] = EdgeValue(xa, ya, xb, yb);
                have_diagonal |= 1u << l;
              }
              const double along = negated ? -diagonal[l] : diagonal[l];
              if (positive ? !(along >= 0) : !(along <= 0)) continue;
            } else if (!ExactInside(Line(b.o[lane], b.d[lane]), fa, fb, fc)) {
              continue;
            }
          }
          double den = 0;
          const double tt = PlaneT(fa, fb, fc, b.o[lane], b.d[lane], den);
          if (!std::isfinite(tt)) {
            x[l].degenerate = true;
          } else {
            x[l].Add(static_cast<float>(tt), den, ring, slot[h]->face);
          }
        }
      }
    }
  }
#undef DISPEX_EDGE
  const unsigned both =
      static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<f8>(counter_clockwise))) &
      static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<f8>(clockwise)));
  for (int h = 0; h < 2; ++h) {
    const Lanes& b = *blocks[h];
    for (int l = 0; l < b.count; ++l) {
      const int lane = 4 * h + l;
      settled[h][l] = x[lane].degenerate || (both & (1u << lane)) != 0;
      decided[h][l] = !settled[h][l] && Decide(x[lane], 1, query.policy, b.k[l], out);
    }
  }
}

bool CpuPairsBlocks() {
  return __builtin_cpu_supports("avx2") != 0;
}
#else
bool CpuPairsBlocks() {
  return false;
}
#endif

}  // namespace

namespace {

// TraceMapped's rings, for a face not at risk of folds.
void TraceRingsOfFace(const SculptMapping& mapping, const Mesh& sculpt, PtexFaceId face, int n,
                      std::span<const std::int32_t> samples, std::span<const Float3> origins,
                      std::span<const Float3> normals, const NormalQuery& query,
                      const NormalHits& out, std::span<std::uint8_t> undecided, MappingScratch& w,
                      MappingCounters& counters) {
  const int m = mapping.grid_size(face.value);
  auto cell_of = [&](int i) {
    return static_cast<int>((std::int64_t{2} * i + 1) * m / (std::int64_t{2} * n));
  };
  // A few samples whose rings all stay inside the face (the search estimate's) need no apron
  // beyond it.
  bool inside = !samples.empty();
  for (std::size_t s = 0; inside && s < samples.size(); ++s) {
    for (const int cell : {cell_of(samples[s] % n), cell_of(samples[s] / n)}) {
      inside = inside && cell >= kMaxRings && cell < m - kMaxRings;
    }
  }
  if (w.face != face.value || (!w.margins && !inside)) LayOut(mapping, face.value, w, !inside);
  if (samples.empty() && w.lattice_face != face.value) {
    FillLattice(sculpt, w);
    w.lattice_face = face.value;
  }
  // Invalid queries are misses; the others get their cell's rings, one by one.
  auto valid = [&](std::size_t k) {
    const Float3& o = origins[k];
    const Float3& d = normals[k];
    if (Finite(o) && Finite(d) && (d.x != 0 || d.y != 0 || d.z != 0)) return true;
    out.t[k] = std::numeric_limits<float>::quiet_NaN();
    out.flags[k] = 0;
    if (!out.prim.empty()) out.prim[k] = SculptPrimId();
    undecided[k] = 0;
    ++counters.decided;
    return false;
  };
  auto one = [&](std::size_t k, int ci, int cj) {
    const bool done = TraceRings(w, sculpt, Line(origins[k], FlushTiny(normals[k])), ci, cj, query,
                                 k, out, counters.quads);
    undecided[k] = !done;
    counters.decided += done;
  };
  if (!samples.empty()) {
    for (const std::int32_t s : samples) {
      const auto k = static_cast<std::size_t>(s);
      if (valid(k)) one(k, cell_of(s % n), cell_of(s / n));
    }
    return;
  }
  // The whole grid, cell by cell: where rings 0 and 1 are all quads of the lattice (no
  // extraordinary corner), the cell's samples go through TraceBlock together.
  const int width = m + 2 * kMargin;
  auto plain = [&](int ci, int cj) {
    for (int c = 0; c < 4; ++c) {
      if (w.fan_corner[c] && CornerDistance(ci, cj, m, c) == 0) return false;
    }
    for (int b = cj - 1; b <= cj + 1; ++b) {
      for (int a = ci - 1; a <= ci + 1; ++a) {
        if (w.apron[static_cast<std::size_t>((b + kMargin) * width + a + kMargin)].state != kCell) {
          return false;
        }
      }
    }
    return true;
  };
  // Blocks of samples, one cell's each, filled in blocks[fill]; paired, a full block
  // waits in the other slot for a second one, and the two are traced together.
  const bool pairs = w.paired_blocks && CpuPairsBlocks();
  Lanes blocks[2];
  int block_ci[2] = {}, block_cj[2] = {};
  int fill = 0;
  bool waiting = false;
  auto finish = [&](int b, const bool* decided, const bool* settled) {
    for (int l = 0; l < blocks[b].count; ++l) {
      const std::size_t k = blocks[b].k[l];
      counters.quads += 9;
      if (decided[l]) {
        undecided[k] = 0;
        ++counters.decided;
      } else if (settled[l]) {
        undecided[k] = 1;
      } else {
        one(k, block_ci[b], block_cj[b]);
      }
    }
    blocks[b].count = 0;
  };
  auto trace_alone = [&](int b) {
    bool decided[kLanes], settled[kLanes];
    TraceBlock(w, sculpt, block_ci[b], block_cj[b], blocks[b], query, out, decided, settled);
    finish(b, decided, settled);
  };
  auto flush = [&](int ci, int cj) {
    if (blocks[fill].count == 0) return;
    block_ci[fill] = ci;
    block_cj[fill] = cj;
    if (!pairs) {
      trace_alone(fill);
    } else if (!waiting) {
      waiting = true;
      fill = 1 - fill;
    } else {
#if defined(__x86_64__)
      const int first = 1 - fill;
      const int ci_pair[2] = {block_ci[first], block_ci[fill]};
      const int cj_pair[2] = {block_cj[first], block_cj[fill]};
      const Lanes* const pair[2] = {&blocks[first], &blocks[fill]};
      bool decided[2][kLanes], settled[2][kLanes];
      TraceBlockPair(w, sculpt, ci_pair, cj_pair, pair, query, out, decided, settled);
      finish(first, decided[0], settled[0]);
      finish(fill, decided[1], settled[1]);
      waiting = false;
#endif
    }
  };
  // The first sample row (column) of each cell row (column); n at the end.
  w.first_sample.assign(static_cast<std::size_t>(m) + 1, n);
  for (int i = n - 1; i >= 0; --i) w.first_sample[static_cast<std::size_t>(cell_of(i))] = i;
  for (int c = m - 1; c >= 0; --c) {
    const auto at = static_cast<std::size_t>(c);
    w.first_sample[at] = std::min(w.first_sample[at], w.first_sample[at + 1]);
  }
  for (int cj = 0; cj < m; ++cj) {
    const int j_begin = w.first_sample[static_cast<std::size_t>(cj)];
    const int j_end = w.first_sample[static_cast<std::size_t>(cj) + 1];
    for (int ci = 0; ci < m; ++ci) {
      const int i_begin = w.first_sample[static_cast<std::size_t>(ci)];
      const int i_end = w.first_sample[static_cast<std::size_t>(ci) + 1];
      const bool block = j_end > j_begin && i_end > i_begin && plain(ci, cj);
      for (int j = j_begin; j < j_end; ++j) {
        for (int i = i_begin; i < i_end; ++i) {
          const std::size_t k = static_cast<std::size_t>(j) * n + i;
          if (!valid(k)) continue;
          if (!block) {
            one(k, ci, cj);
            continue;
          }
          AddLane(w, k, origins[k], FlushTiny(normals[k]), blocks[fill]);
          if (blocks[fill].count == kLanes) flush(ci, cj);
        }
      }
      flush(ci, cj);
    }
  }
  if (waiting) trace_alone(1 - fill);
}

}  // namespace

bool PairedBlocksByDefault() {
  static const bool paired = [] {
    const char* kernel = std::getenv("DISPEX_MAPPING_KERNEL");
    return CpuPairsBlocks() && !(kernel != nullptr && std::string_view(kernel) == "sse2");
  }();
  return paired;
}

void GatherBlockQuads(const SculptMapping& mapping, const Mesh& sculpt, std::int64_t block,
                      BlockQuads& out) {
  const SculptBlocks& blocks = mapping.blocks();
  const SculptBlocks::Place at = blocks.block(block);
  const int b = blocks.block_size(at.face);
  out.b = b;
  std::fill(std::begin(out.quarter_box), std::end(out.quarter_box), Box::Empty());
  // Cell (i, j)'s face has corner RotationOf + k at the cell's corner k, (i, j), (i + 1, j),
  // (i + 1, j + 1), (i, j + 1); a lattice point names the vertex last seen there.
  constexpr int kSide = SculptBlocks::kBlock + 1;
  static constexpr int kDx[4] = {0, 1, 1, 0}, kDy[4] = {0, 0, 1, 1};
  std::int32_t vertex[kSide][kSide];
  std::uint8_t point[kSide][kSide];
  for (auto& row : vertex) std::fill(std::begin(row), std::end(row), -1);
  const Float3* p = sculpt.positions.data();
  out.num_points = 0;
  for (int j = 0; j < b; ++j) {
    for (int i = 0; i < b; ++i) {
      const int c = j * b + i;
      const std::uint32_t cell = mapping.cell(at.face, at.bi * b + i, at.bj * b + j);
      const std::int32_t face = SculptMapping::FaceOf(cell);
      const int rotation = SculptMapping::RotationOf(cell);
      const std::int32_t* ids = sculpt.face_indices.data() + 4 * static_cast<std::size_t>(face);
      const int quarter = b == 1 ? 0 : (2 * j / b) * 2 + 2 * i / b;
      Box& box = out.quarter_box[quarter];
      out.face[c] = face;
      out.quarter_of[c] = static_cast<std::uint8_t>(quarter);
      for (int k = 0; k < 4; ++k) {
        const int x = i + kDx[k], y = j + kDy[k], corner = (rotation + k) & 3;
        if (vertex[y][x] != ids[corner]) {
          vertex[y][x] = ids[corner];
          point[y][x] = static_cast<std::uint8_t>(out.num_points);
          out.points[out.num_points++] = p[ids[corner]];
        }
        out.corner_point[c][corner] = point[y][x];
        const Float3& v = out.points[point[y][x]];
        const float xyz[3] = {v.x, v.y, v.z};
        for (int a = 0; a < 3; ++a) {
          box.lower[a] = std::min(box.lower[a], xyz[a]);
          box.upper[a] = std::max(box.upper[a], xyz[a]);
        }
      }
    }
  }
}

bool WindowCrossesQuads(const BlockQuads& quads, const Mesh& sculpt, unsigned quarters,
                        const Float3& origin, const Float3& normal, float window) {
  const Line line(origin, FlushTiny(normal));
  Crossings x;
  x.distance = window;
  // Each point projected once, when a cell of a quarter tested first needs it (the same
  // doubles as TestQuad's).
  double px[4 * BlockQuads::kCells], py[4 * BlockQuads::kCells];
  bool projected[4 * BlockQuads::kCells] = {};
  const int cells = quads.b * quads.b;
  for (int c = 0; c < cells; ++c) {
    if (!(quarters >> quads.quarter_of[c] & 1u)) continue;
    double cx[4], cy[4];
    for (int k = 0; k < 4; ++k) {
      const int at = quads.corner_point[c][k];
      if (!projected[at]) {
        line.Project(quads.points[at], px[at], py[at]);
        projected[at] = true;
      }
      cx[k] = px[at];
      cy[k] = py[at];
    }
    TestProjectedQuad(line, sculpt, quads.face[c], 0, cx[0], cy[0], cx[1], cy[1], cx[2], cy[2],
                      cx[3], cy[3], x);
  }
  return x.degenerate || x.plus.found() || x.minus.found();
}

void TraceMapped(const SculptMapping& mapping, const Mesh& sculpt, PtexFaceId face, int n,
                 std::span<const std::int32_t> samples, std::span<const Float3> origins,
                 std::span<const Float3> normals, const NormalQuery& query, const NormalHits& out,
                 std::span<std::uint8_t> undecided, MappingScratch& w, MappingCounters& counters) {
  const std::size_t count = samples.empty() ? static_cast<std::size_t>(n) * n : samples.size();
  counters.queries += count;
  if (mapping.fold_risk(face.value)) {
    for (std::size_t s = 0; s < count; ++s) {
      undecided[samples.empty() ? s : static_cast<std::size_t>(samples[s])] = 1;
    }
    return;
  }
  TraceRingsOfFace(mapping, sculpt, face, n, samples, origins, normals, query, out, undecided, w,
                   counters);
  const std::uint64_t far = CheckFarSheets(mapping, sculpt, face.value, n, samples, origins,
                                           normals, query, out, undecided, w);
  counters.decided -= far;
  counters.far_sheets += far;
}

}  // namespace dispex::extract
