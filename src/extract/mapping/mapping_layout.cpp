// Laying out a face's neighbourhood for the mapping (mapping_lattice.h): the cells of the rings
// around the face, across its edges and around its corners, and the blocks near each block.
#include <algorithm>
#include <cmath>

#include "core/vec3.h"
#include "extract/mapping/mapping_lattice.h"

namespace dispex::extract {

namespace mapping {

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

}  // namespace

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

}  // namespace mapping

using namespace mapping;

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

}  // namespace dispex::extract
